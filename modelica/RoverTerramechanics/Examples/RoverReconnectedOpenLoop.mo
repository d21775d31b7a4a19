within RoverTerramechanics.Examples;
model RoverReconnectedOpenLoop "The open-loop run of RoverOpenLoop on RoverBody + 6 Wheel reconnected"
  RoverTerramechanics.Examples.RoverReconnected rover "Reconnected rover";
equation
  for i in 1:6 loop
    rover.tau[i] = openLoopTorque(time);
  end for;
  annotation (
    experiment(StartTime=0, StopTime=6, Interval=0.01, Tolerance=1e-8),
    Documentation(info="<html>
<p>Same torques as <code>RoverOpenLoop</code>; the trajectories must be the same.</p>
</html>"));
end RoverReconnectedOpenLoop;
