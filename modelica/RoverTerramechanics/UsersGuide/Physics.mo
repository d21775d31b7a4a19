within RoverTerramechanics.UsersGuide;
class Physics "How the physics is written: no events, no algebraic loops, every motion regime"
  annotation (Documentation(info="<html>
<ul>
<li><strong>No events, no algebraic loops.</strong> <code>slipRatio</code> floors its
denominator at <code>vEps</code> and uses <code>noEvent</code>; the sinkage is found inside the
function <code>wheelContact</code> by at most <code>nIterations</code> force evaluations (Newton
with Bekker's slope first, then secant, bisection whenever a step leaves the bracket), so the
models only contain explicit equations and ODEs.</li>
<li><strong>Quadrature.</strong> <code>contactForces</code> integrates [&theta;<sub>r</sub>,
&theta;<sub>m</sub>] and [&theta;<sub>m</sub>, &theta;<sub>f</sub>] separately (&sigma; has a
kink at &theta;<sub>m</sub>), each by Gauss-Legendre with <code>nNodes</code> nodes
(<code>gaussLegendre</code>, folded into constants when the model is translated) in s =
u<sup>2</sup>, counted from the end of the piece where &sigma; vanishes, as the numpy reference
does; the rear node's equivalent front angle of Eq. (6) is the front node's, so &sigma; is
evaluated once per pair. The default 10 nodes were chosen by measured error
(<code>benchmarks/bench_quadrature.py</code>, every soil and wheel of the library, loads, slips and
slip angles: within 1.3e-8 of the load in F<sub>x</sub>; every printed digit of the paper's tables
kept, the closed loop faster than with 16). Measured by rumoca probes against 96 nodes of the numpy
reference on the Table 2 soil (sinkage 1 mm to 0.3 m), the largest error of F<sub>x</sub> and
F<sub>z</sub> relative to F<sub>z</sub> at 10 (16) nodes: driving 8e-8 (4e-13); skidding, where the
shear stress has a kink at j<sub>x</sub> = 0 that the quadrature does not split at (the numpy
reference does), 2.2e-5 (6e-6) up to h = 0.1 m, 4.2e-4 (1.1e-4) up to r/2 and 2.2e-3 (5.5e-4)
deeper. Splitting there too would cost the FMUs' C code eight times the compile time (docs:
design/terramechanics). <code>nNodes</code> is a structural parameter (a loop bound): change
it by a modifier in the source, not at run time.</li>
<li><strong>Shear while skidding.</strong> Eq. (9) is applied with the sign of j<sub>x</sub>
(|&tau;| &le; c + &sigma; tan&phi;), as in the numpy reference: read literally, Eq. (9) grows
like exp(|j<sub>x</sub>|/k<sub>x</sub>) and gives drawbar forces of about 1e8 N for a locked
wheel. The reasoning, with the other choices where the paper is silent: the page <em>The
terramechanics wheel</em> of the documentation site (<code>docs/guide/wheel.md</code>, &quot;The
reference wheel&quot;).</li>
<li><strong>Every motion regime</strong> (<code>wheelForces</code>, the same formulation as
<code>terramechanics.wheel_forces</code>). The paper's forces describe a wheel rolling forwards.
They are applied to the mirrored wheel, d&middot;F(W, d&middot;&kappa;) with d = sign(v) (sign of
&omega; at v = 0), so the entry side follows the travel and reverse mirrors forward; and below
<code>vHold</code> (1 mm/s) they blend, with the weight &beta; = u(2 - u), u = min(|v|/vHold, 1),
into a static regime where the soil holds the rim like regularised static friction up to the
patch's Mohr-Coulomb strength: F<sub>static</sub> = F<sub>max</sub>&middot;tanh((r&omega; -
v)/vStick), F<sub>max</sub> = c&middot;b&middot;L + W&middot;tan&phi; (Wong's maximum thrust), L =
r(&theta;<sub>f</sub> - &theta;<sub>r</sub>). Karnopp's stick band in the smooth form of
low-speed tyre models (Bernard and Clover 1995; Pacejka 2012). A wheel at rest stays at rest, a
free-rolling wheel stops without turning back, a holding torque keeps it on a slope, and neither
regime ever gives energy to the wheel and its carrier. The checks, regime by regime: <em>The
terramechanics wheel</em>, &quot;The wheel in every motion regime&quot;.</li>
<li><strong>Lateral force</strong> (Ishigami et al. 2007): <code>lateralShear</code> and the
sidewall term of <code>contactForces</code> give Fy from the hub's slip angle; at slip angle 0
every other output is the paper's and Fy = 0. The model and its choices: <em>The terramechanics
wheel</em>, &quot;Lateral force&quot;.</li>
<li><strong>Parameter checks.</strong> <code>assert</code>s in <code>RigidWheel</code>,
<code>Chassis</code>, <code>SteerableChassis</code> and <code>SingleWheel</code> hold the ranges
of <code>terramechanics.Soil</code> / <code>Wheel</code> and the rover's (mass, gravity, inertia,
limb stiffness and damping, slope in (-&pi;/2, &pi;/2)) and that the soil carries the load with a
sinkage below r. The FMU exporter compiles them; the FMU reports a failing one at
<code>fmi2ExitInitializationMode</code> (and after each step for the load) as
<code>fmi2Error</code> with the values the condition reads.</li>
<li><strong>Angles</strong> are measured from the downward vertical through the axle, positive
towards the direction of travel: the entry angle is positive, the exit angle negative.</li>
</ul>
</html>"));
end Physics;
