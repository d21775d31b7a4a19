within RoverTerramechanics.Functions;
function wheelContact "Sinkage at which the soil carries the wheel load, Fz(h, slip) = W, and the contact forces there"
  input Real W(unit="N") "Vertical load on the wheel (floored at WMin)";
  input Real slip(unit="1") "Slip ratio";
  input RoverTerramechanics.Parameters.SoilParameters soil "Soil";
  input RoverTerramechanics.Parameters.WheelParameters wheel "Wheel";
  input Integer nNodes = 10 "Gauss-Legendre nodes per piece of the contact patch";
  input Integer nIterations = 12 "Bound on the number of force evaluations";
  input Real tolerance(unit="1") = 1e-10 "Relative tolerance on Fz/W - 1";
  input Real WMin(unit="N") = 1e-3 "Smallest load considered (a lifted wheel)";
  input Real slipAngle(unit="rad") = 0 "Slip angle of the hub velocity (Ishigami et al. 2007)";
  input Real logSinkageStart(unit="1") = 0 "log(h / 1 m) to start from, e.g. the previous solve's logSinkage; used only when slopeStart > 0";
  input Real slopeStart(unit="1") = 0 "> 0: warm start from logSinkageStart with this slope d log Fz / d log h for the first step (e.g. the previous solve's slope); <= 0: cold start from Bekker's sinkage";
  input Real rutDepth(unit="m") = 0 "Depth of the rut a previous wheel left (multi-pass): h is the sinkage below its floor";
  output Real h(unit="m") "Sinkage";
  output Real Fx(unit="N") "Longitudinal force at h, Eq. (12)";
  output Real Fz(unit="N") "Vertical force at h, Eq. (11): W once converged";
  output Real Tx(unit="N.m") "Resistance torque at h, Eq. (13)";
  output Real Fy(unit="N") "Lateral force at h";
  output Real FySidewall(unit="N") "Sidewall part of Fy";
  output Real evaluations(unit="1") "Force evaluations the solve used";
  output Real logSinkage(unit="1") "log(h / 1 m) at the last force evaluation: h = exp(logSinkage) (a start for the next solve)";
  output Real slope(unit="1") "d log Fz / d log h near the solution, > 0: the solve's last secant (a start for the next solve)";
protected
  Real load(unit="N") "Load, floored at WMin";
  Real x "log(h/m), the iterate";
  Real xPrev "Previous iterate";
  Real xLow "Bracket: log sinkage with Fz < W";
  Real xHigh "Bracket: log sinkage with Fz > W (or h = r)";
  Real f "Residual log(Fz/W) at x";
  Real fPrev "Residual at xPrev";
  Real step "Next iterate";
  Real bekkerModulus(unit="N/m3");
  Real bekkerSlope "d log Fz / d log h of Bekker's law";
  Real xCold "log of Bekker's sinkage, the cold start";
  Real secant "Slope of the last secant";
  Boolean warm "Started from hStart and not yet fallen back to the cold start";
  Boolean done;
  Boolean first;
algorithm
  load := noEvent(max(W, WMin));
  bekkerModulus := soil.kc/wheel.b + soil.kphi;
  bekkerSlope := (2*soil.n + 1)/2;
  xLow := log(1e-12*wheel.r);
  xHigh := log(wheel.r);
  // Bekker's rigid-wheel sinkage as the cold start: h = [3 W / ((3 - n) b k sqrt(2 r))]^(2/(2n+1)).
  xCold := 2/(2*soil.n + 1)*log(3*load/((3 - min(soil.n, 2.9))*wheel.b*bekkerModulus*sqrt(2*wheel.r)));
  xCold := noEvent(min(max(xCold, xLow), xHigh));
  warm := noEvent(slopeStart > 0);
  x := if warm then noEvent(min(max(logSinkageStart, xLow), xHigh)) else xCold;
  slope := if warm then slopeStart else bekkerSlope;
  xPrev := x;
  fPrev := 0;
  h := exp(x);
  logSinkage := x;
  Fx := 0;
  Fz := 0;
  Tx := 0;
  Fy := 0;
  FySidewall := 0;
  evaluations := 0;
  done := false;
  first := true;
  for k in 1:nIterations loop
    if not done then
      logSinkage := x;
      // A skidding wheel that has barely sunk can have Fz <= 0: f = -1e3, "too shallow".
      (f, h, Fx, Fz, Tx, Fy, FySidewall) := contactResidual(x, W, slip, soil, wheel, nNodes, WMin, slipAngle, rutDepth, false);
      evaluations := evaluations + 1;
      if noEvent(abs(f) <= tolerance) then
        done := true;
      else
        if noEvent(f < 0) then
          xLow := x;
        else
          xHigh := x;
        end if;
        if first and warm and noEvent(abs(f) > 1) then
          // The start is more than a factor e from carrying W: fall back to the cold start.
          step := xCold;
          slope := bekkerSlope;
          warm := false;
        elseif first then
          step := x - f/slope;
          first := false;
        elseif noEvent(abs(f - fPrev) > 1e-300) then
          secant := (f - fPrev)/(x - xPrev);
          slope := if noEvent(secant > 0) then secant else slope;
          step := x - f/secant;
        else
          step := 0.5*(xLow + xHigh);
        end if;
        if noEvent(step <= xLow or step >= xHigh) then
          step := 0.5*(xLow + xHigh);
        end if;
        xPrev := x;
        fPrev := f;
        x := step;
      end if;
    end if;
  end for;
  annotation (__RoverCosim(implicit(unknown="logSinkage", residual="RoverTerramechanics.Functions.contactResidual")),
    Documentation(info="<html>
<p>The paper decides the sinkage \"by the optimization\" so that the vertical force of Eq. (11)
equals the load. Here the equation log F<sub>z</sub>(h, &kappa;) = log W is solved in log h inside
the function, so that a model that calls it has no nonlinear algebraic loop: the first step is
Newton's with the slope (2n+1)/2 of Bekker's law from Bekker's sinkage, later steps are secant
steps, and any step that leaves the bracket [10<sup>-12</sup> r, r] (narrowed by every evaluation)
is replaced by bisection. The loop is bounded by <code>nIterations</code> evaluations (default 12); on the
Table 2 soil it converges to 1e-10 in at most 5 for loads 1 N to 5 kN and slips -1 to 1
(measured with the same algorithm on the Python reference). If the soil cannot carry W even at h = r the result is h = r
with F<sub>z</sub> &lt; W.</p>
<p>Warm start: given <code>slopeStart</code> &gt; 0 (the previous solve's output <code>slope</code>,
its last secant) and <code>logSinkageStart</code> (the previous solve's <code>logSinkage</code>,
log h of its last evaluation) the solve starts there instead; started at a converged solution it
repeats that evaluation bit for bit and stops after it; a start whose residual exceeds 1 (F<sub>z</sub> more than a factor e from W)
falls back to the cold start. The result does not depend on the start beyond the tolerance; a
wheel rolling steadily needs 1-2 evaluations instead of about 4.</p>
<p>Derivatives: the annotation <code>__RoverCosim(implicit(...))</code> tells the rover-cosim FMU
exporter that <code>logSinkage</code> solves <code>contactResidual</code> = 0, so that the FMUs'
directional derivatives and their integrator's Jacobian follow the implicit-function theorem at
the solution, whatever the warm start (other tools differentiate the iterations, or ignore it).</p>
<p>Same method as the Python reference <code>terramechanics.wheel_state</code> (which also splits
the patch where a skidding wheel's shear displacement changes sign).</p>
</html>"));
end wheelContact;
