/* The FMUs' own elementary functions: exp, log, pow, sin, cos, tan, asin, acos, atan, atan2 and
 * tanh, the same bits on every host. Each C library (glibc, Windows', Apple's) rounds its own way in
 * the last place, and a model's Newton solves and integrator carry such differences on (an FMU's
 * win64 binary under Wine differed from linux64 by 5e-14). An FMU built with `--elementary own`
 * calls these instead (fmubuild/elementary.py renames the calls of its generated C and of the
 * integrator); sqrt, fabs, floor, fmin and fmax are exact everywhere (IEEE 754) and stay the C
 * library's. Header only: every function static, so that two FMUs compiled into one program share
 * no name; portable C99, no fused multiply-add needed.
 *
 * How: every function reduces its argument exactly (Cody & Waite: a constant split into a leading
 * part with trailing zero bits, so that an integer times it is exact, and the remainder; exp and
 * log with a table besides), evaluates a Taylor polynomial on the reduced interval (terms kept until the next is below 2^-60 of the
 * result, by Estrin's scheme: shorter chains of dependent operations than Horner's), and rounds
 * once at the end where it can: the last addition is of a number and a much smaller correction.
 * The constants are exact values rounded once (fmubuild/elementary_constants.py, C99 hexadecimal
 * literals, between the GENERATED CONSTANTS lines below). Round to nearest is assumed (the FMUs
 * never change the rounding mode). No step relies on a fused multiply-add, and a compiler that
 * contracted one would still compute a correct (not identical) result: the products in the exact
 * two-product below are exact without one.
 *
 * Accuracy, in units in the last place of the correctly rounded result, measured against mpmath
 * (tests/test_elementary.py asserts 1 ulp for each): exp 0.51, log 0.68, pow 0.52 for |y log x| <=
 * 700, sin and cos 0.74, tan 0.77, asin, acos, atan and atan2 0.50, tanh 0.79 (the last four with
 * their intermediate ratios and square roots carried with their rounding errors). Special values (zeros, infinities, NaN,
 * overflow, underflow, C99 Annex F's cases of pow) are the C library's. sin, cos and tan reduce
 * their argument exactly for |x| < 823549 (2^19 pi/2) and call the C library beyond. */
#ifndef ROVER_COSIM_ELEMENTARY_H
#define ROVER_COSIM_ELEMENTARY_H

#include <math.h>
#include <stdint.h>
#include <string.h>

/* BEGIN GENERATED CONSTANTS (python -m rover_cosim.fmubuild.elementary_constants) */
static const double EXP_TAYLOR[4] = {0x1.0000000000000p-1, 0x1.5555555555555p-3, 0x1.5555555555555p-5, 0x1.1111111111111p-7};
static const double EXP_TABLE[256] = {
    0x1.0000000000000p+0, 0.0, 0x1.0163da9fb3335p+0, 0x1.b61299ab8cdb7p-54,
    0x1.02c9a3e778061p+0, -0x1.19083535b085dp-56, 0x1.04315e86e7f85p+0, -0x1.0a31c1977c96ep-54,
    0x1.059b0d3158574p+0, 0x1.d73e2a475b465p-55, 0x1.0706b29ddf6dep+0, -0x1.c91dfe2b13c27p-55,
    0x1.0874518759bc8p+0, 0x1.186be4bb284ffp-57, 0x1.09e3ecac6f383p+0, 0x1.1487818316136p-54,
    0x1.0b5586cf9890fp+0, 0x1.8a62e4adc610bp-54, 0x1.0cc922b7247f7p+0, 0x1.01edc16e24f71p-54,
    0x1.0e3ec32d3d1a2p+0, 0x1.03a1727c57b53p-59, 0x1.0fb66affed31bp+0, -0x1.b9bedc44ebd7bp-57,
    0x1.11301d0125b51p+0, -0x1.6c51039449b3ap-54, 0x1.12abdc06c31ccp+0, -0x1.1b514b36ca5c7p-58,
    0x1.1429aaea92de0p+0, -0x1.32fbf9af1369ep-54, 0x1.15a98c8a58e51p+0, 0x1.2406ab9eeab0ap-55,
    0x1.172b83c7d517bp+0, -0x1.19041b9d78a76p-55, 0x1.18af9388c8deap+0, -0x1.11023d1970f6cp-54,
    0x1.1a35beb6fcb75p+0, 0x1.e5b4c7b4968e4p-55, 0x1.1bbe084045cd4p+0, -0x1.95386352ef607p-54,
    0x1.1d4873168b9aap+0, 0x1.e016e00a2643cp-54, 0x1.1ed5022fcd91dp+0, -0x1.1df98027bb78cp-54,
    0x1.2063b88628cd6p+0, 0x1.dc775814a8495p-55, 0x1.21f49917ddc96p+0, 0x1.2a97e9494a5eep-55,
    0x1.2387a6e756238p+0, 0x1.9b07eb6c70573p-54, 0x1.251ce4fb2a63fp+0, 0x1.ac155bef4f4a4p-55,
    0x1.26b4565e27cddp+0, 0x1.2bd339940e9d9p-55, 0x1.284dfe1f56381p+0, -0x1.a4c3a8c3f0d7ep-54,
    0x1.29e9df51fdee1p+0, 0x1.612e8afad1255p-55, 0x1.2b87fd0dad990p+0, -0x1.10adcd6381aa4p-59,
    0x1.2d285a6e4030bp+0, 0x1.0024754db41d5p-54, 0x1.2ecafa93e2f56p+0, 0x1.1ca0f45d52383p-56,
    0x1.306fe0a31b715p+0, 0x1.6f46ad23182e4p-55, 0x1.32170fc4cd831p+0, 0x1.a9ce78e18047cp-55,
    0x1.33c08b26416ffp+0, 0x1.32721843659a6p-54, 0x1.356c55f929ff1p+0, -0x1.b5cee5c4e4628p-55,
    0x1.371a7373aa9cbp+0, -0x1.63aeabf42eae2p-54, 0x1.38cae6d05d866p+0, -0x1.e958d3c9904bdp-54,
    0x1.3a7db34e59ff7p+0, -0x1.5e436d661f5e3p-56, 0x1.3c32dc313a8e5p+0, -0x1.efff8375d29c3p-54,
    0x1.3dea64c123422p+0, 0x1.ada0911f09ebcp-55, 0x1.3fa4504ac801cp+0, -0x1.7d023f956f9f3p-54,
    0x1.4160a21f72e2ap+0, -0x1.ef3691c309278p-58, 0x1.431f5d950a897p+0, -0x1.1c7dde35f7999p-55,
    0x1.44e086061892dp+0, 0x1.89b7a04ef80d0p-59, 0x1.46a41ed1d0057p+0, 0x1.c944bd1648a76p-54,
    0x1.486a2b5c13cd0p+0, 0x1.3c1a3b69062f0p-56, 0x1.4a32af0d7d3dep+0, 0x1.9cb62f3d1be56p-54,
    0x1.4bfdad5362a27p+0, 0x1.d4397afec42e2p-56, 0x1.4dcb299fddd0dp+0, 0x1.8ecdbbc6a7833p-54,
    0x1.4f9b2769d2ca7p+0, -0x1.4b309d25957e3p-54, 0x1.516daa2cf6642p+0, -0x1.f768569bd93efp-55,
    0x1.5342b569d4f82p+0, -0x1.07abe1db13cadp-55, 0x1.551a4ca5d920fp+0, -0x1.d689cefede59bp-55,
    0x1.56f4736b527dap+0, 0x1.9bb2c011d93adp-54, 0x1.58d12d497c7fdp+0, 0x1.295e15b9a1de8p-55,
    0x1.5ab07dd485429p+0, 0x1.6324c054647adp-54, 0x1.5c9268a5946b7p+0, 0x1.c4b1b816986a2p-60,
    0x1.5e76f15ad2148p+0, 0x1.ba6f93080e65ep-54, 0x1.605e1b976dc09p+0, -0x1.3e2429b56de47p-54,
    0x1.6247eb03a5585p+0, -0x1.383c17e40b497p-54, 0x1.6434634ccc320p+0, -0x1.c483c759d8933p-55,
    0x1.6623882552225p+0, -0x1.bb60987591c34p-54, 0x1.68155d44ca973p+0, 0x1.038ae44f73e65p-57,
    0x1.6a09e667f3bcdp+0, -0x1.bdd3413b26456p-54, 0x1.6c012750bdabfp+0, -0x1.2895667ff0b0dp-56,
    0x1.6dfb23c651a2fp+0, -0x1.bbe3a683c88abp-57, 0x1.6ff7df9519484p+0, -0x1.83c0f25860ef6p-55,
    0x1.71f75e8ec5f74p+0, -0x1.16e4786887a99p-55, 0x1.73f9a48a58174p+0, -0x1.0a8d96c65d53cp-54,
    0x1.75feb564267c9p+0, -0x1.0245957316dd3p-54, 0x1.780694fde5d3fp+0, 0x1.866b80a02162dp-54,
    0x1.7a11473eb0187p+0, -0x1.41577ee04992fp-55, 0x1.7c1ed0130c132p+0, 0x1.f124cd1164dd6p-54,
    0x1.7e2f336cf4e62p+0, 0x1.05d02ba15797ep-56, 0x1.80427543e1a12p+0, -0x1.27c86626d972bp-54,
    0x1.82589994cce13p+0, -0x1.d4c1dd41532d8p-54, 0x1.8471a4623c7adp+0, -0x1.8d684a341cdfbp-55,
    0x1.868d99b4492edp+0, -0x1.fc6f89bd4f6bap-54, 0x1.88ac7d98a6699p+0, 0x1.994c2f37cb53ap-54,
    0x1.8ace5422aa0dbp+0, 0x1.6e9f156864b27p-54, 0x1.8cf3216b5448cp+0, -0x1.0d55e32e9e3aap-56,
    0x1.8f1ae99157736p+0, 0x1.5cc13a2e3976cp-55, 0x1.9145b0b91ffc6p+0, -0x1.dd6792e582524p-54,
    0x1.93737b0cdc5e5p+0, -0x1.75fc781b57ebcp-57, 0x1.95a44cbc8520fp+0, -0x1.64b7c96a5f039p-56,
    0x1.97d829fde4e50p+0, -0x1.d185b7c1b85d1p-54, 0x1.9a0f170ca07bap+0, -0x1.173bd91cee632p-54,
    0x1.9c49182a3f090p+0, 0x1.c7c46b071f2bep-56, 0x1.9e86319e32323p+0, 0x1.824ca78e64c6ep-56,
    0x1.a0c667b5de565p+0, -0x1.359495d1cd533p-54, 0x1.a309bec4a2d33p+0, 0x1.6305c7ddc36abp-54,
    0x1.a5503b23e255dp+0, -0x1.d2f6edb8d41e1p-54, 0x1.a799e1330b358p+0, 0x1.bcb7ecac563c7p-54,
    0x1.a9e6b5579fdbfp+0, 0x1.0fac90ef7fd31p-54, 0x1.ac36bbfd3f37ap+0, -0x1.f9234cae76cd0p-55,
    0x1.ae89f995ad3adp+0, 0x1.7a1cd345dcc81p-54, 0x1.b0e07298db666p+0, -0x1.bdef54c80e425p-54,
    0x1.b33a2b84f15fbp+0, -0x1.2805e3084d708p-57, 0x1.b59728de5593ap+0, -0x1.c71dfbbba6de3p-54,
    0x1.b7f76f2fb5e47p+0, -0x1.5584f7e54ac3bp-56, 0x1.ba5b030a1064ap+0, -0x1.efcd30e54292ep-54,
    0x1.bcc1e904bc1d2p+0, 0x1.23dd07a2d9e84p-55, 0x1.bf2c25bd71e09p+0, -0x1.efdca3f6b9c73p-54,
    0x1.c199bdd85529cp+0, 0x1.11065895048ddp-55, 0x1.c40ab5fffd07ap+0, 0x1.b4537e083c60ap-54,
    0x1.c67f12e57d14bp+0, 0x1.2884dff483cadp-54, 0x1.c8f6d9406e7b5p+0, 0x1.1acbc48805c44p-56,
    0x1.cb720dcef9069p+0, 0x1.503cbd1e949dbp-56, 0x1.cdf0b555dc3fap+0, -0x1.dd83b53829d72p-55,
    0x1.d072d4a07897cp+0, -0x1.cbc3743797a9cp-54, 0x1.d2f87080d89f2p+0, -0x1.d487b719d8578p-54,
    0x1.d5818dcfba487p+0, 0x1.2ed02d75b3707p-55, 0x1.d80e316c98398p+0, -0x1.11ec18beddfe8p-54,
    0x1.da9e603db3285p+0, 0x1.c2300696db532p-54, 0x1.dd321f301b460p+0, 0x1.2da5778f018c3p-54,
    0x1.dfc97337b9b5fp+0, -0x1.1a5cd4f184b5cp-54, 0x1.e264614f5a129p+0, -0x1.7b627817a1496p-54,
    0x1.e502ee78b3ff6p+0, 0x1.39e8980a9cc8fp-55, 0x1.e7a51fbc74c83p+0, 0x1.2d522ca0c8de2p-54,
    0x1.ea4afa2a490dap+0, -0x1.e9c23179c2893p-54, 0x1.ecf482d8e67f1p+0, -0x1.c93f3b411ad8cp-54,
    0x1.efa1bee615a27p+0, 0x1.dc7f486a4b6b0p-54, 0x1.f252b376bba97p+0, 0x1.3a1a5bf0d8e43p-54,
    0x1.f50765b6e4540p+0, 0x1.9d3e12dd8a18bp-54, 0x1.f7bfdad9cbe14p+0, -0x1.dbb12d006350ap-54,
    0x1.fa7c1819e90d8p+0, 0x1.74853f3a5931ep-55, 0x1.fd3c22b8f71f1p+0, 0x1.2eb74966579e7p-57,
};
static const double EXP_N_OVER_LN2[1] = {0x1.71547652b82fep+7};
static const double EXP_LN2_OVER_N[2] = {0x1.62e42fef80000p-8, 0x1.1cf79abc9e3b4p-43};
static const double LN2[2] = {0x1.62e42fefa3800p-1, 0x1.ef35793c76730p-45};
static const double LOG1P_TAYLOR[9] = {
    -0x1.0000000000000p-1, 0x1.5555555555555p-2, -0x1.0000000000000p-2, 0x1.999999999999ap-3,
    -0x1.5555555555555p-3, 0x1.2492492492492p-3, -0x1.0000000000000p-3, 0x1.c71c71c71c71cp-4,
    -0x1.999999999999ap-4,
};
static const double LOG_TABLE[273] = {
    0x1.6816816816817p+0, -0x1.5d5bddf596000p-2, 0x1.a0b2a08a465dcp-47, 0x1.642c8590b2164p+0,
    -0x1.522ae0738a000p-2, -0x1.ebe708164c759p-45, 0x1.6058160581606p+0, -0x1.4718dc271c000p-2,
    -0x1.06c18fb4c14c5p-44, 0x1.5c9882b931057p+0, -0x1.3c25277333000p-2, -0x1.83b54b606bd5cp-46,
    0x1.58ed2308158edp+0, -0x1.314f1e1d36000p-2, 0x1.8e27ad3213cb8p-45, 0x1.5555555555555p+0,
    -0x1.269621134e000p-2, 0x1.1b61f10522625p-44, 0x1.51d07eae2f815p+0, -0x1.1bf99635a7000p-2,
    0x1.1ac89575c2125p-44, 0x1.4e5e0a72f0539p+0, -0x1.1178e8227e000p-2, -0x1.1ef78ce2d07f2p-44,
    0x1.4afd6a052bf5bp+0, -0x1.07138604d6000p-2, 0x1.e76324e912b17p-44, 0x1.47ae147ae147bp+0,
    -0x1.f991c6cb3c000p-3, 0x1.90d04cd7cc834p-44, 0x1.446f86562d9fbp+0, -0x1.e530effe72000p-3,
    0x1.fdbdbb13f7c18p-44, 0x1.4141414141414p+0, -0x1.d1037f2656000p-3, 0x1.84a7e75b6f6e4p-47,
    0x1.3e22cbce4a902p+0, -0x1.bd087383be000p-3, 0x1.d4bc4595412b6p-45, 0x1.3b13b13b13b14p+0,
    -0x1.a93ed3c8ae000p-3, 0x1.8724350562169p-45, 0x1.3813813813814p+0, -0x1.95a5adcf70000p-3,
    -0x1.7f22858a0ff6fp-47, 0x1.3521cfb2b78c1p+0, -0x1.823c16551a000p-3, -0x1.e0ddb9a631e83p-46,
    0x1.323e34a2b10bfp+0, -0x1.6f0128b756000p-3, -0x1.577390d31ef0fp-44, 0x1.2f684bda12f68p+0,
    -0x1.5bf406b544000p-3, 0x1.27023eb68981cp-46, 0x1.2c9fb4d812ca0p+0, -0x1.4913d8333c000p-3,
    0x1.53e43558124c4p-44, 0x1.29e4129e4129ep+0, -0x1.365fcb015a000p-3, 0x1.fd3a0afb9691bp-44,
    0x1.27350b8812735p+0, -0x1.23d712a49c000p-3, -0x1.00d238fd3df5cp-46, 0x1.2492492492492p+0,
    -0x1.1178e8227e000p-3, -0x1.1ef78ce2d07f2p-45, 0x1.21fb78121fb78p+0, -0x1.fe89139dbc000p-4,
    -0x1.56594d82f7a82p-44, 0x1.1f7047dc11f70p+0, -0x1.da72763844000p-4, -0x1.a89401fa71733p-46,
    0x1.1cf06ada2811dp+0, -0x1.b6ac88dad4000p-4, -0x1.b1bdff50225c7p-44, 0x1.1a7b9611a7b96p+0,
    -0x1.9335e5d594000p-4, -0x1.3115c3abd47dap-45, 0x1.1811811811812p+0, -0x1.700d30aeac000p-4,
    -0x1.c1e8da99ded32p-49, 0x1.15b1e5f75270dp+0, -0x1.4d3115d208000p-4, 0x1.53a2582f4e1efp-48,
    0x1.135c81135c811p+0, -0x1.2aa04a4470000p-4, -0x1.7a48ba8b1cb41p-44, 0x1.1111111111111p+0,
    -0x1.08598b59e4000p-4, 0x1.7e5dd7009902cp-46, 0x1.0ecf56be69c90p+0, -0x1.ccb73cddd8000p-5,
    -0x1.965c36e09f5fep-44, 0x1.0c9714fbcda3bp+0, -0x1.894aa149f8000p-5, -0x1.9a19a8be97661p-44,
    0x1.0a6810a6810a7p+0, -0x1.466aed42e0000p-5, 0x1.c167375bdfd28p-45, 0x1.0842108421084p+0,
    -0x1.0415d89e78000p-5, 0x1.dddc7f461c516p-44, 0x1.0624dd2f1a9fcp+0, -0x1.8492528c90000p-6,
    0x1.aa0ba325a0c34p-45, 0x1.0410410410410p+0, -0x1.0205658930000p-6, -0x1.611d27c8e8417p-44,
    0x1.0204081020408p+0, -0x1.0101575880000p-7, -0x1.bce251998b506p-44, 0x1.0000000000000p+0,
    0.0, 0.0, 0x1.fc07f01fc07f0p-1, 0x1.fe02a6b100000p-8,
    0x1.9e23f0dda40e4p-46, 0x1.f81f81f81f820p-1, 0x1.fc0a8b0fc0000p-7, 0x1.f1e7cf6d3a69cp-50,
    0x1.f44659e4a4271p-1, 0x1.7b91b07d60000p-6, -0x1.3b955b602ace4p-44, 0x1.f07c1f07c1f08p-1,
    0x1.f829b0e780000p-6, 0x1.980267c7e09e4p-45, 0x1.ecc07b301ecc0p-1, 0x1.39e87b9fe8000p-5,
    0x1.eafd480ad9015p-44, 0x1.e9131abf0b767p-1, 0x1.77458f6330000p-5, -0x1.181dce586af09p-44,
    0x1.e573ac901e574p-1, 0x1.b42dd71198000p-5, -0x1.c827ae5d6704cp-46, 0x1.e1e1e1e1e1e1ep-1,
    0x1.f0a30c0118000p-5, -0x1.d599e83368e91p-45, 0x1.de5d6e3f8868ap-1, 0x1.16536eea38000p-4,
    -0x1.47c5e768fa309p-46, 0x1.dae6076b981dbp-1, 0x1.341d7961bc000p-4, 0x1.1d09299837610p-44,
    0x1.d77b654b82c34p-1, 0x1.51b073f060000p-4, 0x1.83f69278e686ap-44, 0x1.d41d41d41d41dp-1,
    0x1.6f0d28ae58000p-4, -0x1.4b4641b664613p-44, 0x1.d0cb58f6ec074p-1, 0x1.8c345d6318000p-4,
    0x1.b20f5acb42a66p-44, 0x1.cd85689039b0bp-1, 0x1.a926d3a4ac000p-4, 0x1.563650bd22a9cp-44,
    0x1.ca4b3055ee191p-1, 0x1.c5e548f5bc000p-4, 0x1.d0c57585fbe06p-46, 0x1.c71c71c71c71cp-1,
    0x1.e27076e2b0000p-4, -0x1.a342c2af0003cp-45, 0x1.c3f8f01c3f8f0p-1, 0x1.fec9131dc0000p-4,
    -0x1.54555d1ae6607p-44, 0x1.c0e070381c0e0p-1, 0x1.0d77e7cd08000p-3, 0x1.cb2cd2ee2f482p-44,
    0x1.bdd2b899406f7p-1, 0x1.1b72ad52f6000p-3, 0x1.e80a41811a396p-45, 0x1.bacf914c1bad0p-1,
    0x1.29552f8200000p-3, -0x1.5b967f4471dfcp-44, 0x1.b7d6c3dda338bp-1, 0x1.371fc201e8000p-3,
    0x1.ee8779b2d8abcp-44, 0x1.b4e81b4e81b4fp-1, 0x1.44d2b6ccb8000p-3, -0x1.70cc16135783cp-46,
    0x1.b2036406c80d9p-1, 0x1.526e5e3a1c000p-3, -0x1.790ba37fc5238p-44, 0x1.af286bca1af28p-1,
    0x1.5ff3070a7a000p-3, -0x1.8586f183bebf2p-44, 0x1.ac5701ac5701bp-1, 0x1.6d60fe719e000p-3,
    -0x1.bc6e557134767p-44, 0x1.a98ef606a63bep-1, 0x1.7ab890210e000p-3, -0x1.bdb9072534a58p-45,
    0x1.a6d01a6d01a6dp-1, 0x1.87fa06520c000p-3, 0x1.22120401202fcp-44, 0x1.a41a41a41a41ap-1,
    0x1.9525a9cf46000p-3, -0x1.297137d9f158fp-44, 0x1.a16d3f97a4b02p-1, 0x1.a23bc1fe2c000p-3,
    -0x1.539cd91dc9f0bp-44, 0x1.9ec8e951033d9p-1, 0x1.af3c94e80c000p-3, -0x1.a4e633fcd9066p-52,
    0x1.9c2d14ee4a102p-1, 0x1.bc286742d8000p-3, 0x1.9ac53f39d121cp-44, 0x1.999999999999ap-1,
    0x1.c8ff7c79aa000p-3, -0x1.7794f689f8434p-45, 0x1.970e4f80cb872p-1, 0x1.d5c216b4fc000p-3,
    -0x1.1ba91bbca681bp-45, 0x1.948b0fcd6e9e0p-1, 0x1.e27076e2b0000p-3, -0x1.a342c2af0003cp-44,
    0x1.920fb49d0e229p-1, 0x1.ef0adcbdc6000p-3, -0x1.b26b79c86af24p-45, 0x1.8f9c18f9c18fap-1,
    0x1.fb9186d5e4000p-3, -0x1.d572aab993c87p-47, 0x1.8d3018d3018d3p-1, 0x1.0402594b4d000p-2,
    0x1.036b89ef42d7fp-48, 0x1.8acb90f6bf3aap-1, 0x1.0a324e2739000p-2, 0x1.c6bee7ef4030ep-47,
    0x1.886e5f0abb04ap-1, 0x1.1058bf9ae5000p-2, -0x1.4ab9d817d52cdp-44, 0x1.8618618618618p-1,
    0x1.1675cababa000p-2, 0x1.8380e731f55c4p-44, 0x1.83c977ab2beddp-1, 0x1.1c898c169a000p-2,
    -0x1.81410e5c62affp-44, 0x1.8181818181818p-1, 0x1.22941fbcf8000p-2, -0x1.a6976f5eb0963p-44,
    0x1.7f405fd017f40p-1, 0x1.2895a13de8000p-2, 0x1.a8d7ad24c13f0p-44, 0x1.7d05f417d05f4p-1,
    0x1.2e8e2bae12000p-2, -0x1.67b1e99b72bd8p-45, 0x1.7ad2208e0ecc3p-1, 0x1.347dd9a988000p-2,
    -0x1.5594dd4c58092p-45, 0x1.78a4c8178a4c8p-1, 0x1.3a64c55694000p-2, 0x1.7a71cbcd735d0p-44,
    0x1.767dce434a9b1p-1, 0x1.404308686a000p-2, 0x1.f8ef43049f7d3p-44, 0x1.745d1745d1746p-1,
    0x1.4618bc21c6000p-2, -0x1.3d82f484c84ccp-46, 0x1.724287f46debcp-1, 0x1.4be5f95778000p-2,
    -0x1.d7c92cd9ad824p-44, 0x1.702e05c0b8170p-1, 0x1.51aad872e0000p-2, -0x1.f4bd8db0a7cc1p-44,
    0x1.6e1f76b4337c7p-1, 0x1.5767717456000p-2, -0x1.64ead9524d7cap-44, 0x1.6c16c16c16c17p-1,
    0x1.5d1bdbf581000p-2, -0x1.8d6bdc9c7c238p-44, 0x1.6a13cd1537290p-1, 0x1.62c82f2b9c000p-2,
    0x1.e54bdbd7c8a98p-44,
};
static const double SIN_TAYLOR[8] = {
    -0x1.5555555555555p-3, 0x1.1111111111111p-7, -0x1.a01a01a01a01ap-13, 0x1.71de3a556c734p-19,
    -0x1.ae64567f544e4p-26, 0x1.6124613a86d09p-33, -0x1.ae7f3e733b81fp-41, 0x1.952c77030ad4ap-49,
};
static const double COS_TAYLOR[7] = {
    0x1.5555555555555p-5, -0x1.6c16c16c16c17p-10, 0x1.a01a01a01a01ap-16, -0x1.27e4fb7789f5cp-22,
    0x1.1eed8eff8d898p-29, -0x1.93974a8c07c9dp-37, 0x1.ae7f3e733b81fp-45,
};
static const double PIO2_PARTS[3] = {0x1.921fb54400000p+0, 0x1.0b4611a600000p-34, 0x1.3198a2e037073p-69};
static const double TWO_OVER_PI[1] = {0x1.45f306dc9c883p-1};
static const double ATAN_TAYLOR[10] = {
    -0x1.5555555555555p-2, 0x1.999999999999ap-3, -0x1.2492492492492p-3, 0x1.c71c71c71c71cp-4,
    -0x1.745d1745d1746p-4, 0x1.3b13b13b13b14p-4, -0x1.1111111111111p-4, 0x1.e1e1e1e1e1e1ep-5,
    -0x1.af286bca1af28p-5, 0x1.8618618618618p-5,
};
static const double ATAN_BREAKPOINT[4] = {0x1.0000000000000p-2, 0x1.0000000000000p-1, 0x1.8000000000000p-1, 0x1.0000000000000p+0};
static const double ATAN_OF_BREAKPOINT[8] = {
    0x1.f5b75f92c80ddp-3, 0x1.8ab6e3cf7afbdp-57, 0x1.dac670561bb4fp-2, 0x1.a2b7f222f65e2p-56,
    0x1.4978fa3269ee1p-1, 0x1.2419a87f2a458p-56, 0x1.921fb54442d18p-1, 0x1.1a62633145c07p-55,
};
static const double PI[2] = {0x1.921fb54442d18p+1, 0x1.1a62633145c07p-53};
static const double PI_OVER_2[2] = {0x1.921fb54442d18p+0, 0x1.1a62633145c07p-54};
static const double THREE_PI_OVER_4[1] = {0x1.2d97c7f3321d2p+1};
static const double TANH_TAYLOR[3] = {-0x1.5555555555555p-2, 0x1.1111111111111p-3, -0x1.ba1ba1ba1ba1cp-5};
/* END GENERATED CONSTANTS */

/* The small kernels inlined into each function (a kernel called through memory costs more than it
 * computes). */
#if defined(__GNUC__) || defined(__clang__)
#define KERNEL static inline __attribute__((always_inline))
#else
#define KERNEL static inline
#endif

/* The functions: static, so that each file that includes this header has its own copy (no
 * external name to collide with another FMU's) and the optimiser sees their bodies. */
#if defined(__GNUC__) || defined(__clang__)
#define FUNCTION static __attribute__((unused))
#else
#define FUNCTION static
#endif

#define ROUND_SHIFT 0x1.8p52 /* x + ROUND_SHIFT - ROUND_SHIFT: x rounded to an integer, |x| < 2^51 */

KERNEL uint64_t bits_of(double x) {
    uint64_t u;
    memcpy(&u, &x, sizeof u);
    return u;
}

KERNEL double double_of(uint64_t u) {
    double x;
    memcpy(&x, &u, sizeof x);
    return x;
}

/* 2^k for -1022 <= k <= 1023 */
KERNEL double power_of_two(int k) {
    return double_of((uint64_t)(k + 1023) << 52);
}

/* the sign bit: 1 for negative numbers, -0 and NaNs with it set */
KERNEL int sign_bit(double x) {
    return (int)(bits_of(x) >> 63);
}

/* a + b = s + e exactly, |a| >= |b| or a == 0 (Dekker's Fast2Sum) */
KERNEL double fast_two_sum(double a, double b, double *e) {
    double s = a + b;
    *e = b - (s - a);
    return s;
}

/* a + b = s + e exactly (Knuth's TwoSum) */
KERNEL double two_sum(double a, double b, double *e) {
    double s = a + b;
    double bb = s - a;
    *e = (a - (s - bb)) + (b - bb);
    return s;
}

/* a = hi + lo with hi of 26 bits (Veltkamp), |a| < 2^995 */
KERNEL void split(double a, double *hi, double *lo) {
    double c = 134217729.0 * a; /* 2^27 + 1 */
    *hi = c - (c - a);
    *lo = a - *hi;
}

/* a * b = p + e exactly (Dekker's two-product; each partial product is exact) */
KERNEL double two_product(double a, double b, double *e) {
    double p = a * b, ah, al, bh, bl;
    split(a, &ah, &al);
    split(b, &bh, &bl);
    *e = ((ah * bh - p) + ah * bl + al * bh) + al * bl;
    return p;
}

/* ---- exp ------------------------------------------------------------------------------------
 * x + xl = (128 m + j) ln2/128 + r, |r| <= ln2/256: exp = 2^m 2^(j/128) e^r with 2^(j/128) from
 * the table (a double t and its remainder) and e^r - 1 = r + r^2/2 + ... + r^5/5! (the next term is
 * below 2^-60), evaluated as r + r^2 (c2 + r c3) + r^4 (c4 + r c5) (Estrin: a shorter chain of
 * dependent operations than Horner's). Returns m; exp = 2^m (*t + *c), *c small. */
KERNEL int64_t exp_parts(double x, double xl, double *t, double *c) {
    double kd = x * EXP_N_OVER_LN2[0] + ROUND_SHIFT;
    int64_t k = (int64_t)(bits_of(kd) & 0x000fffffffffffffULL) - ((int64_t)1 << 51); /* kd's integer */
    kd -= ROUND_SHIFT;
    double r = (x - kd * EXP_LN2_OVER_N[0]) - kd * EXP_LN2_OVER_N[1] + xl;
    const double *a = EXP_TAYLOR;
    double r2 = r * r;
    double p = r + (r2 * (a[0] + r * a[1]) + (r2 * r2) * (a[2] + r * a[3]));
    const double *entry = EXP_TABLE + 2 * (k & 127);
    *t = entry[0];
    *c = entry[0] * p + entry[1];
    return (k - (k & 127)) / 128;
}

/* 2^m (t + c), t + c in [0.99, 2.01]: exact scaling where the result is normal, one more rounding
 * where it is subnormal. */
FUNCTION double exp_scale(int64_t m, double t, double c) {
    double v = t + c;
    if (m > 1023) return (v * 2.0) * power_of_two((int)m - 1);
    if (m < -1021) return (v * power_of_two((int)m + 64)) * power_of_two(-64);
    return v * power_of_two((int)m);
}

/* exp(x + xl), |xl| <= 2^-50 |x| */
FUNCTION double exp_tail(double x, double xl) {
    double t, c;
    if (fabs(x) < 708.0) { /* the result is normal: no test on m */
        int64_t m = exp_parts(x, xl, &t, &c);
        return power_of_two((int)m) * (t + c);
    }
    if (!(x < 709.8)) return x != x ? x + x : HUGE_VAL;
    if (x < -745.2) return 0.0;
    int64_t m = exp_parts(x, xl, &t, &c);
    return exp_scale(m, t, c);
}

FUNCTION double rcm_exp(double x) {
    return exp_tail(x, 0.0);
}

/* ---- log ------------------------------------------------------------------------------------
 * x = 2^k (1 + f), 1 + f in [sqrt(1/2), sqrt(2)) (f exact); c = 1 + j/128, j = f 128 rounded
 * toward 0 (c between 1 and 1 + f), d = f - j/128 exact, |d| < 1/128; log x = k ln2 + log c +
 * log(1 + g), g = d/c (d times the table's 1/c; j = 0: g = f exactly), |g| < 2^-6.5, log(1 + g) =
 * g - g^2/2 + ... - g^10/10 (the next term below 2^-60 g). k ln2 + log c: their leading parts lie
 * on the grid 2^-42, so their sum is exact, and their remainders are added with the small terms:
 * no division, and log(1 + g) has the sign of log c (no cancellation). */
KERNEL int log_reduce(double x, double *f) {
    int scale = 0;
    if (x < 0x1p-1022) { /* subnormal */
        x *= 0x1p54;
        scale = 54;
    }
    /* k and m = x/2^k in [sqrt(1/2), sqrt(2)) from the bits, without a branch: the exponent of
     * x/sqrt(1/2) by an integer subtraction of sqrt(1/2)'s bits (0x3fe6a09e667f3bcd) */
    uint64_t u = bits_of(x);
    int k = (int)((u + (0x400ULL << 52) - 0x3fe6a09e667f3bcdULL) >> 52) - 0x400; /* 0x400: kept positive */
    double m = double_of(u - ((uint64_t)(int64_t)k << 52));
    *f = m - 1.0; /* exact (Sterbenz) */
    return k - scale;
}

/* log(1 + g) - g = g^2 (a0 + a1 g + ... + a8 g^8), a_i = (-1)^i / (i + 2), Estrin's scheme */
KERNEL double log1p_series(double g) {
    const double *a = LOG1P_TAYLOR;
    double g2 = g * g, g4 = g2 * g2, g8 = g4 * g4;
    return g2 * (((a[0] + g * a[1]) + g2 * (a[2] + g * a[3])) + g4 * ((a[4] + g * a[5]) + g2 * (a[6] + g * a[7]))
                 + g8 * a[8]);
}

/* NaN for negative x and NaN, -inf for zero, +inf for +inf; else 0 */
FUNCTION int log_special(double x, double *result) {
    if (x != x || x < 0.0) {
        *result = x != x ? x + x : (x - x) / (x - x);
        return 1;
    }
    if (x == 0.0) {
        *result = -HUGE_VAL;
        return 1;
    }
    if (x == HUGE_VAL) {
        *result = x;
        return 1;
    }
    return 0;
}

/* The reduction of x > 0 (finite): returns g; *entry the table's row of c (1/c, log c's leading
 * part on the grid, its rest), *d, *kd (k as a double), *j. */
KERNEL double log_argument(double x, const double **entry, double *d, double *kd, int *j) {
    double f;
    int k = log_reduce(x, &f);
    *j = (int)(f * 128.0); /* toward 0 */
    *d = f - (double)*j * 0.0078125;
    *entry = LOG_TABLE + 3 * (*j + 37);
    *kd = (double)k;
    return *d * (*entry)[0];
}

FUNCTION double rcm_log(double x) {
    double special;
    if (log_special(x, &special)) return special;
    const double *entry;
    double d, kd;
    int j;
    double g = log_argument(x, &entry, &d, &kd, &j);
    double a = kd * LN2[0] + entry[1]; /* exact: both on the grid 2^-42 */
    double e, hi = two_sum(a, g, &e);
    return hi + (e + (log1p_series(g) + (kd * LN2[1] + entry[2])));
}

/* log(x) = hi + *lo to about 2^-66 relative, for pow: g carried with its rounding error g_lo (d/c
 * = g + g_lo exactly to 2^-106), log(1 + g + g_lo) = g + g_lo (1 - g) + (log(1 + g) - g). */
FUNCTION double log_extended(double x, double *lo) {
    const double *entry;
    double d, kd;
    int j;
    double g = log_argument(x, &entry, &d, &kd, &j);
    double g_lo = 0.0;
    if (j != 0) {
        double pe, p = two_product(g, 1.0 + (double)j * 0.0078125, &pe);
        g_lo = ((d - p) - pe) * entry[0];
    }
    double a = kd * LN2[0] + entry[1];
    double e, hi = two_sum(a, g, &e);
    double rest = e + (g_lo - g * g_lo + (log1p_series(g) + (kd * LN2[1] + entry[2])));
    return fast_two_sum(hi, rest, lo);
}

/* ---- pow (C99 Annex F's special cases, then exp(y log x) with log and the product extended) -- */
FUNCTION int is_integer(double y) {
    return fabs(y) >= 0x1p52 || (double)(int64_t)y == y;
}

FUNCTION int is_odd_integer(double y) {
    return fabs(y) < 0x1p53 && (double)(int64_t)y == y && ((int64_t)y & 1);
}

FUNCTION double rcm_pow(double x, double y) {
    if (y == 0.0 || x == 1.0) return 1.0;
    if (x != x || y != y) return x + y;
    double ax = fabs(x);
    if (y == HUGE_VAL || y == -HUGE_VAL) {
        if (ax == 1.0) return 1.0;
        return (ax < 1.0) == (y > 0.0) ? 0.0 : HUGE_VAL;
    }
    int negative = 0;
    if (sign_bit(x)) { /* negative, -0 or -inf */
        if (!is_integer(y)) return x == 0.0 || x == -HUGE_VAL ? rcm_pow(ax, y) : (x - x) / (x - x);
        negative = is_odd_integer(y);
    }
    double magnitude;
    if (ax == 0.0) {
        magnitude = y < 0.0 ? HUGE_VAL : 0.0;
    } else if (ax == HUGE_VAL) {
        magnitude = y < 0.0 ? 0.0 : HUGE_VAL;
    } else {
        double l_lo, l = log_extended(ax, &l_lo);
        double estimate = y * l;
        if (estimate > 710.0 || estimate < -746.0) return negative ? -exp_tail(estimate, 0.0) : exp_tail(estimate, 0.0);
        double e, product = two_product(y, l, &e);
        e += y * l_lo;
        double tail, head = fast_two_sum(product, e, &tail);
        magnitude = exp_tail(head, tail);
    }
    return negative ? -magnitude : magnitude;
}

/* ---- sin, cos, tan ----------------------------------------------------------------------------
 * x = n pi/2 + (r + rt), |r| <= pi/4 (+1 ulp), n mod 4 returned: pi/2 in parts of 33, 33 and 53
 * bits, n pi/2's first two parts exact for |n| < 2^20; beyond 2^19 pi/2 the C library's. */
#define REDUCTION_LIMIT 823549.0

KERNEL int reduce_half_pi(double x, double *r, double *rt) {
    if (fabs(x) <= 0.78539816339744828) {
        *r = x;
        *rt = 0.0;
        return 0;
    }
    double nd = x * TWO_OVER_PI[0] + ROUND_SHIFT;
    nd -= ROUND_SHIFT;
    double a = x - nd * PIO2_PARTS[0]; /* exact */
    double e, s = two_sum(a, -(nd * PIO2_PARTS[1]), &e);
    *r = two_sum(s, e - nd * PIO2_PARTS[2], rt);
    return (int)((int64_t)nd & 3);
}

/* sin(r + rt) = r + *lo, *lo = r^3 S(r^2) + rt (1 - r^2/2), Taylor to r^17 */
KERNEL double sin_parts(double r, double rt, double *lo) {
    const double *a = SIN_TAYLOR;
    double z = r * r;
    double v = z * r;
    double z2 = z * z, z4 = z2 * z2;
    double s = ((a[0] + z * a[1]) + z2 * (a[2] + z * a[3])) + z4 * ((a[4] + z * a[5]) + z2 * (a[6] + z * a[7]));
    *lo = v * s + rt * (1.0 - 0.5 * z);
    return r;
}

KERNEL double sin_kernel(double r, double rt) {
    double lo, hi = sin_parts(r, rt, &lo);
    return hi + lo;
}

/* cos(r + rt) = w + *lo, w = 1 - r^2/2 rounded and *lo the rest: w's rounding error, r^4 C(r^2)
 * (Taylor to r^16) and -r rt; r^2 exact as z + z_lo */
KERNEL double cos_parts(double r, double rt, double *lo) {
    const double *a = COS_TAYLOR;
    double z_lo, z = two_product(r, r, &z_lo);
    double z2 = z * z, z4 = z2 * z2;
    double c = ((a[0] + z * a[1]) + z2 * (a[2] + z * a[3])) + z4 * ((a[4] + z * a[5]) + z2 * a[6]);
    double hz = 0.5 * z;
    double w = 1.0 - hz;
    *lo = ((1.0 - w) - hz) + (z2 * c - (r * rt + 0.5 * z_lo));
    return w;
}

KERNEL double cos_kernel(double r, double rt) {
    double lo, hi = cos_parts(r, rt, &lo);
    return hi + lo;
}

FUNCTION double rcm_sin(double x) {
    if (fabs(x) < 0x1p-26) return x; /* sin x = x correctly rounded; keeps -0 */
    if (!(fabs(x) < REDUCTION_LIMIT)) return x - x == 0.0 ? sin(x) : x - x;
    double r, rt;
    switch (reduce_half_pi(x, &r, &rt)) {
    case 0: return sin_kernel(r, rt);
    case 1: return cos_kernel(r, rt);
    case 2: return -sin_kernel(r, rt);
    default: return -cos_kernel(r, rt);
    }
}

FUNCTION double rcm_cos(double x) {
    if (fabs(x) < 0x1p-27) return 1.0;
    if (!(fabs(x) < REDUCTION_LIMIT)) return x - x == 0.0 ? cos(x) : x - x;
    double r, rt;
    switch (reduce_half_pi(x, &r, &rt)) {
    case 0: return cos_kernel(r, rt);
    case 1: return -sin_kernel(r, rt);
    case 2: return -cos_kernel(r, rt);
    default: return sin_kernel(r, rt);
    }
}

FUNCTION double rcm_tan(double x) {
    if (fabs(x) < 0x1p-27) return x;
    if (!(fabs(x) < REDUCTION_LIMIT)) return x - x == 0.0 ? tan(x) : x - x;
    double r, rt;
    int n = reduce_half_pi(x, &r, &rt);
    double s_lo, s = sin_parts(r, rt, &s_lo);
    double c_lo, c = cos_parts(r, rt, &c_lo);
    s = fast_two_sum(s, s_lo, &s_lo); /* each a sum and its rounding error */
    c = fast_two_sum(c, c_lo, &c_lo);
    if (n & 1) { /* -cos/sin */
        double t = c, t_lo = c_lo;
        c = -s, c_lo = -s_lo;
        s = t, s_lo = t_lo;
    }
    /* (s + s_lo)/(c + c_lo) = q + its error, as ratio() does */
    double q = s / c;
    double pe, p = two_product(q, c, &pe);
    return q + (((s - p) - pe) + (s_lo - q * c_lo)) / c;
}

/* ---- atan, atan2, asin, acos ---------------------------------------------------------------
 * atan(t + t_lo), t in [0, 1]: the nearest breakpoint c of 0, 1/4, 1/2, 3/4, 1 and atan(t) =
 * atan(c) + atan(u), u = (t - c)/(1 + t c) (t - c exact; u carried with its rounding error u_lo),
 * |u| <= 1/8; atan(u + u_lo) = u + u^3 Q(u^2) + u_lo (1 - u^2), Taylor to u^21. Returned as
 * hi + *lo. */
KERNEL double atan_unit(double t, double t_lo, double *lo) {
    int i = (int)(t * 4.0 + 0.5);
    double u = t, u_lo = t_lo, head = 0.0, head_lo = 0.0;
    if (i > 0) {
        double c = ATAN_BREAKPOINT[i - 1];
        double num = t - c; /* exact (Sterbenz) */
        double pe, p = two_product(t, c, &pe);
        double de, den = two_sum(1.0, p, &de);
        double den_lo = de + pe + t_lo * c;
        u = num / den;
        double re, r = two_product(u, den, &re);
        u_lo = (((num - r) - re) + t_lo - u * den_lo) / den;
        head = ATAN_OF_BREAKPOINT[2 * (i - 1)];
        head_lo = ATAN_OF_BREAKPOINT[2 * (i - 1) + 1];
    }
    const double *a = ATAN_TAYLOR;
    double z = u * u;
    double z2 = z * z, z4 = z2 * z2, z8 = z4 * z4;
    double q = ((a[0] + z * a[1]) + z2 * (a[2] + z * a[3])) + z4 * ((a[4] + z * a[5]) + z2 * (a[6] + z * a[7]))
               + z8 * (a[8] + z * a[9]);
    double e, sum = two_sum(head, u, &e);
    return fast_two_sum(sum, e + ((u * z * q + u_lo * (1.0 - z)) + head_lo), lo);
}

/* (n + n_lo)/(d + d_lo) = q + *lo for 0 < n <= d (finite; the lo parts below their ulp): q
 * rounded, *lo its error (0 where the ratio is below 2^-60, whose atan is the ratio itself); n and
 * d scaled by a power of two first, so that the exact product below neither overflows nor
 * underflows. */
KERNEL double ratio(double n, double n_lo, double d, double d_lo, double *lo) {
    double q = n / d;
    *lo = 0.0;
    if (n < d * 0x1p-60) return q;
    int e = (int)((bits_of(d) >> 52) & 0x7ff) - 1023;
    double scale = power_of_two(-e);
    double ns = n * scale, ds = d * scale;
    double pe, p = two_product(q, ds, &pe);
    *lo = (((ns - p) - pe) + (n_lo - q * d_lo) * scale) / ds;
    return q;
}

/* atan((n + n_lo)/(d + d_lo)) for n, d > 0 (finite) as hi + *lo: atan(d/n) reflected about pi/2
 * when n > d */
FUNCTION double atan_ratio(double n, double n_lo, double d, double d_lo, double *lo) {
    double q_lo;
    if (n <= d) {
        double q = ratio(n, n_lo, d, d_lo, &q_lo);
        return atan_unit(q, q_lo, lo);
    }
    double q = ratio(d, d_lo, n, n_lo, &q_lo);
    double l, h = atan_unit(q, q_lo, &l);
    double e, s = two_sum(PI_OVER_2[0], -h, &e);
    return fast_two_sum(s, e + (PI_OVER_2[1] - l), lo);
}

FUNCTION double rcm_atan2(double y, double x) {
    if (x != x || y != y) return x + y;
    double ay = fabs(y), ax = fabs(x);
    double angle;
    if (ay == HUGE_VAL) {
        angle = ax == HUGE_VAL ? (x > 0.0 ? 0.78539816339744828 : THREE_PI_OVER_4[0]) : PI_OVER_2[0];
    } else if (ax == HUGE_VAL) {
        angle = x > 0.0 ? 0.0 : PI[0];
    } else if (ay == 0.0) {
        angle = sign_bit(x) ? PI[0] : 0.0;
    } else if (ax == 0.0) {
        angle = PI_OVER_2[0];
    } else {
        double lo, hi = atan_ratio(ay, 0.0, ax, 0.0, &lo);
        if (x < 0.0) {
            double e, s = two_sum(PI[0], -hi, &e);
            angle = s + (e + (PI[1] - lo));
        } else {
            angle = hi + lo;
        }
    }
    return sign_bit(y) ? -angle : angle;
}

FUNCTION double rcm_atan(double x) {
    if (fabs(x) < 0x1p-27) return x;
    return rcm_atan2(x, 1.0);
}

/* sqrt(1 - x^2) = c + *lo for |x| <= 1: 1 - x^2 as (1 - |x|)(1 + |x|) for |x| >= 1/2 (1 - |x|
 * exact) or 1 - x x below, each with its rounding error, then the square root corrected by it */
KERNEL double cosine_of_asin(double x, double *lo) {
    double ax = fabs(x), a, a_lo;
    if (ax >= 0.5) {
        double om = 1.0 - ax;
        double be, b = two_sum(1.0, ax, &be);
        double pe;
        a = two_product(om, b, &pe);
        a_lo = pe + om * be;
    } else {
        double x2e, x2 = two_product(ax, ax, &x2e);
        double ae;
        a = two_sum(1.0, -x2, &ae);
        a_lo = ae - x2e;
    }
    double c = sqrt(a);
    *lo = 0.0;
    if (c > 0.0) {
        double ce, cc = two_product(c, c, &ce);
        *lo = (((a - cc) - ce) + a_lo) / (2.0 * c);
    }
    return c;
}

/* asin(x) = atan2(x, sqrt(1 - x^2)), acos(x) = atan2(sqrt(1 - x^2), x), the square root carried
 * with its rounding error */
FUNCTION double rcm_asin(double x) {
    if (x != x) return x + x;
    if (fabs(x) > 1.0) return (x - x) / (x - x);
    if (fabs(x) < 0x1p-26) return x;
    double c_lo, c = cosine_of_asin(x, &c_lo);
    double angle = PI_OVER_2[0];
    if (c > 0.0) {
        double lo, hi = atan_ratio(fabs(x), 0.0, c, c_lo, &lo);
        angle = hi + lo;
    }
    return sign_bit(x) ? -angle : angle;
}

FUNCTION double rcm_acos(double x) {
    if (x != x) return x + x;
    if (fabs(x) > 1.0) return (x - x) / (x - x);
    if (x == 0.0) return PI_OVER_2[0];
    double c_lo, c = cosine_of_asin(x, &c_lo);
    if (c == 0.0) return x > 0.0 ? 0.0 : PI[0];
    double lo, hi = atan_ratio(c, c_lo, fabs(x), 0.0, &lo);
    if (x > 0.0) return hi + lo;
    double e, s = two_sum(PI[0], -hi, &e);
    return s + (e + (PI[1] - lo));
}

/* ---- tanh ------------------------------------------------------------------------------------
 * |x| < 2^-8: x + x^3 (-1/3 + x^2 (2/15 - 17 x^2/315)) (the next term is below 2^-60 x);
 * else e = expm1(2|x|) from exp's parts (2^m t - 1 and 2^m c summed exactly), tanh = e/(e + 2)
 * with e and e + 2 carried with their rounding errors; 1 beyond 22. */
FUNCTION double rcm_tanh(double x) {
    if (x != x) return x + x;
    double ax = fabs(x);
    double result;
    if (ax < 0x1p-27) {
        return x;
    } else if (ax < 0x1p-8) {
        double z = x * x;
        return x + x * z * (TANH_TAYLOR[0] + z * (TANH_TAYLOR[1] + z * TANH_TAYLOR[2]));
    } else if (ax > 22.0) {
        result = 1.0;
    } else {
        double t, c;
        double scale = power_of_two((int)exp_parts(2.0 * ax, 0.0, &t, &c));
        double e1, h1 = two_sum(scale * t, -1.0, &e1); /* scale t exact */
        double e2, em1 = two_sum(h1, scale * c, &e2);
        double em1_lo = e1 + e2;
        double de, den = two_sum(em1, 2.0, &de);
        double den_lo = de + em1_lo;
        double q = em1 / den; /* (em1 + em1_lo)/(den + den_lo) = q + its error */
        double pe, p = two_product(q, den, &pe);
        result = q + (((em1 - p) - pe) + (em1_lo - q * den_lo)) / den;
    }
    return x < 0.0 ? -result : result;
}

#endif
