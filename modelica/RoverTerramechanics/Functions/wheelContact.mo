within RoverTerramechanics.Functions;
function wheelContact "Sinkage at which the soil carries the wheel load, Fz(h, slip) = W, and the contact forces there"
  input Real W(unit="N") "Vertical load on the wheel (floored at WMin)";
  input Real slip(unit="1") "Slip ratio";
  input RoverTerramechanics.Parameters.SoilParameters soil "Soil";
  input RoverTerramechanics.Parameters.WheelParameters wheel "Wheel";
  input Integer nNodes = 16 "Gauss-Legendre nodes per piece of the contact patch";
  input Integer nIterations = 12 "Bound on the number of force evaluations";
  input Real tolerance(unit="1") = 1e-10 "Relative tolerance on Fz/W - 1";
  input Real WMin(unit="N") = 1e-3 "Smallest load considered (a lifted wheel)";
  input Real slipAngle(unit="rad") = 0 "Slip angle of the hub velocity (Ishigami et al. 2007)";
  output Real h(unit="m") "Sinkage";
  output Real Fx(unit="N") "Longitudinal force at h, Eq. (12)";
  output Real Fz(unit="N") "Vertical force at h, Eq. (11): W once converged";
  output Real Tx(unit="N.m") "Resistance torque at h, Eq. (13)";
  output Real Fy(unit="N") "Lateral force at h";
  output Real FySidewall(unit="N") "Sidewall part of Fy";
  output Real evaluations(unit="1") "Force evaluations the solve used";
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
  Real slope "d log Fz / d log h of Bekker's law, for the first step";
  Boolean done;
  Boolean first;
algorithm
  load := noEvent(max(W, WMin));
  bekkerModulus := soil.kc/wheel.b + soil.kphi;
  slope := (2*soil.n + 1)/2;
  // Bekker's rigid-wheel sinkage as the start: h = [3 W / ((3 - n) b k sqrt(2 r))]^(2/(2n+1)).
  x := 2/(2*soil.n + 1)*log(3*load/((3 - min(soil.n, 2.9))*wheel.b*bekkerModulus*sqrt(2*wheel.r)));
  xLow := log(1e-12*wheel.r);
  xHigh := log(wheel.r);
  x := noEvent(min(max(x, xLow), xHigh));
  xPrev := x;
  fPrev := 0;
  h := exp(x);
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
      h := exp(x);
      (Fx, Fz, Tx, Fy, FySidewall) := contactForces(h, slip, soil, wheel, nNodes, slipAngle);
      evaluations := evaluations + 1;
      // A skidding wheel that has barely sunk can have Fz <= 0: treat it as "too shallow".
      f := if noEvent(Fz > 0) then log(Fz/load) else -1e3;
      if noEvent(abs(f) <= tolerance) then
        done := true;
      else
        if noEvent(f < 0) then
          xLow := x;
        else
          xHigh := x;
        end if;
        if first then
          step := x - f/slope;
        elseif noEvent(abs(f - fPrev) > 1e-300) then
          step := x - f*(x - xPrev)/(f - fPrev);
        else
          step := 0.5*(xLow + xHigh);
        end if;
        if noEvent(step <= xLow or step >= xHigh) then
          step := 0.5*(xLow + xHigh);
        end if;
        xPrev := x;
        fPrev := f;
        x := step;
        first := false;
      end if;
    end if;
  end for;
  annotation (Documentation(info="<html>
<p>The paper decides the sinkage \"by the optimization\" so that the vertical force of Eq. (11)
equals the load. Here the equation log F<sub>z</sub>(h, &kappa;) = log W is solved in log h inside
the function, so that a model that calls it has no nonlinear algebraic loop: the first step is
Newton's with the slope (2n+1)/2 of Bekker's law from Bekker's sinkage, later steps are secant
steps, and any step that leaves the bracket [10<sup>-12</sup> r, r] (narrowed by every evaluation)
is replaced by bisection. The loop is bounded by <code>nIterations</code> evaluations (default 12); on the
Table 2 soil it converges to 1e-10 in at most 5 for loads 1 N to 5 kN and slips -1 to 1
(measured with the same algorithm on the Python reference). If the soil cannot carry W even at h = r the result is h = r
with F<sub>z</sub> &lt; W.</p>
<p>Same method as the Python reference <code>terramechanics.wheel_state</code> (which also splits
the patch where a skidding wheel's shear displacement changes sign).</p>
</html>"));
end wheelContact;
