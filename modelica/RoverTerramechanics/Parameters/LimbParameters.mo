within RoverTerramechanics.Parameters;
record LimbParameters "One limb of the leg-wheel rover: its mount on the body and its link lengths (six rotary joints after NASA/JPL's ATHLETE)"
  parameter Real mount[3](each unit="m") = {1.190784930203603, 0.6875, 0.0} "Position of the hip yaw joint in the body frame (x forward, y left, z up, from the centre of gravity)";
  parameter Real mountYaw(unit="rad") = 0.5235987755982988 "Direction the limb points at zero hip yaw, from the body's x axis to the left";
  parameter Real thigh(unit="m") = 1.0 "Hip pitch joint to knee";
  parameter Real shank(unit="m") = 1.0 "Knee to ankle pitch joint";
  parameter Real ankle(unit="m") = 0.25 "Ankle pitch joint to the ankle steer and roll joints";
  parameter Real hubOffset(unit="m") = 0.15 "Ankle roll joint to the wheel hub";
  annotation (Documentation(info="<html>
<p>The joints of a limb from the body out: hip yaw q<sub>1</sub> about the body's z axis; hip
pitch q<sub>2</sub>, knee pitch q<sub>3</sub> and ankle pitch q<sub>4</sub> about the limb's
horizontal axis (positive: the link tips down); ankle steer q<sub>5</sub> about the ankle link;
ankle roll q<sub>6</sub> about the axis normal to the link and the axle (the wheel's camber).
Wilcox et al. (J. Field Robotics 24, 2007) give ATHLETE six rotary joints per limb (hip yaw, hip,
knee and ankle pitch, two at the ankle); the axes of the two ankle joints and every length here
are our stated reading: a hexagonal frame 2.75 m across (the mount of limb 1 at its front-left
corner, the default), 1.0 m thigh and shank, an ankle link of 0.25 m and the hub 0.15 m beyond
the roll joint. The same geometry in Python: <code>rover_cosim.limbs.LimbGeometry</code>
(the cross-check of <code>Components.Limb</code>).</p>
</html>"));
end LimbParameters;
