within RoverTerramechanics.Components;
model RigidWheel "Terramechanics rigid wheel: spin dynamics with inertia J, drive torque in, contact forces, slip and sinkage out"
  parameter RoverTerramechanics.Parameters.SoilParameters soil "Soil (Table 2)";
  parameter RoverTerramechanics.Parameters.WheelParameters wheel "Wheel (Table 2)";
  parameter Integer nPanels = 8 "Simpson panels (2 intervals each) per piece of the contact patch";
  parameter Integer nIterations = 12 "Bound on the force evaluations of the sinkage solve";
  parameter Real vEps(unit="m/s") = 1e-3 "Regularising speed of the slip ratio";
  input Real tau(unit="N.m") "Drive torque applied to the wheel by its motor";
  input Real W(unit="N") "Vertical load on the wheel";
  input Real v_hub(unit="m/s") "Forward speed of the wheel hub";
  output Real omega(unit="rad/s", start=0, fixed=true) "Wheel angular velocity";
  output Real slip(unit="1") "Slip ratio, Eq. (4)";
  output Real sinkage(unit="m") "Sinkage h at which Fz = W";
  output Real Fx(unit="N") "Longitudinal force of the soil on the wheel, Eq. (12)";
  output Real Fz(unit="N") "Vertical force of the soil on the wheel, Eq. (11)";
  output Real Tx(unit="N.m") "Resistance torque of the soil about the axle, Eq. (13)";
equation
  slip = RoverTerramechanics.Functions.slipRatio(wheel.r*omega, v_hub, vEps);
  (sinkage, Fx, Fz, Tx) = RoverTerramechanics.Functions.wheelContact(W, slip, soil, wheel, nPanels, nIterations);
  wheel.J*der(omega) = tau - Tx;
  annotation (Documentation(info="<html>
<p>J d&omega;/dt = &tau; - T<sub>x</sub>, with the slip ratio of Eq. (4) from r&omega; and the hub
speed, and the sinkage and contact forces of Eqs. (1)-(13) from <code>wheelContact</code>, which
solves F<sub>z</sub>(h, &kappa;) = W inside a function (no algebraic loop). The hub force on the
carrier is F<sub>x</sub> forward; the load W is carried by the soil (F<sub>z</sub> = W).</p>
</html>"));
end RigidWheel;
