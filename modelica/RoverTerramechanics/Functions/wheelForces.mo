within RoverTerramechanics.Functions;
function wheelForces "Contact of the wheel in every motion regime: driving, braking, free rolling, reverse and standstill"
  input Real W(unit="N") "Vertical load on the wheel";
  input Real omega(unit="rad/s") "Wheel spin";
  input Real v(unit="m/s") "Forward speed of the wheel hub";
  input RoverTerramechanics.Parameters.SoilParameters soil "Soil";
  input RoverTerramechanics.Parameters.WheelParameters wheel "Wheel";
  input Real vEps(unit="m/s") = 1e-3 "Regularising speed of the slip ratio";
  input Real vHold(unit="m/s") = 1e-3 "Transition speed: below it the steady forces blend into the static regime";
  input Real vStick(unit="m/s") = 1e-4 "Slip speed at which the static shear reaches tanh(1) of its limit";
  input Integer nNodes = 10 "Gauss-Legendre nodes per piece of the contact patch";
  input Integer nIterations = 12 "Bound on the force evaluations of the sinkage solve";
  input Real vLat(unit="m/s") = 0 "Speed of the hub to the wheel's left (lateral, in the wheel frame)";
  input Real logSinkageStart(unit="1") = 0 "Start of the sinkage solve, log(h / 1 m) (warm start: the previous logSinkage)";
  input Real slopeStart(unit="1") = 0 "> 0: warm start with this slope d log Fz / d log h (the previous contactSlope); <= 0: cold start";
  input Real rutDepth(unit="m") = 0 "Depth of the rut a previous wheel left where this one rolls (multi-pass); 0: virgin soil";
  output Real slip(unit="1") "Slip ratio, Eq. (4)";
  output Real h(unit="m") "Sinkage below the undisturbed surface: the rut's depth and the sinkage below its floor";
  output Real Fx(unit="N") "Longitudinal force of the soil on the wheel";
  output Real Fz(unit="N") "Vertical force of the soil on the wheel (= W)";
  output Real Tx(unit="N.m") "Resistance torque of the soil about the axle";
  output Real entryAngle(unit="rad") "Entry angle, signed: positive ahead of the axle, negative behind it when reversing";
  output Real Fy(unit="N") "Lateral force of the soil on the wheel, along its left";
  output Real slipAngle(unit="rad") "Slip angle of the hub velocity, seen from the direction of travel";
  output Real contactEvaluations(unit="1") "Force evaluations of the sinkage solve";
  output Real logSinkage(unit="1") "log(h / 1 m) from the sinkage solve (a start for the next solve)";
  output Real contactSlope(unit="1") "d log Fz / d log h near the sinkage (a start for the next solve)";
protected
  Real hFloor(unit="m") "Sinkage below the rut's floor (the undisturbed surface without a rut)";
  Real direction "+1 travelling forwards, -1 backwards";
  Real FxSteady(unit="N") "Paper's Fx of the mirrored wheel";
  Real TxSteady(unit="N.m") "Paper's Tx of the mirrored wheel";
  Real FySteady(unit="N") "Ishigami's Fy of the mirrored wheel";
  Real FySidewall(unit="N") "Its sidewall part";
  Real thetaF(unit="rad") "Entry angle, Eq. (1)";
  Real thetaR(unit="rad") "Exit angle, Eq. (2)";
  Real strength(unit="N") "Mohr-Coulomb strength of the patch, c b L + W tan(phi)";
  Real staticShear(unit="N") "Hold of the soil on the rim";
  Real u(unit="1") "Speed relative to vHold, at most 1";
  Real weight(unit="1") "Weight of the steady forces";
algorithm
  slip := slipRatio(wheel.r*omega, v, vEps);
  direction := if noEvent(v > 0) then 1.0 else if noEvent(v < 0) then -1.0 else if noEvent(omega < 0) then -1.0 else 1.0;
  slipAngle := atan2(direction*vLat, noEvent(max(abs(v), vEps)));
  (hFloor, FxSteady, Fz, TxSteady, FySteady, FySidewall, contactEvaluations, logSinkage, contactSlope) := wheelContact(W,
    direction*slip, soil, wheel, nNodes, nIterations, 1e-10, 1e-3, slipAngle, logSinkageStart, slopeStart, rutDepth);
  h := hFloor + rutDepth;
  thetaF := acos(1 - hFloor/wheel.r);
  thetaR := -acos(1 - soil.lam*hFloor/wheel.r);
  entryAngle := direction*thetaF;
  strength := soil.c*wheel.b*wheel.r*(thetaF - thetaR) + noEvent(max(W, 0.0))*tan(soil.phi);
  staticShear := strength*tanh((wheel.r*omega - v)/vStick);
  u := noEvent(min(abs(v)/vHold, 1.0));
  weight := u*(2 - u);
  Fx := weight*direction*FxSteady + (1 - weight)*staticShear;
  Tx := weight*direction*TxSteady + (1 - weight)*wheel.r*staticShear;
  Fy := weight*direction*FySteady - (1 - weight)*strength*tanh(vLat/vStick);
  annotation (Documentation(info="<html>
<p>The paper's forces (Eqs. 1-13, <code>wheelContact</code>) describe a wheel rolling forwards
with the soil entering at the front. Two additions make the wheel a drop-in component in any
motion regime, with the same formulation as the Python reference
<code>terramechanics.wheel_forces</code>:</p>
<ol>
<li>Direction of travel: the steady forces are those of the mirrored wheel,
d F(W, d &kappa;) with d = sign(v) (the sign of &omega; when v = 0), so the entry side follows
the hub and driving backwards mirrors driving forwards.</li>
<li>Standstill: below <code>vHold</code> the steady forces blend into a static regime, the soil
holding the rim like regularised static friction up to the Mohr-Coulomb strength of the patch
(Wong, <i>Theory of Ground Vehicles</i>: maximum thrust A c + W tan &phi;):
F<sub>static</sub> = F<sub>max</sub> tanh((r&omega; - v)/v<sub>stick</sub>), F<sub>max</sub> =
c b L + W tan &phi;, L = r(&theta;<sub>f</sub> - &theta;<sub>r</sub>);
F<sub>x</sub> = &beta; F<sub>steady</sub> + (1 - &beta;) F<sub>static</sub>, T<sub>x</sub> =
&beta; T<sub>steady</sub> + (1 - &beta;) r F<sub>static</sub>, &beta; = u(2 - u), u = min(|v|/v<sub>hold</sub>, 1).</li>
</ol>
<p>Lateral: the slip angle &beta; = atan2(d v<sub>lat</sub>, max(|v|, vEps)), Ishigami's F<sub>y</sub>
of the mirrored wheel (<code>contactForces</code>) turned back by d, and below vHold the static
lateral hold -F<sub>max</sub> tanh(v<sub>lat</sub>/vStick).</p>
<p>Above vHold the forces are exactly the paper's. The stick band is Karnopp's (1985, ASME J. Dyn.
Syst. Meas. Control 107), in the smooth form of low-speed tyre models that fade the rolling forces
out below a threshold speed (Bernard and Clover 1995, SAE 950311; Pacejka, <i>Tire and Vehicle
Dynamics</i>, 2012). Both regimes only take energy out of the wheel and its carrier: a wheel at
rest stays at rest, a free-rolling wheel slows down to rest without turning back, and a holding
torque keeps it on a slope (the spin creeps at a fraction of vStick while the hub stays).</p>
</html>"));
end wheelForces;
