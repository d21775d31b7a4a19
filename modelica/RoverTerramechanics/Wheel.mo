within RoverTerramechanics;
model Wheel "One terramechanics wheel for co-simulation: inputs tau, W, v_hub (the rover cut at the wheel hub)"
  extends RoverTerramechanics.Components.RigidWheel;
  annotation (
    experiment(StartTime=0, StopTime=10, Interval=0.01),
    Documentation(info="<html>
<p>The wheel side of the rover cut at the hubs (FMU <code>Wheel</code>). Inputs: drive torque
<code>tau</code> [N&middot;m], load <code>W</code> [N] and hub speed <code>v_hub</code> [m/s]
from <code>RoverBody</code>. Outputs: <code>Fx</code>, <code>Fz</code> [N], <code>Tx</code>
[N&middot;m], <code>slip</code>, <code>sinkage</code> [m], <code>omega</code> [rad/s]; Fx goes
back to RoverBody. Physics: <code>Components.RigidWheel</code>.</p>
</html>"));
end Wheel;
