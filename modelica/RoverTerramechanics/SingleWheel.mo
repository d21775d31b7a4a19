within RoverTerramechanics;
model SingleWheel "Single-wheel test bed: one terramechanics wheel on a carriage of mass W/g that moves freely in x"
  parameter RoverTerramechanics.Parameters.SoilParameters soil "Soil (Table 2)";
  parameter RoverTerramechanics.Parameters.WheelParameters wheel "Wheel (Table 2)";
  parameter Real W(unit="N") = 424 "Vertical load on the wheel (the carriage weight)";
  parameter Real g(unit="m/s2") = 1.62 "Gravity (lunar)";
  parameter Integer nPanels = 8 "Simpson panels (2 intervals each) per piece of the contact patch";
  parameter Integer nIterations = 12 "Bound on the force evaluations of the sinkage solve";
  parameter Real vEps(unit="m/s") = 1e-3 "Regularising speed of the slip ratio";
  input Real tau(unit="N.m") "Drive torque";
  output Real Fx(unit="N") "Longitudinal force, Eq. (12)";
  output Real Fz(unit="N") "Vertical force, Eq. (11)";
  output Real Tx(unit="N.m") "Resistance torque, Eq. (13)";
  output Real slip(unit="1") "Slip ratio, Eq. (4)";
  output Real sinkage(unit="m") "Sinkage";
  output Real omega(unit="rad/s") "Wheel angular velocity";
  output Real v(unit="m/s", start=0, fixed=true) "Carriage (hub) forward velocity";
  Real x(unit="m", start=0, fixed=true) "Carriage position";
  RoverTerramechanics.Components.RigidWheel rigidWheel(soil=soil, wheel=wheel, nPanels=nPanels, nIterations=nIterations, vEps=vEps) "The wheel";
equation
  rigidWheel.tau = tau;
  rigidWheel.W = W;
  rigidWheel.v_hub = v;
  der(x) = v;
  W/g*der(v) = rigidWheel.Fx;
  Fx = rigidWheel.Fx;
  Fz = rigidWheel.Fz;
  Tx = rigidWheel.Tx;
  slip = rigidWheel.slip;
  sinkage = rigidWheel.sinkage;
  omega = rigidWheel.omega;
  annotation (Documentation(info="<html>
<p>The paper's single-wheel test bed (Sec. 3): the wheel carries the constant load W and pushes
a carriage of mass W/g that moves freely in x, (W/g) dv/dt = F<sub>x</sub>. Input: drive torque
<code>tau</code>; parameter <code>W</code>; outputs as listed. The identification applies steps
in tau to this model.</p>
</html>"));
end SingleWheel;
