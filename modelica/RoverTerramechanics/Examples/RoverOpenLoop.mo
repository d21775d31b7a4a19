within RoverTerramechanics.Examples;
model RoverOpenLoop "Open-loop run of the monolithic rover: all six wheels driven by openLoopTorque"
  RoverTerramechanics.FMUs.Rover rover "Rover";
equation
  for i in 1:6 loop
    rover.tau[i] = openLoopTorque(time);
    rover.rutDepth[i] = 0 "virgin soil";
  end for;
  annotation (
    experiment(StartTime=0, StopTime=6, Interval=0.01, Tolerance=1e-8),
    Documentation(info="<html>
<p>From rest, the wheels accelerate the rover to about 1 m/s and then cruise. While
accelerating the body pitches nose up: Fz of limb 1 falls and Fz of limb 3 rises (paper Fig.
10c).</p>
</html>"));
end RoverOpenLoop;
