within RoverTerramechanics.Examples;
model LimbKinematics "The hub of a leg-wheel limb for given joint angles (Components.Limb), the cross-check of the numpy kinematics"
  parameter RoverTerramechanics.Parameters.LimbParameters limb "Limb 1 of the hexagonal frame";
  parameter Real q[6](each unit="rad") = {0.68, -0.41, 2.03, -0.05, 1.21, 0.0} "Joint angles (about the paper's posture of limb 1)";
  RoverTerramechanics.Components.Limb kinematics(geometry = limb) "The limb";
  Real t(unit="s", start=0, fixed=true) "Time, so that the model has a state";
equation
  der(t) = 1;
  for k in 1:6 loop
    kinematics.q[k] = q[k];
  end for;
  annotation (
    experiment(StartTime=0, StopTime=0.01, Interval=0.01),
    Documentation(info="<html>
<p>Evaluates <code>Components.Limb</code> for the joint angles <code>q</code> [rad] of the limb
<code>limb</code>; tests/test_limbs.py sets both as parameters and compares the hub, link, axle,
Jacobian and axes with <code>rover_cosim.limbs.forward</code> and <code>jacobian</code>.</p>
</html>"));
end LimbKinematics;
