within RoverTerramechanics.Examples;
model LimbKinematics "The hub of a leg-wheel limb for given joint angles (Functions.limbForward), the cross-check of the numpy kinematics"
  parameter RoverTerramechanics.Parameters.LimbParameters limb "Limb 1 of the hexagonal frame";
  parameter Real q[6](each unit="rad") = {0.68, -0.41, 2.03, -0.05, 1.21, 0.0} "Joint angles (about the paper's posture of limb 1)";
  output Real hub[3](each unit="m") "Wheel hub in the body frame";
  output Real link[3](each unit="1") "Direction of the last link";
  output Real axle[3](each unit="1") "The wheel's axle";
  output Real jacobian[3, 6](each unit="m") "d hub / d q [m/rad]";
  Real t(unit="s", start=0, fixed=true) "Time, so that the model has a state";
equation
  der(t) = 1;
  (hub, link, axle, jacobian) = RoverTerramechanics.Functions.limbForward(limb, q);
  annotation (
    experiment(StartTime=0, StopTime=0.01, Interval=0.01),
    Documentation(info="<html>
<p>Evaluates <code>Functions.limbForward</code> for the joint angles <code>q</code> [rad] of the
limb <code>limb</code>; tests/test_limbs.py sets both as parameters and compares the hub, link and
axle with <code>rover_cosim.limbs.forward</code>.</p>
</html>"));
end LimbKinematics;
