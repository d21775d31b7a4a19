within RoverTerramechanics.FMUs;
model SingleWheel "Single-wheel test bed: one terramechanics wheel on a carriage of mass W/g that moves freely in x, on level ground or a slope"
  parameter RoverTerramechanics.Parameters.SoilParameters soil "Soil (Table 2)";
  parameter RoverTerramechanics.Parameters.WheelParameters wheel "Wheel (Table 2)";
  parameter Real W(unit="N") = 424 "Weight of the carriage, carried by the wheel";
  parameter Real g(unit="m/s2") = 1.62 "Gravity (lunar)";
  parameter Real slope(unit="rad") = 0 "Slope of the ground along x, positive uphill";
  parameter Real slipAngle(unit="rad") = 0 "Angle of the carriage's track to the wheel plane (Ishigami's test bed), positive: the hub slides to the wheel's left";
  parameter Integer nNodes = 10 "Gauss-Legendre nodes per piece of the contact patch";
  parameter Integer nIterations = 12 "Bound on the force evaluations of the sinkage solve";
  parameter Real vEps(unit="m/s") = 1e-3 "Regularising speed of the slip ratio";
  parameter Real vHold(unit="m/s") = 1e-3 "Transition speed: below it the steady forces blend into the static regime";
  parameter Real vStick(unit="m/s") = 1e-4 "Slip speed at which the static shear reaches tanh(1) of its limit";
  input Real tau(unit="N.m") "Drive torque";
  input Real rutDepth(unit="m", min=0, start=0) "Depth of the rut a previous pass left (repeated passes on the test bed; 0: virgin soil)";
  input Real trackAngle(unit="rad", start=0) "Turn of the carriage's track during a run, added to slipAngle (optional input, 0 when not driven)";
  output Real Fx(unit="N") "Longitudinal force, Eq. (12) when rolling";
  output Real Fz(unit="N") "Vertical force, Eq. (11): the load normal to the ground, W cos(slope)";
  output Real Tx(unit="N.m") "Resistance torque, Eq. (13) when rolling";
  output Real slip(unit="1") "Slip ratio, Eq. (4)";
  output Real sinkage(unit="m") "Sinkage";
  output Real omega(unit="rad/s") "Wheel angular velocity";
  output Real entryAngle(unit="rad") "Entry angle, signed with the direction of travel";
  output Real Fy(unit="N") "Lateral force of the soil on the wheel, along its left (Ishigami et al. 2007)";
  output Real beta(unit="rad") "Slip angle of the hub velocity in the wheel frame: slipAngle + trackAngle";
  output Real v(unit="m/s", start=0, fixed=true) "Carriage (hub) velocity along the ground";
  output Real x(unit="m", start=0, fixed=true) "Carriage position along the ground";
  RoverTerramechanics.Components.RigidWheel rigidWheel(soil=soil, soilB=soil, wheel=wheel, nNodes=nNodes, nIterations=nIterations, vEps=vEps, vHold=vHold, vStick=vStick) "The wheel";
equation
  rigidWheel.tau = tau;
  rigidWheel.soilShare = 0 "one soil under the test bed";
  rigidWheel.rutDepth = rutDepth;
  rigidWheel.W = W*cos(slope);
  beta = slipAngle + trackAngle;
  rigidWheel.v_hub = v*cos(beta);
  rigidWheel.v_lat = v*sin(beta);
  der(x) = v;
  W/g*der(v) = rigidWheel.Fx*cos(beta) + rigidWheel.Fy*sin(beta) - W*sin(slope);
  Fx = rigidWheel.Fx;
  Fz = rigidWheel.Fz;
  Tx = rigidWheel.Tx;
  slip = rigidWheel.slip;
  sinkage = rigidWheel.sinkage;
  omega = rigidWheel.omega;
  entryAngle = rigidWheel.entryAngle;
  Fy = rigidWheel.Fy;
  assert(W > 0, "W: the carriage weight must be > 0 N");
  assert(g > 0, "g: the gravity must be > 0 m/s2");
  assert(slope > -1.5707963267948966 and slope < 1.5707963267948966, "slope: must be in (-pi/2, pi/2) rad");
  assert(beta > -1.5707963267948966 and beta < 1.5707963267948966, "slipAngle + trackAngle: must be in (-pi/2, pi/2) rad");
  annotation (
    experiment(StartTime=0, StopTime=10, Interval=0.01),
    Documentation(info="<html>
<p>The paper's single-wheel test bed (Sec. 3): the wheel carries the carriage weight W and
pushes a carriage of mass W/g that moves freely along the ground, (W/g) dv/dt = F<sub>x</sub> -
W sin(slope), with the load W cos(slope) normal to the ground on the wheel. Input: drive torque
<code>tau</code>; parameters <code>W</code>, <code>slope</code>; outputs as listed. The states
<code>x</code>, <code>v</code> and <code>omega</code> take start values, so a run can start in
motion. The identification applies steps in tau to this model on level ground.</p>
<p>Parameter <code>slipAngle</code> sets the wheel at an angle to the carriage's track, as on
Ishigami's single-wheel test bed: the hub moves at v cos(slipAngle) along the wheel and
v sin(slipAngle) to its left, and the carriage is driven by F<sub>x</sub> cos + F<sub>y</sub> sin
of it; output <code>Fy</code> is the lateral force in the wheel frame. The optional input
<code>trackAngle</code> (start 0) turns the track during a run, e.g. a staircase of slip angles
for the validation of the identified lateral model; the slip angle is
<code>beta</code> = slipAngle + trackAngle.</p>
</html>"));
end SingleWheel;
