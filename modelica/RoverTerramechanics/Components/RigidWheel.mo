within RoverTerramechanics.Components;
model RigidWheel "Terramechanics rigid wheel: spin dynamics with inertia J, drive torque in, contact forces, slip and sinkage out, in every motion regime"
  extends RoverTerramechanics.Interfaces.WheelHub;
  parameter RoverTerramechanics.Parameters.SoilParameters soil "Soil (Table 2): the soil under the wheel where soilShare = 0";
  parameter RoverTerramechanics.Parameters.SoilParameters soilB "Second soil: the soil under the wheel where soilShare = 1 (default Table 2's)";
  parameter RoverTerramechanics.Parameters.WheelParameters wheel "Wheel (Table 2)";
  parameter Integer nNodes = 10 "Gauss-Legendre nodes per piece of the contact patch";
  parameter Integer nIterations = 12 "Bound on the force evaluations of the sinkage solve";
  parameter Real vEps(unit="m/s") = 1e-3 "Regularising speed of the slip ratio";
  parameter Real vHold(unit="m/s") = 1e-3 "Transition speed: below it the steady forces blend into the static regime";
  parameter Real vStick(unit="m/s") = 1e-4 "Slip speed at which the static shear reaches tanh(1) of its limit";
  Real contactEvaluations(unit="1") "Force evaluations of the sinkage solve at this point (a cost, for benchmarks)";
  Real logSinkage(unit="1") "log(sinkage / 1 m), the sinkage solve's last iterate";
  Real contactSlope(unit="1") "d log Fz / d log h near the sinkage, from the solve";
  Real logSinkageStart(unit="1") = 0 "Start of the sinkage solve, log(h / 1 m); rover-cosim FMUs hold the logSinkage of the previous step here"
    annotation (__RoverCosim(previous="logSinkage"));
  Real slopeStart(unit="1") = 0 "0: cold start of the sinkage solve (Bekker's sinkage); rover-cosim FMUs hold the contactSlope of the previous step here (warm start)"
    annotation (__RoverCosim(previous="contactSlope"));
equation
  // The soil under the wheel: each parameter (1 - soilShare) soil + soilShare soilB (exact at 0 and 1);
  // xc blends each soil's own angle (its 0 stands for 45 deg - phi/2 of that soil), as Soil.blend does:
  // blending the raw 0 with a given angle made an angle of almost 0 near soilShare 0 (sidewall force ~ 1/xc^3)
  (slip, sinkage, Fx, Fz, Tx, entryAngle, Fy, slipAngle, contactEvaluations, logSinkage, contactSlope) = RoverTerramechanics.Functions.wheelForces(W, omega, v_hub,
    RoverTerramechanics.Parameters.SoilParameters(
      c=(1 - soilShare)*soil.c + soilShare*soilB.c, phi=(1 - soilShare)*soil.phi + soilShare*soilB.phi, kc=(1 - soilShare)*soil.kc + soilShare*soilB.kc,
      kphi=(1 - soilShare)*soil.kphi + soilShare*soilB.kphi, n=(1 - soilShare)*soil.n + soilShare*soilB.n, kx=(1 - soilShare)*soil.kx + soilShare*soilB.kx,
      a0=(1 - soilShare)*soil.a0 + soilShare*soilB.a0, a1=(1 - soilShare)*soil.a1 + soilShare*soilB.a1, lam=(1 - soilShare)*soil.lam + soilShare*soilB.lam,
      kxBeta=(1 - soilShare)*soil.kxBeta + soilShare*soilB.kxBeta, ky=(1 - soilShare)*soil.ky + soilShare*soilB.ky, kyBeta=(1 - soilShare)*soil.kyBeta + soilShare*soilB.kyBeta,
      rho=(1 - soilShare)*soil.rho + soilShare*soilB.rho, gravity=(1 - soilShare)*soil.gravity + soilShare*soilB.gravity, xc=(1 - soilShare)*RoverTerramechanics.Functions.destructiveAngle(soil.xc, soil.phi)
        + soilShare*RoverTerramechanics.Functions.destructiveAngle(soilB.xc, soilB.phi),
      nSlip=(1 - soilShare)*soil.nSlip + soilShare*soilB.nSlip),
    wheel, vEps, vHold, vStick, nNodes, nIterations, v_lat, logSinkageStart, slopeStart, rutDepth);
  wheel.J*der(omega) = tau - Tx;
  assert(soil.c >= 0, "soil.c: the cohesion must be >= 0 Pa");
  assert(soil.phi > 0 and soil.phi < 1.5707963267948966, "soil.phi: the internal friction angle must be in (0, pi/2) rad");
  assert(soil.kc >= 0, "soil.kc: the cohesive modulus must be >= 0 N/m^(n+1)");
  assert(soil.kphi > 0, "soil.kphi: the frictional modulus must be > 0 N/m^(n+2)");
  assert(soil.n > 0, "soil.n: the sinkage exponent must be > 0");
  assert(soil.kx > 0, "soil.kx: the shear deformation modulus must be > 0 m");
  assert(soil.a0 > 0 and soil.a0 < 1, "soil.a0: must be in (0, 1)");
  assert(soil.a1 >= 0 and soil.a1 < soil.a0 and soil.a0 + soil.a1 < 1, "soil.a1: must satisfy 0 <= a1 < min(a0, 1 - a0)");
  assert(soil.lam > 0 and soil.lam <= 1, "soil.lam: the exit-angle ratio must be in (0, 1]");
  assert(soil.kxBeta >= 0, "soil.kxBeta: must be >= 0 m/rad");
  assert(soil.ky > 0, "soil.ky: the lateral shear deformation modulus must be > 0 m");
  assert(soil.kyBeta >= 0, "soil.kyBeta: must be >= 0 m/rad");
  assert(soil.rho >= 0, "soil.rho: the dry density must be >= 0 kg/m3");
  assert(soil.gravity >= 0, "soil.gravity: must be >= 0 m/s2");
  assert(soil.xc >= 0 and soil.xc < 1.5707963267948966, "soil.xc: the destructive angle must be in (0, pi/2) rad, or 0 for 45 deg - phi/2");
  assert(soilB.c >= 0, "soilB.c: the cohesion must be >= 0 Pa");
  assert(soilB.phi > 0 and soilB.phi < 1.5707963267948966, "soilB.phi: the internal friction angle must be in (0, pi/2) rad");
  assert(soilB.kc >= 0, "soilB.kc: the cohesive modulus must be >= 0 N/m^(n+1)");
  assert(soilB.kphi > 0, "soilB.kphi: the frictional modulus must be > 0 N/m^(n+2)");
  assert(soilB.n > 0, "soilB.n: the sinkage exponent must be > 0");
  assert(soilB.kx > 0, "soilB.kx: the shear deformation modulus must be > 0 m");
  assert(soilB.a0 > 0 and soilB.a0 < 1, "soilB.a0: must be in (0, 1)");
  assert(soilB.a1 >= 0 and soilB.a1 < soilB.a0 and soilB.a0 + soilB.a1 < 1, "soilB.a1: must satisfy 0 <= a1 < min(a0, 1 - a0)");
  assert(soilB.lam > 0 and soilB.lam <= 1, "soilB.lam: the exit-angle ratio must be in (0, 1]");
  assert(soilB.kxBeta >= 0, "soilB.kxBeta: must be >= 0 m/rad");
  assert(soilB.ky > 0, "soilB.ky: the lateral shear deformation modulus must be > 0 m");
  assert(soilB.kyBeta >= 0, "soilB.kyBeta: must be >= 0 m/rad");
  assert(soilB.rho >= 0, "soilB.rho: the dry density must be >= 0 kg/m3");
  assert(soilB.gravity >= 0, "soilB.gravity: must be >= 0 m/s2");
  assert(soilB.xc >= 0 and soilB.xc < 1.5707963267948966, "soilB.xc: the destructive angle must be in (0, pi/2) rad, or 0 for 45 deg - phi/2");
  assert(soil.nSlip >= 0, "soil.nSlip: the slip-sinkage growth of the exponent must be >= 0");
  assert(soilB.nSlip >= 0, "soilB.nSlip: the slip-sinkage growth of the exponent must be >= 0");
  assert(noEvent(soilShare >= 0 and soilShare <= 1), "soilShare: the share of the second soil must be in [0, 1]");
  assert(noEvent(rutDepth >= 0 and rutDepth <= wheel.r), "rutDepth: the rut's depth must be in [0, wheel.r] m");
  assert(wheel.r > 0, "wheel.r: the radius must be > 0 m");
  assert(wheel.b > 0, "wheel.b: the width must be > 0 m");
  assert(wheel.J > 0, "wheel.J: the spin inertia must be > 0 kg.m2");
  assert(wheel.grouserHeight >= 0 and wheel.grouserHeight <= wheel.r/2, "wheel.grouserHeight: must be in [0, r/2] m");
  assert(wheel.grouserCount >= 0 and wheel.grouserCount <= 360 and wheel.grouserCount == floor(wheel.grouserCount), "wheel.grouserCount: must be a whole number in [0, 360]");
  assert(vEps > 0, "vEps: must be a speed > 0 m/s");
  assert(vHold > 0, "vHold: must be a speed > 0 m/s");
  assert(vStick > 0, "vStick: must be a speed > 0 m/s");
  assert(noEvent(Fz >= 0.999*W), "W: the soil cannot carry this load with a sinkage below the wheel radius; Fz is the most it carries (at h = r)");
  annotation (Documentation(info="<html>
<p>J d&omega;/dt = &tau; - T<sub>x</sub>, with the slip ratio of Eq. (4), the sinkage and the
contact forces from <code>Functions.wheelForces</code>: the paper's Eqs. (1)-(13) for a rolling
wheel (sinkage from F<sub>z</sub>(h, &kappa;) = W inside <code>wheelContact</code>, no algebraic
loop), mirrored for reverse travel and blended below <code>vHold</code> into a static regime
that holds the wheel at rest. The hub force on the carrier is F<sub>x</sub> forward; the load W
is carried by the soil (F<sub>z</sub> = W).</p>
<p>Warm start: <code>logSinkageStart</code> and <code>slopeStart</code> are only the start of the
sinkage solve (its result does not depend on them beyond the solve's tolerance). In Modelica they
are 0, the cold start from Bekker's sinkage. The vendor annotation
<code>__RoverCosim(previous=&quot;logSinkage&quot;)</code> asks the rover-cosim FMU exporter to hold there the
value the named variable had at the end of the previous step, kept per instance and saved with the
FMU state, so that a wheel rolling on needs fewer force evaluations per solve (about 4 cold).
Other tools ignore the annotation.</p>
<p>Soil that varies (issue 35): the soil under the wheel is a blend of two soils, each parameter
(1 - s) <code>soil</code> + s <code>soilB</code> with s = <code>soilShare</code> (an input, start 0:
the first soil, bit for bit). A soil map gives s from the wheel's position: 0 on the first soil, 1
on the second, a smooth ramp across their boundary, where the contact patch lies on both. The
blend of two valid soils is a valid soil (every range below is convex). X<sub>c</sub> blends each
soil's own angle, a soil's 0 standing for 45&deg; - &phi;/2 of its own &phi; (when both leave it at
0 that is 45&deg; - &phi;/2 of the blended &phi;: the angle is affine in &phi;); blending the raw 0
with a given angle would give an angle near 0 just inside the second soil, and a sidewall force
growing as 1/X<sub>c</sub><sup>3</sup>. The reference <code>terramechanics.Soil.blend</code> blends
the same way.</p>
<p>Parameter checks (asserts, reported by the FMUs at initialization with the value): the
ranges of <code>terramechanics.Soil</code> for both soils, soilShare in [0, 1], and <code>Wheel</code>, speeds &gt; 0, and a load
the soil carries with a sinkage below r.</p>
</html>"));
end RigidWheel;
