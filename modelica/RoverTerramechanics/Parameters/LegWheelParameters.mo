within RoverTerramechanics.Parameters;
record LegWheelParameters "The six limbs of the leg-wheel rover: mounts on a hexagonal frame, link lengths, joint servos"
  parameter RoverTerramechanics.Parameters.LimbParameters limb1(mount = {1.190784930203603, 0.6875, 0.0}, mountYaw = 0.5235987755982988) "Front left";
  parameter RoverTerramechanics.Parameters.LimbParameters limb2(mount = {0.0, 1.375, 0.0}, mountYaw = 1.5707963267948966) "Middle left";
  parameter RoverTerramechanics.Parameters.LimbParameters limb3(mount = {-1.190784930203603, 0.6875, 0.0}, mountYaw = 2.6179938779914944) "Rear left";
  parameter RoverTerramechanics.Parameters.LimbParameters limb4(mount = {1.190784930203603, -0.6875, 0.0}, mountYaw = -0.5235987755982988) "Front right";
  parameter RoverTerramechanics.Parameters.LimbParameters limb5(mount = {0.0, -1.375, 0.0}, mountYaw = -1.5707963267948966) "Middle right";
  parameter RoverTerramechanics.Parameters.LimbParameters limb6(mount = {-1.190784930203603, -0.6875, 0.0}, mountYaw = -2.6179938779914944) "Rear right";
  parameter Real kJoint(unit="N.m/rad") = 2.0e4 "Stiffness of each joint's position servo";
  parameter Real dJoint(unit="N.m.s/rad") = 2.0e3 "Damping of each joint's position servo";
  parameter Real tauJointMax(unit="N.m") = 2.0e3 "Torque limit of each joint's servo: beyond it the joint gives way";
  annotation (Documentation(info="<html>
<p>The mounts are the corners of a hexagonal frame 2.75 m across (ATHLETE's size, Wilcox et al.
2007), each limb pointing radially out at zero hip yaw, numbered as the rover's wheels (1-3 front,
middle, rear on the left; 4-6 mirror them). Each joint is a position servo about its set-point
of stiffness <code>kJoint</code>, damping <code>dJoint</code> and torque limit <code>tauJointMax</code> (ours: about
five times the hip's torque in the paper's posture at rest): the limb's compliance at
the hub is C = J K<sup>-1</sup> J<sup>T</sup> (<code>Components.Limb</code>'s Jacobian), its
vertical spring 1/C<sub>zz</sub>, the damping in the same proportion. The same geometry in Python:
<code>rover_cosim.limbs.athlete_limbs()</code>.</p>
</html>"));
end LegWheelParameters;
