within RoverTerramechanics.Interfaces;
partial model BodyHubs "The body side of the cut at the six wheel hubs of the pitch-plane rover: hub forces and drive torques in; wheel loads and hub speeds out"
  parameter Integer nWheels = 6 "Number of wheels (structural: an FMU is built for one value; wheels 1..nWheels/2 on the left from front to rear, the others mirror them on the right)";
  input Real Fx[nWheels](each unit="N") "Longitudinal force of each wheel on its hub";
  input Real tau[nWheels](each unit="N.m") "Drive torque of each wheel motor; its reaction acts on the body";
  output Real W[nWheels](each unit="N") "Wheel loads: the limb forces pressing each wheel into the soil";
  output Real v_hub[nWheels](each unit="m/s") "Forward speed of each wheel hub";
  annotation (Documentation(info="<html>
<p>What the body of the pitch-plane rover exchanges with its six wheels (limb 1 front, 2 middle,
3 rear of one side, 4-6 mirror them). Inputs: the hub forces <code>Fx[i]</code> [N] of the
wheels and their drive torques <code>tau[i]</code> [N&middot;m] (the same signals the wheels get:
the motors' reaction pitches the body, so without them the cut rover would not be the monolithic
one). Outputs: the wheel loads <code>W[i]</code> [N] and hub speeds <code>v_hub[i]</code>
[m/s], the inputs of <code>WheelHub</code>.</p>
<p>Physics: <code>Components.Chassis</code>; FMU: <code>FMUs.RoverBody</code>.</p>
</html>"));
end BodyHubs;
