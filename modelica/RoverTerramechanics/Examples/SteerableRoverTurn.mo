within RoverTerramechanics.Examples;
model SteerableRoverTurn "Open-loop turn of the steerable rover: 20 N.m on every wheel, front wheels steered left and rear wheels right, from 0.5 m/s"
  parameter Real tauDrive(unit="N.m") = 20 "Drive torque of every wheel";
  parameter Real steerFront(unit="rad") = 0.05 "Steering of the front wheels (the rear ones take the opposite)";
  RoverTerramechanics.FMUs.SteerableRover rover(body(v(start=0.5)), wheels(each omega(start=1.4084507042253522))) "Rover starting at 0.5 m/s, wheels rolling";
equation
  for i in 1:6 loop
    rover.tau[i] = tauDrive;
  end for;
  rover.steer = {steerFront, 0, -steerFront, steerFront, 0, -steerFront};
  rover.groundHeight = zeros(6);
  rover.groundHeightRate = zeros(6);
  rover.groundGradientAlong = zeros(6);
  rover.groundGradientLateral = zeros(6);
  rover.soilShare = zeros(6);
  rover.rutDepth = zeros(6);
  annotation (
    experiment(StartTime=0, StopTime=10, Interval=0.01, Tolerance=1e-6),
    Documentation(info="<html>
<p>The steerable rover (<code>SteerableRover</code>) turning left in open loop: every wheel
driven with <code>tauDrive</code>, front wheels steered <code>steerFront</code> to the left and
rear wheels as much to the right, starting at 0.5 m/s with the wheels rolling (omega = v/r). The
body yaws left, rolls to the outside of the turn (left side up) and loads the outer wheels; the
same system co-simulated is <code>steerable_rover_cosim.toml</code>. The ground is the plane of
<code>rover.terrain</code> (level by default) without a height map (the ground inputs 0), on one soil (<code>soilShare</code> 0).</p>
</html>"));
end SteerableRoverTurn;
