within RoverTerramechanics.Functions;
function contactResidual "Residual log(Fz/W) of the sinkage equation at a given log sinkage, with the contact forces there"
  input Real logSinkage(unit="1") "log(h / 1 m)";
  input Real W(unit="N") "Vertical load on the wheel (floored at WMin)";
  input Real slip(unit="1") "Slip ratio";
  input RoverTerramechanics.Parameters.SoilParameters soil "Soil";
  input RoverTerramechanics.Parameters.WheelParameters wheel "Wheel";
  input Integer nNodes = 10 "Gauss-Legendre nodes per piece of the contact patch";
  input Real WMin(unit="N") = 1e-3 "Smallest load considered (a lifted wheel)";
  input Real slipAngle(unit="rad") = 0 "Slip angle of the hub velocity (Ishigami et al. 2007)";
  input Real rutDepth(unit="m") = 0 "Depth of the rut a previous wheel left (multi-pass); h below its floor";
  input Boolean lateralAtZero = true "Evaluate the lateral terms at beta = 0 too (see contactForces)";
  output Real residual(unit="1") "log(Fz/W); -1e3 where Fz <= 0 (a skidding wheel barely sunk)";
  output Real h(unit="m") "Sinkage, exp(logSinkage)";
  output Real Fx(unit="N") "Longitudinal force at h, Eq. (12)";
  output Real Fz(unit="N") "Vertical force at h, Eq. (11)";
  output Real Tx(unit="N.m") "Resistance torque at h, Eq. (13)";
  output Real Fy(unit="N") "Lateral force at h";
  output Real FySidewall(unit="N") "Sidewall part of Fy";
algorithm
  h := exp(logSinkage);
  (Fx, Fz, Tx, Fy, FySidewall) := contactForces(h, slip, soil, wheel, nNodes, slipAngle, lateralAtZero, rutDepth);
  residual := if noEvent(Fz > 0) then log(Fz/noEvent(max(W, WMin))) else -1e3;
  annotation (Documentation(info="<html>
<p>One evaluation of the sinkage equation log F<sub>z</sub>(h, &kappa;) = log W of
<code>wheelContact</code>, which calls it at every iterate (with <code>lateralAtZero</code> =
false, so that a wheel driving straight skips the lateral terms). It is also the residual that
<code>wheelContact</code>'s annotation <code>__RoverCosim(implicit(unknown=&quot;logSinkage&quot;,
residual=&quot;...contactResidual&quot;))</code> names: the rover-cosim FMU exporter differentiates
the solve by the implicit-function theorem at the solution it found, dh/dW = -(&part;r/&part;W) /
(&part;r/&part;log h) and so on, instead of through the iterations (which, started warm at the
previous solution, stop after one evaluation and would carry no derivative). Other Modelica tools
ignore the annotation.</p>
</html>"));
end contactResidual;
