within RoverTerramechanics;
package Interfaces "Partial models of the cut at the wheel hubs: the signals a wheel and the rover body exchange, declared once"
  annotation (Documentation(info="<html>
<p>The rover is cut at its wheel hubs: the body gives each wheel its load and hub velocity and
the drive torque, each wheel gives the body its hub forces. These partial models declare the
signals of each side once, with units and descriptions; the physics that extends them and the
FMU top levels built from that physics inherit the same names.</p>
<ul>
<li><code>WheelHub</code>: the wheel side (one wheel). Extended by
<code>Components.RigidWheel</code>, hence by <code>FMUs.Wheel</code> and by every wheel of
<code>FMUs.SingleWheel</code>, <code>FMUs.Rover</code> and <code>FMUs.SteerableRover</code>.</li>
<li><code>BodyHubs</code>: the body side of the pitch-plane rover (six hubs). Extended by
<code>Components.Chassis</code>, hence by <code>FMUs.RoverBody</code> and the body of
<code>FMUs.Rover</code>.</li>
<li><code>SteerableBodyHubs</code>: the body side of the steerable rover (six steered hubs).
Extended by <code>Components.SteerableChassis</code>, hence by
<code>FMUs.SteerableRoverBody</code> and the body of <code>FMUs.SteerableRover</code>.</li>
<li><code>PitchPlaneRover</code>: the inputs and outputs of the whole pitch-plane rover, the
same for the monolithic <code>FMUs.Rover</code> and for <code>Examples.RoverReconnected</code>
(body and six wheels wired through the cut).</li>
</ul>
<p>A co-simulation wires the FMUs exactly along these declarations:
<code>RoverBody.W[i]</code> &rarr; <code>Wheel.W</code>, <code>RoverBody.v_hub[i]</code>
&rarr; <code>Wheel.v_hub</code>, <code>Wheel.Fx</code> &rarr; <code>RoverBody.Fx[i]</code>,
and the drive torque to both (<code>orchestrator/systems/rover_cosim.toml</code>); the steerable
rover adds <code>v_lat</code>, <code>Fy</code> and <code>steer</code>
(<code>steerable_rover_cosim.toml</code>). The variables of the FMUs keep these names.</p>
</html>"));
end Interfaces;
