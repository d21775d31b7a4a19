within RoverTerramechanics.Components;
model LegWheelChassis "Leg-wheel rover body (x, y, yaw, heave, pitch, roll) on six limbs of six joint servos each, cut at the wheel hubs"
  extends RoverTerramechanics.Interfaces.GroundContacts(final nWheels=6);
  parameter RoverTerramechanics.Parameters.RoverParameters rover "Mass, inertias and gravity (the limb fields are not used: the limbs are legs)";
  parameter RoverTerramechanics.Parameters.LegWheelParameters legs "Limb mounts, link lengths and joint servos";
  parameter RoverTerramechanics.Parameters.TerrainParameters terrain "Ground plane (default level)";
  parameter Real height0(unit="m") = 1.0 "Start height of the centre of gravity above the ground plane";
  input Real hipYaw[6](each unit="rad") "Set-points of the hip yaw joints";
  input Real hipPitch[6](each unit="rad") "Set-points of the hip pitch joints (positive: the thigh down)";
  input Real kneePitch[6](each unit="rad") "Set-points of the knee pitch joints";
  input Real anklePitch[6](each unit="rad") "Set-points of the ankle pitch joints";
  input Real ankleSteer[6](each unit="rad") "Set-points of the ankle steer joints (the wheels' steering)";
  input Real ankleRoll[6](each unit="rad") "Set-points of the ankle roll joints (the wheels' camber)";
  input Real Fx[6](each unit="N") "Longitudinal force of each wheel on its hub, along the wheel's heading";
  input Real Fy[6](each unit="N") "Lateral force of each wheel on its hub, to the wheel's left";
  input Real tau[6](each unit="N.m") "Drive torque of each wheel motor; its reaction acts on the limb";
  output Real W[6](each unit="N") "Wheel loads: what the compliant limbs press into the soil, along the ground's normal";
  output Real v_hub[6](each unit="m/s") "Hub speed along each wheel's heading";
  output Real v_lat[6](each unit="m/s") "Hub speed to each wheel's left";
  output Real steer[6](each unit="rad") "Heading of each wheel against the body's, from its limb's joints";
  output Real hipYawAngle[6](each unit="rad") "Angle of each limb's hip yaw joint: its set-point deflected by the load (q = q_set - torque/kJoint)";
  output Real hipPitchAngle[6](each unit="rad") "Angle of each limb's hip pitch joint: its set-point deflected by the load (q = q_set - torque/kJoint)";
  output Real kneePitchAngle[6](each unit="rad") "Angle of each limb's knee pitch joint: its set-point deflected by the load (q = q_set - torque/kJoint)";
  output Real anklePitchAngle[6](each unit="rad") "Angle of each limb's ankle pitch joint: its set-point deflected by the load (q = q_set - torque/kJoint)";
  output Real ankleSteerAngle[6](each unit="rad") "Angle of each limb's ankle steer joint: its set-point deflected by the load (q = q_set - torque/kJoint)";
  output Real ankleRollAngle[6](each unit="rad") "Angle of each limb's ankle roll joint: its set-point deflected by the load (q = q_set - torque/kJoint)";
  output Real hipYawTorque[6](each unit="N.m") "Torque of each limb's hip yaw servo that holds the hub's load and the wheel motor's reaction";
  output Real hipPitchTorque[6](each unit="N.m") "Torque of each limb's hip pitch servo that holds the hub's load and the wheel motor's reaction";
  output Real kneePitchTorque[6](each unit="N.m") "Torque of each limb's knee pitch servo that holds the hub's load and the wheel motor's reaction";
  output Real anklePitchTorque[6](each unit="N.m") "Torque of each limb's ankle pitch servo that holds the hub's load and the wheel motor's reaction";
  output Real ankleSteerTorque[6](each unit="N.m") "Torque of each limb's ankle steer servo that holds the hub's load and the wheel motor's reaction";
  output Real ankleRollTorque[6](each unit="N.m") "Torque of each limb's ankle roll servo that holds the hub's load and the wheel motor's reaction";
  output Real hubX[6](each unit="m") "Hub position in the body frame, ahead of the centre of gravity, where the joint angles put it";
  output Real hubY[6](each unit="m") "Hub position in the body frame, to the left";
  output Real hubZ[6](each unit="m") "Hub position in the body frame, above the centre of gravity (negative)";
  output Real x(unit="m", start=0, fixed=true) "Position of the centre of gravity along the ground's x axis";
  output Real y(unit="m", start=0, fixed=true) "Position of the centre of gravity along the ground's y axis";
  output Real yaw(unit="rad", start=0, fixed=true) "Heading against the ground's x axis, positive to the left";
  output Real v(unit="m/s", start=0, fixed=true) "Forward velocity of the centre of gravity, along the heading";
  output Real vy(unit="m/s", start=0, fixed=true) "Lateral velocity, to the left of the heading";
  output Real yawRate(unit="rad/s", start=0, fixed=true) "Yaw rate";
  output Real z(unit="m", start=height0, fixed=true) "Height of the centre of gravity above the ground plane, along its normal";
  output Real pitch(unit="rad", start=0, fixed=true) "Pitch angle against the ground plane, nose up positive";
  output Real roll(unit="rad", start=0, fixed=true) "Roll angle against the ground plane, left side up positive";
  output Real heaveRate(unit="m/s", start=0, fixed=true) "Rate of z";
  output Real pitchRate(unit="rad/s", start=0, fixed=true) "Pitch rate";
  output Real rollRate(unit="rad/s", start=0, fixed=true) "Roll rate";
  input Real hipYawRate[6](each unit="rad/s", each start=0) "Rates of the hip yaw set-points: with the others, the hubs' velocity against the body (0: held)";
  input Real hipPitchRate[6](each unit="rad/s", each start=0) "Rates of the hip pitch set-points: with the others, the hubs' velocity against the body (0: held)";
  input Real kneePitchRate[6](each unit="rad/s", each start=0) "Rates of the knee pitch set-points: with the others, the hubs' velocity against the body (0: held)";
  input Real anklePitchRate[6](each unit="rad/s", each start=0) "Rates of the ankle pitch set-points: with the others, the hubs' velocity against the body (0: held)";
  input Real ankleSteerRate[6](each unit="rad/s", each start=0) "Rates of the ankle steer set-points: with the others, the hubs' velocity against the body (0: held)";
  input Real ankleRollRate[6](each unit="rad/s", each start=0) "Rates of the ankle roll set-points: with the others, the hubs' velocity against the body (0: held)";
  Real kz[6](each unit="N/m") "Spring of each limb along the ground's normal: kJoint over the squared normal components of its Jacobian's columns";
  Real WLimit[6](each unit="N") "Load at which the limb's most loaded joint reaches the servos' torque limit: the limb yields beyond it";
  Real normal[3](each unit="1") "The ground plane's normal in the body frame";
  Real jacobianNormal[6, 6](each unit="m") "Row i: the normal component of each column of limb i's Jacobian at the set-points";
  Real force[6, 3](each unit="N") "Row i: the force of wheel i on its hub, body frame";
  Real moment[6, 3](each unit="N.m") "Row i: the moment of wheel i's motor on its hub (its reaction), body frame";
  Real jointTorque[6, 6](each unit="N.m") "Row i: limb i's servo torques, joints 1-6";
  Real jointAngle[6, 6](each unit="rad") "Row i: limb i's joint angles";
  RoverTerramechanics.Components.Limb limbSet1(geometry = legs.limb1) "Limb 1 at the joints' set-points";
  RoverTerramechanics.Components.Limb limbSet2(geometry = legs.limb2) "Limb 2 at the joints' set-points";
  RoverTerramechanics.Components.Limb limbSet3(geometry = legs.limb3) "Limb 3 at the joints' set-points";
  RoverTerramechanics.Components.Limb limbSet4(geometry = legs.limb4) "Limb 4 at the joints' set-points";
  RoverTerramechanics.Components.Limb limbSet5(geometry = legs.limb5) "Limb 5 at the joints' set-points";
  RoverTerramechanics.Components.Limb limbSet6(geometry = legs.limb6) "Limb 6 at the joints' set-points";
  RoverTerramechanics.Components.Limb limb1(geometry = legs.limb1) "Limb 1 at its joint angles";
  RoverTerramechanics.Components.Limb limb2(geometry = legs.limb2) "Limb 2 at its joint angles";
  RoverTerramechanics.Components.Limb limb3(geometry = legs.limb3) "Limb 3 at its joint angles";
  RoverTerramechanics.Components.Limb limb4(geometry = legs.limb4) "Limb 4 at its joint angles";
  RoverTerramechanics.Components.Limb limb5(geometry = legs.limb5) "Limb 5 at its joint angles";
  RoverTerramechanics.Components.Limb limb6(geometry = legs.limb6) "Limb 6 at its joint angles";
  Real hubSetX[6](each unit="m") "Hub at the set-points in the body frame, x";
  Real hubSetY[6](each unit="m") "Hub at the set-points, y";
  Real hubSetZ[6](each unit="m") "Hub at the set-points, z";
  Real deflection[6](each unit="m") "Limb compression: how far below the ground the hub at the set-points would be";
  Real deflectionRate[6](each unit="m/s") "Its rate from the body's motion and the set-points' rates";
  Real jointRate[6, 6](each unit="rad/s") "Row i: the rates of limb i's set-points, joints 1-6";
  Real hubRateX[6](each unit="m/s") "Hub velocity against the body from the set-points' rates (J q_set'), body frame x";
  Real hubRateY[6](each unit="m/s") "Its y";
  Real hubRateZ[6](each unit="m/s") "Its z";
  Real yRolledRate[6](each unit="m/s") "The set-points' hub velocity turned by the roll, y";
  Real zRolledRate[6](each unit="m/s") "The set-points' hub velocity turned by the roll, z";
  Real xHubRate[6](each unit="m/s") "The set-points' hub velocity in the heading frame, ahead";
  Real zHubRate[6](each unit="m/s") "The set-points' hub velocity in the heading frame, along the normal";
  Real yRolled[6](each unit="m");
  Real zRolled[6](each unit="m");
  Real xHubWorld[6](each unit="m") "Hub ahead of the centre of gravity (heading frame)";
  Real zHubWorld[6](each unit="m") "Hub height relative to the centre of gravity";
  Real vxHub[6](each unit="m/s");
  Real vyHub[6](each unit="m/s");
  Real FxBody[6](each unit="N");
  Real FyBody[6](each unit="N");
  Real FxHub[6](each unit="N");
  Real FyHub[6](each unit="N");
  Real forcePitched[6, 3](each unit="N");
  Real gAlong(unit="m/s2");
  Real gLateral(unit="m/s2");
protected
  parameter Real gNormal(unit="m/s2") = rover.g*cos(terrain.slope) "Gravity into the ground";
equation
  for k in 1:6 loop
    limb1.q[k] = jointAngle[1, k];
    limb2.q[k] = jointAngle[2, k];
    limb3.q[k] = jointAngle[3, k];
    limb4.q[k] = jointAngle[4, k];
    limb5.q[k] = jointAngle[5, k];
    limb6.q[k] = jointAngle[6, k];
    jacobianNormal[1, k] = limbSet1.jacobian[1, k]*normal[1] + limbSet1.jacobian[2, k]*normal[2] + limbSet1.jacobian[3, k]*normal[3];
    jacobianNormal[2, k] = limbSet2.jacobian[1, k]*normal[1] + limbSet2.jacobian[2, k]*normal[2] + limbSet2.jacobian[3, k]*normal[3];
    jacobianNormal[3, k] = limbSet3.jacobian[1, k]*normal[1] + limbSet3.jacobian[2, k]*normal[2] + limbSet3.jacobian[3, k]*normal[3];
    jacobianNormal[4, k] = limbSet4.jacobian[1, k]*normal[1] + limbSet4.jacobian[2, k]*normal[2] + limbSet4.jacobian[3, k]*normal[3];
    jacobianNormal[5, k] = limbSet5.jacobian[1, k]*normal[1] + limbSet5.jacobian[2, k]*normal[2] + limbSet5.jacobian[3, k]*normal[3];
    jacobianNormal[6, k] = limbSet6.jacobian[1, k]*normal[1] + limbSet6.jacobian[2, k]*normal[2] + limbSet6.jacobian[3, k]*normal[3];
    jointTorque[1, k] = -(limbSet1.jacobian[1, k]*force[1, 1] + limbSet1.jacobian[2, k]*force[1, 2] + limbSet1.jacobian[3, k]*force[1, 3] + limbSet1.axes[1, k]*moment[1, 1] + limbSet1.axes[2, k]*moment[1, 2] + limbSet1.axes[3, k]*moment[1, 3]);
    jointTorque[2, k] = -(limbSet2.jacobian[1, k]*force[2, 1] + limbSet2.jacobian[2, k]*force[2, 2] + limbSet2.jacobian[3, k]*force[2, 3] + limbSet2.axes[1, k]*moment[2, 1] + limbSet2.axes[2, k]*moment[2, 2] + limbSet2.axes[3, k]*moment[2, 3]);
    jointTorque[3, k] = -(limbSet3.jacobian[1, k]*force[3, 1] + limbSet3.jacobian[2, k]*force[3, 2] + limbSet3.jacobian[3, k]*force[3, 3] + limbSet3.axes[1, k]*moment[3, 1] + limbSet3.axes[2, k]*moment[3, 2] + limbSet3.axes[3, k]*moment[3, 3]);
    jointTorque[4, k] = -(limbSet4.jacobian[1, k]*force[4, 1] + limbSet4.jacobian[2, k]*force[4, 2] + limbSet4.jacobian[3, k]*force[4, 3] + limbSet4.axes[1, k]*moment[4, 1] + limbSet4.axes[2, k]*moment[4, 2] + limbSet4.axes[3, k]*moment[4, 3]);
    jointTorque[5, k] = -(limbSet5.jacobian[1, k]*force[5, 1] + limbSet5.jacobian[2, k]*force[5, 2] + limbSet5.jacobian[3, k]*force[5, 3] + limbSet5.axes[1, k]*moment[5, 1] + limbSet5.axes[2, k]*moment[5, 2] + limbSet5.axes[3, k]*moment[5, 3]);
    jointTorque[6, k] = -(limbSet6.jacobian[1, k]*force[6, 1] + limbSet6.jacobian[2, k]*force[6, 2] + limbSet6.jacobian[3, k]*force[6, 3] + limbSet6.axes[1, k]*moment[6, 1] + limbSet6.axes[2, k]*moment[6, 2] + limbSet6.axes[3, k]*moment[6, 3]);
  end for;
  for a in 1:3 loop
    moment[1, a] = -tau[1]*limbSet1.axle[a];
    moment[2, a] = -tau[2]*limbSet2.axle[a];
    moment[3, a] = -tau[3]*limbSet3.axle[a];
    moment[4, a] = -tau[4]*limbSet4.axle[a];
    moment[5, a] = -tau[5]*limbSet5.axle[a];
    moment[6, a] = -tau[6]*limbSet6.axle[a];
  end for;
  limbSet1.q[1] = hipYaw[1];
  limbSet1.q[2] = hipPitch[1];
  limbSet1.q[3] = kneePitch[1];
  limbSet1.q[4] = anklePitch[1];
  limbSet1.q[5] = ankleSteer[1];
  limbSet1.q[6] = ankleRoll[1];
  limbSet2.q[1] = hipYaw[2];
  limbSet2.q[2] = hipPitch[2];
  limbSet2.q[3] = kneePitch[2];
  limbSet2.q[4] = anklePitch[2];
  limbSet2.q[5] = ankleSteer[2];
  limbSet2.q[6] = ankleRoll[2];
  limbSet3.q[1] = hipYaw[3];
  limbSet3.q[2] = hipPitch[3];
  limbSet3.q[3] = kneePitch[3];
  limbSet3.q[4] = anklePitch[3];
  limbSet3.q[5] = ankleSteer[3];
  limbSet3.q[6] = ankleRoll[3];
  limbSet4.q[1] = hipYaw[4];
  limbSet4.q[2] = hipPitch[4];
  limbSet4.q[3] = kneePitch[4];
  limbSet4.q[4] = anklePitch[4];
  limbSet4.q[5] = ankleSteer[4];
  limbSet4.q[6] = ankleRoll[4];
  limbSet5.q[1] = hipYaw[5];
  limbSet5.q[2] = hipPitch[5];
  limbSet5.q[3] = kneePitch[5];
  limbSet5.q[4] = anklePitch[5];
  limbSet5.q[5] = ankleSteer[5];
  limbSet5.q[6] = ankleRoll[5];
  limbSet6.q[1] = hipYaw[6];
  limbSet6.q[2] = hipPitch[6];
  limbSet6.q[3] = kneePitch[6];
  limbSet6.q[4] = anklePitch[6];
  limbSet6.q[5] = ankleSteer[6];
  limbSet6.q[6] = ankleRoll[6];
  for i in 1:6 loop
    jointRate[i, 1] = hipYawRate[i];
    jointRate[i, 2] = hipPitchRate[i];
    jointRate[i, 3] = kneePitchRate[i];
    jointRate[i, 4] = anklePitchRate[i];
    jointRate[i, 5] = ankleSteerRate[i];
    jointRate[i, 6] = ankleRollRate[i];
  end for;
  hubRateX[1] = sum(limbSet1.jacobian[1, k]*jointRate[1, k] for k in 1:6);
  hubRateY[1] = sum(limbSet1.jacobian[2, k]*jointRate[1, k] for k in 1:6);
  hubRateZ[1] = sum(limbSet1.jacobian[3, k]*jointRate[1, k] for k in 1:6);
  hubRateX[2] = sum(limbSet2.jacobian[1, k]*jointRate[2, k] for k in 1:6);
  hubRateY[2] = sum(limbSet2.jacobian[2, k]*jointRate[2, k] for k in 1:6);
  hubRateZ[2] = sum(limbSet2.jacobian[3, k]*jointRate[2, k] for k in 1:6);
  hubRateX[3] = sum(limbSet3.jacobian[1, k]*jointRate[3, k] for k in 1:6);
  hubRateY[3] = sum(limbSet3.jacobian[2, k]*jointRate[3, k] for k in 1:6);
  hubRateZ[3] = sum(limbSet3.jacobian[3, k]*jointRate[3, k] for k in 1:6);
  hubRateX[4] = sum(limbSet4.jacobian[1, k]*jointRate[4, k] for k in 1:6);
  hubRateY[4] = sum(limbSet4.jacobian[2, k]*jointRate[4, k] for k in 1:6);
  hubRateZ[4] = sum(limbSet4.jacobian[3, k]*jointRate[4, k] for k in 1:6);
  hubRateX[5] = sum(limbSet5.jacobian[1, k]*jointRate[5, k] for k in 1:6);
  hubRateY[5] = sum(limbSet5.jacobian[2, k]*jointRate[5, k] for k in 1:6);
  hubRateZ[5] = sum(limbSet5.jacobian[3, k]*jointRate[5, k] for k in 1:6);
  hubRateX[6] = sum(limbSet6.jacobian[1, k]*jointRate[6, k] for k in 1:6);
  hubRateY[6] = sum(limbSet6.jacobian[2, k]*jointRate[6, k] for k in 1:6);
  hubRateZ[6] = sum(limbSet6.jacobian[3, k]*jointRate[6, k] for k in 1:6);
  hubSetX[1] = limbSet1.hub[1];
  hubX[1] = limb1.hub[1];
  hubSetX[2] = limbSet2.hub[1];
  hubX[2] = limb2.hub[1];
  hubSetX[3] = limbSet3.hub[1];
  hubX[3] = limb3.hub[1];
  hubSetX[4] = limbSet4.hub[1];
  hubX[4] = limb4.hub[1];
  hubSetX[5] = limbSet5.hub[1];
  hubX[5] = limb5.hub[1];
  hubSetX[6] = limbSet6.hub[1];
  hubX[6] = limb6.hub[1];
  hubSetY[1] = limbSet1.hub[2];
  hubY[1] = limb1.hub[2];
  hubSetY[2] = limbSet2.hub[2];
  hubY[2] = limb2.hub[2];
  hubSetY[3] = limbSet3.hub[2];
  hubY[3] = limb3.hub[2];
  hubSetY[4] = limbSet4.hub[2];
  hubY[4] = limb4.hub[2];
  hubSetY[5] = limbSet5.hub[2];
  hubY[5] = limb5.hub[2];
  hubSetY[6] = limbSet6.hub[2];
  hubY[6] = limb6.hub[2];
  hubSetZ[1] = limbSet1.hub[3];
  hubZ[1] = limb1.hub[3];
  hubSetZ[2] = limbSet2.hub[3];
  hubZ[2] = limb2.hub[3];
  hubSetZ[3] = limbSet3.hub[3];
  hubZ[3] = limb3.hub[3];
  hubSetZ[4] = limbSet4.hub[3];
  hubZ[4] = limb4.hub[3];
  hubSetZ[5] = limbSet5.hub[3];
  hubZ[5] = limb5.hub[3];
  hubSetZ[6] = limbSet6.hub[3];
  hubZ[6] = limb6.hub[3];
  steer[1] = atan2(-limbSet1.axle[1], limbSet1.axle[2]) "the wheel rolls along axle x up";
  steer[2] = atan2(-limbSet2.axle[1], limbSet2.axle[2]) "the wheel rolls along axle x up";
  steer[3] = atan2(-limbSet3.axle[1], limbSet3.axle[2]) "the wheel rolls along axle x up";
  steer[4] = atan2(-limbSet4.axle[1], limbSet4.axle[2]) "the wheel rolls along axle x up";
  steer[5] = atan2(-limbSet5.axle[1], limbSet5.axle[2]) "the wheel rolls along axle x up";
  steer[6] = atan2(-limbSet6.axle[1], limbSet6.axle[2]) "the wheel rolls along axle x up";
  normal[1] = sin(pitch);
  normal[2] = sin(roll)*cos(pitch);
  normal[3] = cos(roll)*cos(pitch);
  for i in 1:6 loop
    hipYawAngle[i] = jointAngle[i, 1];
    hipYawTorque[i] = jointTorque[i, 1];
    hipPitchAngle[i] = jointAngle[i, 2];
    hipPitchTorque[i] = jointTorque[i, 2];
    kneePitchAngle[i] = jointAngle[i, 3];
    kneePitchTorque[i] = jointTorque[i, 3];
    anklePitchAngle[i] = jointAngle[i, 4];
    anklePitchTorque[i] = jointTorque[i, 4];
    ankleSteerAngle[i] = jointAngle[i, 5];
    ankleSteerTorque[i] = jointTorque[i, 5];
    ankleRollAngle[i] = jointAngle[i, 6];
    ankleRollTorque[i] = jointTorque[i, 6];
    jointAngle[i, 1] = hipYaw[i] - jointTorque[i, 1]/legs.kJoint;
    jointAngle[i, 2] = hipPitch[i] - jointTorque[i, 2]/legs.kJoint;
    jointAngle[i, 3] = kneePitch[i] - jointTorque[i, 3]/legs.kJoint;
    jointAngle[i, 4] = anklePitch[i] - jointTorque[i, 4]/legs.kJoint;
    jointAngle[i, 5] = ankleSteer[i] - jointTorque[i, 5]/legs.kJoint;
    jointAngle[i, 6] = ankleRoll[i] - jointTorque[i, 6]/legs.kJoint;
  end for;
  gAlong = rover.g*sin(terrain.slope)*cos(terrain.downhill - yaw);
  gLateral = rover.g*sin(terrain.slope)*sin(terrain.downhill - yaw);
  der(x) = v*cos(yaw) - vy*sin(yaw);
  der(y) = v*sin(yaw) + vy*cos(yaw);
  der(yaw) = yawRate;
  der(z) = heaveRate;
  der(pitch) = pitchRate;
  der(roll) = rollRate;
  for i in 1:6 loop
    kz[i] = legs.kJoint/(jacobianNormal[i, 1]^2 + jacobianNormal[i, 2]^2 + jacobianNormal[i, 3]^2 + jacobianNormal[i, 4]^2 + jacobianNormal[i, 5]^2 + jacobianNormal[i, 6]^2);
    WLimit[i] = legs.tauJointMax/noEvent(max(max(max(abs(jacobianNormal[i, 1]), abs(jacobianNormal[i, 2])), max(abs(jacobianNormal[i, 3]), abs(jacobianNormal[i, 4]))), max(abs(jacobianNormal[i, 5]), abs(jacobianNormal[i, 6]))));
    yRolled[i] = hubSetY[i]*cos(roll) - hubSetZ[i]*sin(roll);
    zRolled[i] = hubSetY[i]*sin(roll) + hubSetZ[i]*cos(roll);
    xHubWorld[i] = hubSetX[i]*cos(pitch) - zRolled[i]*sin(pitch);
    zHubWorld[i] = hubSetX[i]*sin(pitch) + zRolled[i]*cos(pitch);
    deflection[i] = groundHeight[i] - (z + zHubWorld[i]);
    yRolledRate[i] = hubRateY[i]*cos(roll) - hubRateZ[i]*sin(roll);
    zRolledRate[i] = hubRateY[i]*sin(roll) + hubRateZ[i]*cos(roll);
    xHubRate[i] = hubRateX[i]*cos(pitch) - zRolledRate[i]*sin(pitch);
    zHubRate[i] = hubRateX[i]*sin(pitch) + zRolledRate[i]*cos(pitch);
    deflectionRate[i] = -heaveRate - pitchRate*xHubWorld[i] - rollRate*cos(pitch)*yRolled[i] - zHubRate[i] + groundHeightRate[i];
    W[i] = noEvent(max(min(kz[i]*deflection[i] + kz[i]*legs.dJoint/legs.kJoint*deflectionRate[i], WLimit[i]), 0.0));
    vxHub[i] = v - pitchRate*zHubWorld[i] - rollRate*sin(pitch)*yRolled[i] - yawRate*yRolled[i] + xHubRate[i];
    vyHub[i] = vy - rollRate*zRolled[i] + yawRate*xHubWorld[i] + yRolledRate[i];
    v_hub[i] = vxHub[i]*cos(steer[i]) + vyHub[i]*sin(steer[i]);
    v_lat[i] = vyHub[i]*cos(steer[i]) - vxHub[i]*sin(steer[i]);
    FxBody[i] = Fx[i]*cos(steer[i]) - Fy[i]*sin(steer[i]);
    FyBody[i] = Fx[i]*sin(steer[i]) + Fy[i]*cos(steer[i]);
    FxHub[i] = FxBody[i] - W[i]*groundGradientAlong[i];
    FyHub[i] = FyBody[i] - W[i]*groundGradientLateral[i];
    forcePitched[i, 1] = FxHub[i]*cos(pitch) + W[i]*sin(pitch);
    forcePitched[i, 2] = FyHub[i];
    forcePitched[i, 3] = -FxHub[i]*sin(pitch) + W[i]*cos(pitch);
    force[i, 1] = forcePitched[i, 1];
    force[i, 2] = forcePitched[i, 2]*cos(roll) + forcePitched[i, 3]*sin(roll);
    force[i, 3] = -forcePitched[i, 2]*sin(roll) + forcePitched[i, 3]*cos(roll);
  end for;
  rover.M*(der(v) - yawRate*vy) = sum(FxHub) + rover.M*gAlong;
  rover.M*(der(vy) + yawRate*v) = sum(FyHub) + rover.M*gLateral;
  rover.Izz*der(yawRate) = sum(xHubWorld[i]*FyHub[i] - yRolled[i]*FxHub[i] for i in 1:6);
  rover.M*der(heaveRate) = sum(W) - rover.M*gNormal;
  rover.Iyy*der(pitchRate) = sum(xHubWorld[i]*W[i] - zHubWorld[i]*FxHub[i] + tau[i]*cos(steer[i]) for i in 1:6);
  rover.Ixx*der(rollRate) = sum(yRolled[i]*W[i] - zHubWorld[i]*FyHub[i] + tau[i]*sin(steer[i]) for i in 1:6);
  assert(rover.M > 0, "rover.M: the mass must be > 0 kg");
  assert(legs.kJoint > 0, "legs.kJoint: the joint servos' stiffness must be > 0 N.m/rad");
  assert(legs.dJoint >= 0, "legs.dJoint: the joint servos' damping must be >= 0 N.m.s/rad");
  assert(legs.tauJointMax > 0, "legs.tauJointMax: the joint servos' torque limit must be > 0 N.m");
  annotation (Documentation(info="<html>
<p>The body of <code>SteerableChassis</code> (x, y, yaw in the ground plane; heave, pitch, roll
against it) carried by six limbs of six joints (<code>Parameters.LegWheelParameters</code>), each
joint a position servo of stiffness k<sub>joint</sub>, damping d<sub>joint</sub> and torque limit
&tau;<sub>max</sub>. The hubs sit where the joints' set-points (the inputs) put them
(<code>Components.Limb</code>, body frame); each wheel's heading follows from its limb's axle
(the ankle steer joint steers: <code>steer</code>).</p>
<p><b>Limb compliance.</b> The servos' compliance at the hub is C = J K<sup>-1</sup> J<sup>T</sup>
(J the hub's Jacobian at the set-points, K = k<sub>joint</sub> I). Along the ground's normal n (body
frame) the limb is the spring k<sub>n</sub> = 1 / (n<sup>T</sup> C n) = k<sub>joint</sub> /
&Sigma;<sub>k</sub> (n&middot;J<sub>k</sub>)<sup>2</sup>, damped in the same proportion:
W<sub>i</sub> = max(min(k<sub>n</sub> &delta;<sub>i</sub> + d<sub>n</sub> d&delta;<sub>i</sub>/dt,
W<sub>limit,i</sub>), 0), &delta;<sub>i</sub> how far below the ground the hub at the set-points
would be. W<sub>limit,i</sub> = &tau;<sub>max</sub> / max<sub>k</sub> |n&middot;J<sub>k</sub>|: beyond
the load at which its most loaded joint reaches the torque limit the limb yields (the servo holds its
limit and gives way). The compliance across the normal is not modelled (the hubs' horizontal
positions are the set-points').</p>
<p><b>Moving limbs.</b> The set-points' rates (<code>hipYawRate</code> ... <code>ankleRollRate</code>
[rad/s], the inputs' derivatives: a master that ramps the set-points gives their slopes, 0 holds
them) move each hub against the body at J q&#775;<sub>set</sub> (body frame, J at the set-points). That
velocity, turned into the heading frame by the roll and pitch, adds to the hub's velocity from the
body's motion: what the wheel rolls or slides over (<code>v_hub</code>, <code>v_lat</code>) and, along
the normal, the limb's compression rate d&delta;<sub>i</sub>/dt. So a limb that swings a planted
hub back makes its wheel roll (or, braked, push the body ahead), and one that presses its hub down
loads it through the servos' damping as well as their stiffness. A hub moved without its rate (rates
left at 0) jumps relative to the ground as the body stays: the wheel does not see it.</p>
<p><b>Joint torques and angles.</b> The wheel pushes on its hub with the force F (its loads
W, F<sub>x</sub>, F<sub>y</sub> turned into the body frame) and the reaction M = -&tau; a of its
motor (a the axle); the servos hold them with &tau;<sub>joint</sub> = -J<sup>T</sup> (F, M) (virtual
work; the rows 4-6 of the geometric Jacobian are the joints' axes) and deflect to
q = q<sub>set</sub> - &tau;<sub>joint</sub> / k<sub>joint</sub> (quasi-static: the joints' own inertia is not
modelled). <code>hubX</code>, <code>hubY</code>, <code>hubZ</code> are the hubs at these
angles (the dynamics use the hubs at the set-points plus the normal spring: the two differ by
the second order of the deflection).</p>
<p><b>Contact causality.</b> As <code>Chassis</code>'s: the load comes out of the compliant limb
(W<sub>i</sub> from the hub's height over the ground); the wheel's sinkage is not fed back into the
hub's height (it would close an algebraic loop between load and sinkage). So the co-simulation cut
is the same as the steerable rover's: W, v_hub, v_lat out of the body, F<sub>x</sub>, F<sub>y</sub>
in from the wheels. <code>z</code> is the centre of gravity's height over the ground plane (start
<code>height0</code>); the body equations are <code>SteerableChassis</code>'s with the hub's body
position from the limb instead of (x<sub>i</sub>, y<sub>i</sub>, -h<sub>CoG</sub>).</p>
</html>"));
end LegWheelChassis;
