within RoverTerramechanics;
package Components "Building blocks: the terramechanics rigid wheel and the rover chassis"
  annotation (Documentation(info="<html>
<p><code>RigidWheel</code>: wheel spin dynamics and terramechanics contact (paper Sec. 2).
<code>Chassis</code>: the rover body in the pitch plane on six compliant limbs.
<code>SteerableChassis</code>: the rover body free in the plane, every wheel steered. Each
extends its side of the hub cut from <code>Interfaces</code>. The models of <code>FMUs</code>
and <code>Examples.RoverReconnected</code> are built from these, so the physics is written
once.</p>
</html>"));
end Components;
