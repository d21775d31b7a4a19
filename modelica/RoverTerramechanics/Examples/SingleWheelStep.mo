within RoverTerramechanics.Examples;
model SingleWheelStep "Torque step at t = 0 on the single-wheel test bed, wheel and carriage at rest"
  parameter Real W(unit="N") = 424 "Load on the wheel";
  parameter Real tauStep(unit="N.m") = 50 "Torque after the step";
  parameter Real slipAngle(unit="rad") = 0 "Angle of the carriage's track to the wheel plane";
  RoverTerramechanics.FMUs.SingleWheel testBed(W=W, slipAngle=slipAngle) "Test bed";
equation
  testBed.tau = tauStep;
  testBed.trackAngle = 0;
  testBed.rutDepth = 0;
  annotation (
    experiment(StartTime=0, StopTime=4, Interval=0.01, Tolerance=1e-8),
    Documentation(info="<html>
<p>The identification experiment of the paper's Sec. 3: the wheel and carriage start at rest
and the drive torque steps from 0 to <code>tauStep</code> at t = 0. The slip rises and settles
with a first-order-like response.</p>
</html>"));
end SingleWheelStep;
