within RoverTerramechanics.Components;
model LegWheelChassis "Leg-wheel rover body (x, y, yaw, heave, pitch, roll) on six limbs of six joint servos each, cut at the wheel hubs"
  extends RoverTerramechanics.Interfaces.GroundContacts(final nWheels=6);
  parameter RoverTerramechanics.Parameters.RoverParameters rover "Mass, inertias and gravity (the limb fields are not used: the limbs are legs)";
  parameter RoverTerramechanics.Parameters.LegWheelParameters legs "Limb mounts, link lengths and joint servos";
  parameter Real height0(unit="m") = 1.0 "Start height of the centre of gravity above the ground plane";
  input Real hipYaw[6](each unit="rad") "Set-points of the hip yaw joints";
  input Real hipPitch[6](each unit="rad") "Set-points of the hip pitch joints (positive: the thigh down)";
  input Real kneePitch[6](each unit="rad") "Set-points of the knee pitch joints";
  input Real anklePitch[6](each unit="rad") "Set-points of the ankle pitch joints";
  input Real ankleSteer[6](each unit="rad") "Set-points of the ankle steer joints (the wheels' steering)";
  input Real ankleRoll[6](each unit="rad") "Set-points of the ankle roll joints (the wheels' camber)";
  input Real Fx[6](each unit="N") "Longitudinal force of each wheel on its hub, along the wheel's heading";
  input Real Fy[6](each unit="N") "Lateral force of each wheel on its hub, to the wheel's left";
  input Real tau[6](each unit="N.m") "Drive torque of each wheel motor; its reaction acts on the body";
  output Real W[6](each unit="N") "Wheel loads: what the compliant limbs press into the soil";
  output Real v_hub[6](each unit="m/s") "Hub speed along each wheel's heading";
  output Real v_lat[6](each unit="m/s") "Hub speed to each wheel's left";
  output Real steer[6](each unit="rad") "Heading of each wheel against the body's, from its limb's joints";
  output Real hubX[6](each unit="m") "Hub position in the body frame, ahead of the centre of gravity";
  output Real hubY[6](each unit="m") "Hub position in the body frame, to the left";
  output Real hubZ[6](each unit="m") "Hub position in the body frame, above the centre of gravity (negative)";
  output Real x(unit="m", start=0, fixed=true) "Position of the centre of gravity along the ground's x axis";
  output Real y(unit="m", start=0, fixed=true) "Position of the centre of gravity along the ground's y axis";
  output Real yaw(unit="rad", start=0, fixed=true) "Heading against the ground's x axis, positive to the left";
  output Real v(unit="m/s", start=0, fixed=true) "Forward velocity of the centre of gravity, along the heading";
  output Real vy(unit="m/s", start=0, fixed=true) "Lateral velocity, to the left of the heading";
  output Real yawRate(unit="rad/s", start=0, fixed=true) "Yaw rate";
  output Real z(unit="m", start=height0, fixed=true) "Height of the centre of gravity above the ground plane";
  output Real pitch(unit="rad", start=0, fixed=true) "Pitch angle, nose up positive";
  output Real roll(unit="rad", start=0, fixed=true) "Roll angle, left side up positive";
  Real w(unit="m/s", start=0, fixed=true) "Heave velocity";
  Real q(unit="rad/s", start=0, fixed=true) "Pitch rate";
  Real p(unit="rad/s", start=0, fixed=true) "Roll rate";
  Real kz[6](each unit="N/m") "Vertical spring of each limb: 1/C_zz of its joint servos";
  Real jacobian1[3, 6](each unit="m");
  Real jacobian2[3, 6](each unit="m");
  Real jacobian3[3, 6](each unit="m");
  Real jacobian4[3, 6](each unit="m");
  Real jacobian5[3, 6](each unit="m");
  Real jacobian6[3, 6](each unit="m");
  Real hub1[3](each unit="m");
  Real hub2[3](each unit="m");
  Real hub3[3](each unit="m");
  Real hub4[3](each unit="m");
  Real hub5[3](each unit="m");
  Real hub6[3](each unit="m");
  Real link1[3](each unit="1");
  Real link2[3](each unit="1");
  Real link3[3](each unit="1");
  Real link4[3](each unit="1");
  Real link5[3](each unit="1");
  Real link6[3](each unit="1");
  Real axle1[3](each unit="1");
  Real axle2[3](each unit="1");
  Real axle3[3](each unit="1");
  Real axle4[3](each unit="1");
  Real axle5[3](each unit="1");
  Real axle6[3](each unit="1");
  Real axleX[6](each unit="1") "Each wheel's axle in the body frame, x";
  Real axleY[6](each unit="1") "Each wheel's axle in the body frame, y";
  Real deflection[6](each unit="m") "Limb compression: how far below the ground the unloaded hub would be";
  Real deflectionRate[6](each unit="m/s") "Its rate from the body's motion";
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
  Real gAlong(unit="m/s2");
  Real gLateral(unit="m/s2");
protected
  parameter Real gNormal(unit="m/s2") = rover.g*cos(terrain.slope) "Gravity into the ground";
public
  parameter RoverTerramechanics.Parameters.TerrainParameters terrain "Ground plane (default level)";
equation
  (hub1, link1, axle1, jacobian1) = RoverTerramechanics.Functions.limbForward(legs.limb1, {hipYaw[1], hipPitch[1], kneePitch[1], anklePitch[1], ankleSteer[1], ankleRoll[1]});
  (hub2, link2, axle2, jacobian2) = RoverTerramechanics.Functions.limbForward(legs.limb2, {hipYaw[2], hipPitch[2], kneePitch[2], anklePitch[2], ankleSteer[2], ankleRoll[2]});
  (hub3, link3, axle3, jacobian3) = RoverTerramechanics.Functions.limbForward(legs.limb3, {hipYaw[3], hipPitch[3], kneePitch[3], anklePitch[3], ankleSteer[3], ankleRoll[3]});
  (hub4, link4, axle4, jacobian4) = RoverTerramechanics.Functions.limbForward(legs.limb4, {hipYaw[4], hipPitch[4], kneePitch[4], anklePitch[4], ankleSteer[4], ankleRoll[4]});
  (hub5, link5, axle5, jacobian5) = RoverTerramechanics.Functions.limbForward(legs.limb5, {hipYaw[5], hipPitch[5], kneePitch[5], anklePitch[5], ankleSteer[5], ankleRoll[5]});
  (hub6, link6, axle6, jacobian6) = RoverTerramechanics.Functions.limbForward(legs.limb6, {hipYaw[6], hipPitch[6], kneePitch[6], anklePitch[6], ankleSteer[6], ankleRoll[6]});
  hubX = {hub1[1], hub2[1], hub3[1], hub4[1], hub5[1], hub6[1]};
  hubY = {hub1[2], hub2[2], hub3[2], hub4[2], hub5[2], hub6[2]};
  hubZ = {hub1[3], hub2[3], hub3[3], hub4[3], hub5[3], hub6[3]};
  axleX = {axle1[1], axle2[1], axle3[1], axle4[1], axle5[1], axle6[1]};
  axleY = {axle1[2], axle2[2], axle3[2], axle4[2], axle5[2], axle6[2]};
  kz = legs.kJoint*{1/sum(jacobian1[3, k]^2 for k in 1:6), 1/sum(jacobian2[3, k]^2 for k in 1:6), 1/sum(jacobian3[3, k]^2 for k in 1:6), 1/sum(jacobian4[3, k]^2 for k in 1:6), 1/sum(jacobian5[3, k]^2 for k in 1:6), 1/sum(jacobian6[3, k]^2 for k in 1:6)};
  gAlong = rover.g*sin(terrain.slope)*cos(terrain.downhill - yaw);
  gLateral = rover.g*sin(terrain.slope)*sin(terrain.downhill - yaw);
  der(x) = v*cos(yaw) - vy*sin(yaw);
  der(y) = v*sin(yaw) + vy*cos(yaw);
  der(yaw) = yawRate;
  der(z) = w;
  der(pitch) = q;
  der(roll) = p;
  for i in 1:6 loop
    steer[i] = atan2(-axleX[i], axleY[i]) "the wheel rolls along axle x up";
    yRolled[i] = hubY[i]*cos(roll) - hubZ[i]*sin(roll);
    zRolled[i] = hubY[i]*sin(roll) + hubZ[i]*cos(roll);
    xHubWorld[i] = hubX[i]*cos(pitch) - zRolled[i]*sin(pitch);
    zHubWorld[i] = hubX[i]*sin(pitch) + zRolled[i]*cos(pitch);
    deflection[i] = groundHeight[i] - (z + zHubWorld[i]);
    deflectionRate[i] = -w - q*xHubWorld[i] - p*cos(pitch)*yRolled[i] + groundHeightRate[i];
    W[i] = noEvent(max(kz[i]*deflection[i] + kz[i]*legs.dJoint/legs.kJoint*deflectionRate[i], 0.0));
    vxHub[i] = v - q*zHubWorld[i] - p*sin(pitch)*yRolled[i] - yawRate*yRolled[i];
    vyHub[i] = vy - p*zRolled[i] + yawRate*xHubWorld[i];
    v_hub[i] = vxHub[i]*cos(steer[i]) + vyHub[i]*sin(steer[i]);
    v_lat[i] = vyHub[i]*cos(steer[i]) - vxHub[i]*sin(steer[i]);
    FxBody[i] = Fx[i]*cos(steer[i]) - Fy[i]*sin(steer[i]);
    FyBody[i] = Fx[i]*sin(steer[i]) + Fy[i]*cos(steer[i]);
    FxHub[i] = FxBody[i] - W[i]*groundGradientAlong[i];
    FyHub[i] = FyBody[i] - W[i]*groundGradientLateral[i];
  end for;
  rover.M*(der(v) - yawRate*vy) = sum(FxHub) + rover.M*gAlong;
  rover.M*(der(vy) + yawRate*v) = sum(FyHub) + rover.M*gLateral;
  rover.Izz*der(yawRate) = sum(xHubWorld[i]*FyHub[i] - yRolled[i]*FxHub[i] for i in 1:6);
  rover.M*der(w) = sum(W) - rover.M*gNormal;
  rover.Iyy*der(q) = sum(xHubWorld[i]*W[i] - zHubWorld[i]*FxHub[i] + tau[i]*cos(steer[i]) for i in 1:6);
  rover.Ixx*der(p) = sum(yRolled[i]*W[i] - zHubWorld[i]*FyHub[i] + tau[i]*sin(steer[i]) for i in 1:6);
  assert(rover.M > 0, "rover.M: the mass must be > 0 kg");
  assert(legs.kJoint > 0, "legs.kJoint: the joint servos' stiffness must be > 0 N.m/rad");
  assert(legs.dJoint >= 0, "legs.dJoint: the joint servos' damping must be >= 0 N.m.s/rad");
  annotation (Documentation(info="<html>
<p>The body of <code>SteerableChassis</code> (x, y, yaw in the ground plane; heave, pitch, roll)
carried by six limbs of six joints (<code>Parameters.LegWheelParameters</code>). The hubs sit where
the joints' set-points put them (<code>Functions.limbForward</code>, body frame); the wheels' headings
follow from the limbs' axles (the ankle steer joint steers). Each limb is the spring of its joint
servos at the hub: vertical stiffness k<sub>z</sub> = k<sub>joint</sub> / &Sigma;<sub>k</sub>
J<sub>z,k</sub><sup>2</sup> (1/C<sub>zz</sub> of C = J K<sup>-1</sup> J<sup>T</sup>), damping in the same
proportion, so W<sub>i</sub> = max(k<sub>z</sub> &delta;<sub>i</sub> + d<sub>z</sub> d&delta;<sub>i</sub>/dt, 0)
with &delta;<sub>i</sub> how far below the ground the unloaded hub would be. The contact
causality is <code>Chassis</code>'s: the load comes out of the compliant limb; the wheel's sinkage is
not fed back into the hub's height (it would close an algebraic loop between load and sinkage).
<code>z</code> is the centre of gravity's height over the ground plane (start
<code>height0</code>). The body equations are <code>SteerableChassis</code>'s with the hub's body
position from the limb instead of (x<sub>i</sub>, y<sub>i</sub>, -h<sub>CoG</sub>).</p>
</html>"));
end LegWheelChassis;
