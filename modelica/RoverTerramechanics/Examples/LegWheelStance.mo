within RoverTerramechanics.Examples;
model LegWheelStance "The leg-wheel body at rest in the paper's posture: it settles on its six compliant limbs"
  RoverTerramechanics.Components.LegWheelChassis body(height0 = 1.0, rover(M = 1570)) "No wheel forces: the body alone on its limbs";
  parameter Real hipYaw[6](each unit="rad") = {0.6835504671705936, 0.0, -0.6835504671705932, -0.6835504671705936, 0.0, 0.6835504671705932};
  parameter Real hipPitch[6](each unit="rad") = {-0.41027729528934376, 0.10605678318355172, -0.41027729528934376, -0.41027729528934376, 0.10605678318355172, -0.41027729528934376};
  parameter Real kneePitch[6](each unit="rad") = {2.028751485911332, 2.518688308843155, 2.028751485911332, 2.028751485911332, 2.518688308843155, 2.028751485911332};
  parameter Real anklePitch[6](each unit="rad") = {-0.04767786382709138, -1.0539487652318102, -0.04767786382709138, -0.04767786382709138, -1.0539487652318102, -0.04767786382709138};
  parameter Real ankleSteer[6](each unit="rad") = {1.2071492427688926, 1.5707963267948974, 1.9344434108209012, -1.2071492427688926, -1.5707963267948974, -1.9344434108209012};
equation
  body.hipYaw = hipYaw;
  body.hipPitch = hipPitch;
  body.kneePitch = kneePitch;
  body.anklePitch = anklePitch;
  body.ankleSteer = ankleSteer;
  body.ankleRoll = zeros(6);
  body.hipYawRate = zeros(6);
  body.hipPitchRate = zeros(6);
  body.kneePitchRate = zeros(6);
  body.anklePitchRate = zeros(6);
  body.ankleSteerRate = zeros(6);
  body.ankleRollRate = zeros(6);
  body.Fx = zeros(6);
  body.Fy = zeros(6);
  body.tau = zeros(6);
  body.groundHeight = zeros(6);
  body.groundHeightRate = zeros(6);
  body.groundGradientAlong = zeros(6);
  body.groundGradientLateral = zeros(6);
  annotation (
    experiment(StartTime=0, StopTime=5, Interval=0.01),
    Documentation(info="<html>
<p>The paper's posture (hubs at x = 1.5, 0, -1.5 m, y = &plusmn;1.5 m, 1.0 m below the centre of
gravity; the joint angles from <code>rover_cosim.limbs.stance_inverse</code>), started with the
unloaded hubs on the ground: the body sinks on the limbs' springs and settles. At rest the loads
sum to the weight and equal <code>rover_cosim.limbs.static_loads</code> (tests/test_limbs.py).</p>
</html>"));
end LegWheelStance;
