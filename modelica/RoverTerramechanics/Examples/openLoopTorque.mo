within RoverTerramechanics.Examples;
function openLoopTorque "Smooth open-loop drive torque: accelerate, then cruise"
  input Real t(unit="s") "Time";
  input Real tauAccel(unit="N.m") = 40 "Torque while accelerating";
  input Real tauCruise(unit="N.m") = 9 "Torque while cruising (about the rolling resistance at 424 N)";
  input Real tSwitch(unit="s") = 3 "Time of the change from accelerating to cruising";
  input Real tBlend(unit="s") = 0.3 "Duration of the (tanh) change";
  output Real tau(unit="N.m") "Drive torque";
algorithm
  tau := tauCruise + (tauAccel - tauCruise)*0.5*(1 - tanh((t - tSwitch)/tBlend));
  annotation (Documentation(info="<html>
<p>&tau;(t) = &tau;<sub>cruise</sub> + (&tau;<sub>accel</sub> - &tau;<sub>cruise</sub>)(1 -
tanh((t - t<sub>switch</sub>)/t<sub>blend</sub>))/2: a smooth (event-free) profile. With the
defaults each wheel runs at about 10 % slip and the rover reaches about 1 m/s at 3 s, then
rolls on with the torque near the rolling resistance.</p>
</html>"));
end openLoopTorque;
