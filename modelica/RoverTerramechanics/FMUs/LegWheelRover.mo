within RoverTerramechanics.FMUs;
model LegWheelRover "Leg-wheel rover: the body on six limbs of six joint servos (ATHLETE-like, paper Fig. 1) with six terramechanics wheels (monolithic)"
  extends RoverTerramechanics.Interfaces.GroundContacts(final nWheels=6);
  parameter RoverTerramechanics.Parameters.SoilParameters soil "Soil (Table 2): the soil under a wheel where its soilShare = 0";
  parameter RoverTerramechanics.Parameters.SoilParameters soilB "Second soil: the soil under a wheel where its soilShare = 1 (default Table 2's)";
  parameter RoverTerramechanics.Parameters.WheelParameters wheel "Wheel (Table 2)";
  parameter RoverTerramechanics.Parameters.RoverParameters rover "Rover mass, inertias and gravity (its limb fields are not used: the limbs are legs)";
  parameter RoverTerramechanics.Parameters.LegWheelParameters legs "Limb mounts, link lengths and joint servos";
  parameter RoverTerramechanics.Parameters.TerrainParameters terrain "Ground plane: slope and downhill direction (default level)";
  parameter Real height0(unit="m") = 1.0 "Start height of the centre of gravity above the ground plane";
  parameter Integer nNodes = 10 "Gauss-Legendre nodes per piece of the contact patch";
  parameter Integer nIterations = 12 "Bound on the force evaluations of the sinkage solve";
  parameter Real vEps(unit="m/s") = 1e-3 "Regularising speed of the slip ratio";
  parameter Real vHold(unit="m/s") = 1e-3 "Transition speed: below it the steady forces blend into the static regime";
  parameter Real vStick(unit="m/s") = 1e-4 "Slip speed at which the static shear reaches tanh(1) of its limit";
  input Real hipYaw[6](each unit="rad", start = {0.6835504671705936, 0.0, -0.6835504671705932, -0.6835504671705936, 0.0, 0.6835504671705932}) "Set-points of the hip yaw joints (start: the paper's posture)";
  input Real hipPitch[6](each unit="rad", start = {-0.41027729528934376, 0.10605678318355172, -0.41027729528934376, -0.41027729528934376, 0.10605678318355172, -0.41027729528934376}) "Set-points of the hip pitch joints (start: the paper's posture)";
  input Real kneePitch[6](each unit="rad", start = {2.028751485911332, 2.518688308843155, 2.028751485911332, 2.028751485911332, 2.518688308843155, 2.028751485911332}) "Set-points of the knee pitch joints (start: the paper's posture)";
  input Real anklePitch[6](each unit="rad", start = {-0.04767786382709138, -1.0539487652318102, -0.04767786382709138, -0.04767786382709138, -1.0539487652318102, -0.04767786382709138}) "Set-points of the ankle pitch joints (start: the paper's posture)";
  input Real ankleSteer[6](each unit="rad", start = {1.2071492427688926, 1.5707963267948974, 1.9344434108209012, -1.2071492427688926, -1.5707963267948974, -1.9344434108209012}) "Set-points of the ankle steer joints (start: the paper's posture)";
  input Real ankleRoll[6](each unit="rad", start = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0}) "Set-points of the ankle roll joints (start: the paper's posture)";
  input Real tau[6](each unit="N.m") "Drive torque of each wheel";
  input Real soilShare[6](each unit="1", each min=0, each max=1, each start=0) "Share of the second soil (soilB) in the soil under each wheel, from a soil map (0: soil)";
  input Real rutDepth[6](each unit="m", each min=0, each start=0) "Depth of the rut a previous wheel left under each wheel, from a rut participant (0: virgin soil)";
  output Real hipYawAngle[6](each unit="rad") "Angle of each limb's hip yaw joint, deflected by the load";
  output Real hipPitchAngle[6](each unit="rad") "Angle of each limb's hip pitch joint, deflected by the load";
  output Real kneePitchAngle[6](each unit="rad") "Angle of each limb's knee pitch joint, deflected by the load";
  output Real anklePitchAngle[6](each unit="rad") "Angle of each limb's ankle pitch joint, deflected by the load";
  output Real ankleSteerAngle[6](each unit="rad") "Angle of each limb's ankle steer joint, deflected by the load";
  output Real ankleRollAngle[6](each unit="rad") "Angle of each limb's ankle roll joint, deflected by the load";
  output Real hipYawTorque[6](each unit="N.m") "Torque of each limb's hip yaw servo";
  output Real hipPitchTorque[6](each unit="N.m") "Torque of each limb's hip pitch servo";
  output Real kneePitchTorque[6](each unit="N.m") "Torque of each limb's knee pitch servo";
  output Real anklePitchTorque[6](each unit="N.m") "Torque of each limb's ankle pitch servo";
  output Real ankleSteerTorque[6](each unit="N.m") "Torque of each limb's ankle steer servo";
  output Real ankleRollTorque[6](each unit="N.m") "Torque of each limb's ankle roll servo";
  output Real hubX[6](each unit="m") "Hub position in the body frame, ahead of the centre of gravity";
  output Real hubY[6](each unit="m") "Hub position in the body frame, to the left";
  output Real hubZ[6](each unit="m") "Hub position in the body frame, above the centre of gravity (negative)";
  output Real steer[6](each unit="rad") "Heading of each wheel against the body's, from its limb's joints";
  output Real x(unit="m") "Position of the centre of gravity along the ground's x axis";
  output Real y(unit="m") "Position of the centre of gravity along the ground's y axis";
  output Real z(unit="m") "Height of the centre of gravity above the ground plane";
  output Real yaw(unit="rad") "Heading against the ground's x axis, positive to the left";
  output Real pitch(unit="rad") "Pitch angle against the ground plane, nose up positive";
  output Real roll(unit="rad") "Roll angle against the ground plane, left side up positive";
  output Real v(unit="m/s") "Forward velocity of the centre of gravity, along the heading";
  output Real vy(unit="m/s") "Lateral velocity of the centre of gravity, to the left";
  output Real yawRate(unit="rad/s") "Yaw rate";
  output Real heaveRate(unit="m/s") "Rate of z";
  output Real pitchRate(unit="rad/s") "Pitch rate";
  output Real rollRate(unit="rad/s") "Roll rate";
  output Real Fz[6](each unit="N") "Vertical force of each wheel, Eq. (11) (= its load)";
  output Real Fx[6](each unit="N") "Longitudinal force of each wheel, along its heading";
  output Real Fy[6](each unit="N") "Lateral force of each wheel, to its left";
  output Real Tx[6](each unit="N.m") "Resistance torque of each wheel, Eq. (13)";
  output Real slip[6](each unit="1") "Slip ratio of each wheel, Eq. (4)";
  output Real slipAngle[6](each unit="rad") "Slip angle of each wheel's hub velocity";
  output Real sinkage[6](each unit="m") "Sinkage of each wheel";
  output Real omega[6](each unit="rad/s") "Angular velocity of each wheel";
  input Real hipYawRate[6](each unit="rad/s", each start=0) "Rates of the hip yaw set-points (0: held; the hubs move against the body at J q_set', see Components.LegWheelChassis)";
  input Real hipPitchRate[6](each unit="rad/s", each start=0) "Rates of the hip pitch set-points (0: held; the hubs move against the body at J q_set', see Components.LegWheelChassis)";
  input Real kneePitchRate[6](each unit="rad/s", each start=0) "Rates of the knee pitch set-points (0: held; the hubs move against the body at J q_set', see Components.LegWheelChassis)";
  input Real anklePitchRate[6](each unit="rad/s", each start=0) "Rates of the ankle pitch set-points (0: held; the hubs move against the body at J q_set', see Components.LegWheelChassis)";
  input Real ankleSteerRate[6](each unit="rad/s", each start=0) "Rates of the ankle steer set-points (0: held; the hubs move against the body at J q_set', see Components.LegWheelChassis)";
  input Real ankleRollRate[6](each unit="rad/s", each start=0) "Rates of the ankle roll set-points (0: held; the hubs move against the body at J q_set', see Components.LegWheelChassis)";
  RoverTerramechanics.Components.LegWheelChassis body(rover=rover, legs=legs, terrain=terrain, height0=height0) "Body and limbs";
  RoverTerramechanics.Components.RigidWheel wheels[6](each soil=soil, each soilB=soilB, each wheel=wheel, each nNodes=nNodes, each nIterations=nIterations, each vEps=vEps, each vHold=vHold, each vStick=vStick) "Wheels 1-6";
equation
  for i in 1:6 loop
    body.hipYaw[i] = hipYaw[i];
    body.hipYawRate[i] = hipYawRate[i];
    body.hipPitchRate[i] = hipPitchRate[i];
    body.kneePitchRate[i] = kneePitchRate[i];
    body.anklePitchRate[i] = anklePitchRate[i];
    body.ankleSteerRate[i] = ankleSteerRate[i];
    body.ankleRollRate[i] = ankleRollRate[i];
    hipYawAngle[i] = body.hipYawAngle[i];
    hipYawTorque[i] = body.hipYawTorque[i];
    body.hipPitch[i] = hipPitch[i];
    hipPitchAngle[i] = body.hipPitchAngle[i];
    hipPitchTorque[i] = body.hipPitchTorque[i];
    body.kneePitch[i] = kneePitch[i];
    kneePitchAngle[i] = body.kneePitchAngle[i];
    kneePitchTorque[i] = body.kneePitchTorque[i];
    body.anklePitch[i] = anklePitch[i];
    anklePitchAngle[i] = body.anklePitchAngle[i];
    anklePitchTorque[i] = body.anklePitchTorque[i];
    body.ankleSteer[i] = ankleSteer[i];
    ankleSteerAngle[i] = body.ankleSteerAngle[i];
    ankleSteerTorque[i] = body.ankleSteerTorque[i];
    body.ankleRoll[i] = ankleRoll[i];
    ankleRollAngle[i] = body.ankleRollAngle[i];
    ankleRollTorque[i] = body.ankleRollTorque[i];
    hubX[i] = body.hubX[i];
    hubY[i] = body.hubY[i];
    hubZ[i] = body.hubZ[i];
    steer[i] = body.steer[i];
    wheels[i].tau = tau[i];
    wheels[i].W = body.W[i];
    wheels[i].v_hub = body.v_hub[i];
    wheels[i].v_lat = body.v_lat[i];
    wheels[i].soilShare = soilShare[i];
    wheels[i].rutDepth = rutDepth[i];
    body.Fx[i] = wheels[i].Fx;
    body.Fy[i] = wheels[i].Fy;
    body.tau[i] = tau[i];
    body.groundHeight[i] = groundHeight[i];
    body.groundHeightRate[i] = groundHeightRate[i];
    body.groundGradientAlong[i] = groundGradientAlong[i];
    body.groundGradientLateral[i] = groundGradientLateral[i];
    Fz[i] = wheels[i].Fz;
    Fx[i] = wheels[i].Fx;
    Fy[i] = wheels[i].Fy;
    Tx[i] = wheels[i].Tx;
    slip[i] = wheels[i].slip;
    slipAngle[i] = wheels[i].slipAngle;
    sinkage[i] = wheels[i].sinkage;
    omega[i] = wheels[i].omega;
  end for;
  x = body.x;
  y = body.y;
  z = body.z;
  yaw = body.yaw;
  pitch = body.pitch;
  roll = body.roll;
  v = body.v;
  vy = body.vy;
  yawRate = body.yawRate;
  heaveRate = body.heaveRate;
  pitchRate = body.pitchRate;
  rollRate = body.rollRate;
  annotation (
    experiment(StartTime=0, StopTime=5, Interval=0.01),
    Documentation(info="<html>
<p>The paper's plant (Sec. 2.1, Fig. 1): a leg-wheel robot with six joints per limb after NASA/JPL's
ATHLETE. Body and limbs: <code>Components.LegWheelChassis</code> (x, y, yaw in the ground plane;
heave, pitch, roll against it; each limb's six joints position servos of stiffness, damping and a
torque limit, <code>Parameters.LegWheelParameters</code>); wheels: <code>Components.RigidWheel</code>,
each fed its hub's velocity in its own frame (the heading its limb's joints give it), the load its
compliant limb presses into the soil. Inputs: the 36 joint set-points (start: the paper's posture,
hubs at x = 1.5, 0, -1.5 m, y = &plusmn;1.5 m, 1.0 m below the centre of gravity) and their rates
(<code>hipYawRate</code> ... <code>ankleRollRate</code> [rad/s], default 0: the hubs' velocity against the
body), the six drive torques <code>tau</code>, the soil and ground under each wheel (<code>soilShare</code>,
<code>Interfaces.GroundContacts</code>). Outputs: joint angles and servo torques, hub positions
(body frame) and headings, wheel loads, forces, slips, slip angles, sinkages and speeds, the body's
pose and velocity. The contact causality and the limb model: <code>Components.LegWheelChassis</code>;
<code>LegWheelRoverBody</code> is its body alone, for co-simulation with six <code>Wheel</code>s.</p>
</html>"));
end LegWheelRover;
