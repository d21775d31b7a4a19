within RoverTerramechanics.UsersGuide;
class Examples "Examples: the runnable experiments"
  annotation (Documentation(info="<html>
<table border=\"1\" cellpadding=\"3\">
<tr><th>example</th><th>what</th><th>experiment</th></tr>
<tr><td><a href=\"modelica://RoverTerramechanics.Examples.SingleWheelStep\">Examples.SingleWheelStep</a></td>
<td>torque step 0 &rarr; <code>tauStep</code> (50 N&middot;m) at t = 0 on
<code>FMUs.SingleWheel</code> at <code>W</code> (424 N)</td><td>0-4 s, 10 ms</td></tr>
<tr><td><a href=\"modelica://RoverTerramechanics.Examples.RoverOpenLoop\">Examples.RoverOpenLoop</a></td>
<td><code>FMUs.Rover</code> from rest, all wheels <code>openLoopTorque(time)</code>: 40
N&middot;m, blended (tanh) to 9 N&middot;m at 3 s; about 1 m/s at 3 s</td><td>0-6 s, 10
ms</td></tr>
<tr><td><a href=\"modelica://RoverTerramechanics.Examples.RoverReconnectedOpenLoop\">Examples.RoverReconnectedOpenLoop</a></td>
<td>the same on <code>Examples.RoverReconnected</code></td><td>0-6 s, 10 ms</td></tr>
<tr><td><a href=\"modelica://RoverTerramechanics.Examples.SteerableRoverTurn\">Examples.SteerableRoverTurn</a></td>
<td><code>FMUs.SteerableRover</code> from 0.5 m/s, 20 N&middot;m on every wheel, front wheels
steered 0.05 rad left, rear 0.05 rad right: a left turn</td><td>0-10 s, 10 ms</td></tr>
</table>
<p>Measured with rumoca 0.10.2 on our 2-core machine: SingleWheelStep simulates in about 0.1 s,
RoverOpenLoop in about 0.7 s. During the acceleration of RoverOpenLoop the front loads fall from
424 N to about 295 N and the rear rise to about 553 N (pitch about 0.0043 rad).</p>
</html>"));
end Examples;
