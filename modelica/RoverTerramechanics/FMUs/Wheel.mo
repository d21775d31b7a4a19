within RoverTerramechanics.FMUs;
model Wheel "One terramechanics wheel for co-simulation: inputs tau, W, v_hub (the rover cut at the wheel hub)"
  extends RoverTerramechanics.Interfaces.WheelHub;
  extends RoverTerramechanics.Components.RigidWheel;
  annotation (
    experiment(StartTime=0, StopTime=10, Interval=0.01),
    Documentation(info="<html>
<p>The wheel side of the rover cut at the hubs (FMU <code>Wheel</code>), declared by
<code>Interfaces.WheelHub</code>. Inputs: drive torque <code>tau</code> [N&middot;m], load
<code>W</code> [N] and hub speed <code>v_hub</code> [m/s] from <code>RoverBody</code>, and the
optional lateral hub speed <code>v_lat</code> [m/s] (start 0) from
<code>SteerableRoverBody</code>. Outputs: <code>Fx</code>, <code>Fy</code>, <code>Fz</code> [N],
<code>Tx</code> [N&middot;m], <code>slip</code>, <code>slipAngle</code> [rad],
<code>sinkage</code> [m], <code>omega</code> [rad/s], <code>entryAngle</code> [rad]; Fx (and Fy)
go back to the body. Physics: <code>Components.RigidWheel</code>, which extends the same
interface (Modelica keeps one copy of the identical inherited declarations).</p>
</html>"));
end Wheel;
