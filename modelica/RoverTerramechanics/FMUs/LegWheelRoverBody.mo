within RoverTerramechanics.FMUs;
model LegWheelRoverBody "Leg-wheel rover body on six limbs of six joint servos for co-simulation: joint set-points, Fx[i], Fy[i], tau[i] in; wheel loads W[i], hub velocities, joint angles and torques, hub poses out"
  extends RoverTerramechanics.Components.LegWheelChassis(hipYaw(start = {0.6835504671705936, 0.0, -0.6835504671705932, -0.6835504671705936, 0.0, 0.6835504671705932}), hipPitch(start = {-0.41027729528934376, 0.10605678318355172, -0.41027729528934376, -0.41027729528934376, 0.10605678318355172, -0.41027729528934376}), kneePitch(start = {2.028751485911332, 2.518688308843155, 2.028751485911332, 2.028751485911332, 2.518688308843155, 2.028751485911332}), anklePitch(start = {-0.04767786382709138, -1.0539487652318102, -0.04767786382709138, -0.04767786382709138, -1.0539487652318102, -0.04767786382709138}), ankleSteer(start = {1.2071492427688926, 1.5707963267948974, 1.9344434108209012, -1.2071492427688926, -1.5707963267948974, -1.9344434108209012}), ankleRoll(start = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0}));
  annotation (
    experiment(StartTime=0, StopTime=5, Interval=0.01),
    Documentation(info="<html>
<p>The body side of the leg-wheel rover cut at the wheel hubs (FMU <code>LegWheelRoverBody</code>):
<code>Components.LegWheelChassis</code>, the body on six limbs of six joint servos. Inputs: the 36
joint set-points (<code>hipYaw[1..6]</code>, <code>hipPitch</code>, <code>kneePitch</code>,
<code>anklePitch</code>, <code>ankleSteer</code>, <code>ankleRoll</code> [rad]; start: the paper's
posture, hubs at x = 1.5, 0, -1.5 m, y = &plusmn;1.5 m, 1.0 m below the centre of gravity) and their
rates (<code>hipYawRate</code> ... <code>ankleRollRate</code> [rad/s], default 0), the hub
forces <code>Fx[1..6]</code>, <code>Fy[1..6]</code> [N] from six <code>Wheel</code>s (in their
frames), the drive torques <code>tau[1..6]</code> [N&middot;m] and the ground under each hub
(<code>Interfaces.GroundContacts</code>). Outputs: to the wheels <code>W[1..6]</code> [N],
<code>v_hub[1..6]</code>, <code>v_lat[1..6]</code> [m/s]; the wheels' headings <code>steer</code>;
joint angles (<code>hipYawAngle</code> ...) and servo torques (<code>hipYawTorque</code> ...), hub
positions <code>hubX</code>, <code>hubY</code>, <code>hubZ</code> (body frame), the body's pose and
velocity. The steering is the ankle steer joints': a wheel has no steering input of its own.</p>
</html>"));
end LegWheelRoverBody;
