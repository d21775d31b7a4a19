within RoverTerramechanics.Interfaces;
partial model PitchPlaneRover "Inputs and outputs of the six-wheel rover in the pitch plane: drive torques in; body motion and per-wheel forces, slip, sinkage and spin out"
  parameter Integer nWheels = 6 "Number of wheels (structural: an FMU is built for one value; wheels 1..nWheels/2 on the left from front to rear, the others mirror them on the right)";
  input Real tau[nWheels](each unit="N.m") "Drive torque of each wheel";
  output Real x(unit="m") "Position of the centre of gravity";
  output Real v(unit="m/s") "Forward velocity of the centre of gravity";
  output Real pitch(unit="rad") "Pitch angle, nose up positive";
  output Real Fz[nWheels](each unit="N") "Vertical force of each wheel, Eq. (11) (= its load)";
  output Real Fx[nWheels](each unit="N") "Longitudinal force of each wheel, Eq. (12)";
  output Real Tx[nWheels](each unit="N.m") "Resistance torque of each wheel, Eq. (13)";
  output Real slip[nWheels](each unit="1") "Slip ratio of each wheel, Eq. (4)";
  output Real sinkage[nWheels](each unit="m") "Sinkage of each wheel";
  output Real omega[nWheels](each unit="rad/s") "Angular velocity of each wheel";
  annotation (Documentation(info="<html>
<p>The rover as its user sees it, whether it is one model (<code>FMUs.Rover</code>) or the body
and six wheels wired through the hub cut (<code>Examples.RoverReconnected</code>): inputs the
drive torques <code>tau[1..6]</code> [N&middot;m] (limb 1 front, 2 middle, 3 rear of one side,
4-6 mirror them); outputs the centre of gravity's position <code>x</code> [m] and velocity
<code>v</code> [m/s], the <code>pitch</code> [rad] (nose up positive) and per wheel
<code>Fz[i]</code> [N] (= its load), <code>Fx[i]</code> [N], <code>Tx[i]</code> [N&middot;m],
<code>slip[i]</code>, <code>sinkage[i]</code> [m] and <code>omega[i]</code> [rad/s]. Declared
once, so the two cannot drift apart.</p>
</html>"));
end PitchPlaneRover;
