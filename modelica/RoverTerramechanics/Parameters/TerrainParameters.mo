within RoverTerramechanics.Parameters;
record TerrainParameters "Ground plane under the steerable rover: slope angle and downhill direction"
  parameter Real slope(unit="rad", displayUnit="deg", min=0, max=1.5707963267948966) = 0 "Inclination of the ground plane against the horizontal, 0 <= slope < pi/2 (0: level ground)";
  parameter Real downhill(unit="rad", displayUnit="deg") = 0 "Direction of steepest descent in the ground plane, measured from the ground's x axis, positive to the left (-pi/2: a path along x runs across the slope with the valley to its right)";
  annotation (Documentation(info="<html>
<p>The ground of the steerable rover is a plane of inclination <code>slope</code> = &theta;
whose direction of steepest descent makes the angle <code>downhill</code> = &psi;<sub>d</sub>
with the ground's x axis. The body's position (x, y) and heading are measured in that plane
(x, y along the ground, the heading about its normal). The world height of the ground point
(x, y) is</p>
<p>z<sub>ground</sub>(x, y) = -sin &theta; (x cos &psi;<sub>d</sub> + y sin &psi;<sub>d</sub>),</p>
<p>and gravity (0, 0, -g) has, in the heading frame of a body with heading &psi; (x forward, y
left, z along the ground's normal),</p>
<ul>
<li>along the heading: g<sub>x</sub> = g sin &theta; cos(&psi;<sub>d</sub> - &psi;),</li>
<li>to the left: g<sub>y</sub> = g sin &theta; sin(&psi;<sub>d</sub> - &psi;),</li>
<li>along the normal: -g<sub>n</sub> = -g cos &theta;.</li>
</ul>
<p>A plane of gradients G<sub>x</sub> = dz/dx and G<sub>y</sub> = dz/dy (world, horizontal
coordinates) is &theta; = atan(sqrt(G<sub>x</sub><sup>2</sup> + G<sub>y</sub><sup>2</sup>)),
&psi;<sub>d</sub> = atan2(-G<sub>y</sub>, -G<sub>x</sub>); the ground's x axis is then world x
turned into the plane about the horizontal line across the slope (a side slope leaves it
horizontal, an up- or down-slope tilts it by &theta;). The pitch-plane <code>Chassis</code>'s
<code>slope</code> (positive uphill along x) is slope = |slope|, downhill = &pi; (uphill) or 0.</p>
<p>The same formulas are <code>rover_cosim.terramechanics.terrain.PlaneTerrain</code> in
Python (the controller's feed-forward, the reference and the energy balance). Source: the
weight's components on a slope as in Ishigami, Miwa, Nagatani, Yoshida (J. Field Robotics
24(3), 2007), who steer a rover across slopes of loose soil.</p>
</html>"));
end TerrainParameters;
