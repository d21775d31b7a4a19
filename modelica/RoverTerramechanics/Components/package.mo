within RoverTerramechanics;
package Components "Building blocks: the terramechanics rigid wheel and the rover chassis"
  annotation (Documentation(info="<html>
<p><code>RigidWheel</code>: wheel spin dynamics and terramechanics contact (paper Sec. 2).
<code>Chassis</code>: the rover body in the pitch plane on six compliant limbs. The models at the
top of the package (SingleWheel, Rover, RoverBody, Wheel, RoverReconnected) are built from
these two, so the physics is written once.</p>
</html>"));
end Components;
