within RoverTerramechanics.Interfaces;
partial model SteerableBodyHubs "The body side of the cut at the six steered wheel hubs of the steerable rover: hub forces, drive torques and steering angles in; wheel loads and hub velocities out"
  extends RoverTerramechanics.Interfaces.GroundContacts;
  input Real Fx[nWheels](each unit="N") "Longitudinal force of each wheel on its hub, along the wheel's heading";
  input Real Fy[nWheels](each unit="N") "Lateral force of each wheel on its hub, to the wheel's left";
  input Real tau[nWheels](each unit="N.m") "Drive torque of each wheel motor; its reaction acts on the body";
  input Real steer[nWheels](each unit="rad") "Steering angle of each wheel against the body's heading, positive to the left";
  output Real W[nWheels](each unit="N") "Wheel loads: the limb forces pressing each wheel into the soil";
  output Real v_hub[nWheels](each unit="m/s") "Hub speed along each wheel's heading";
  output Real v_lat[nWheels](each unit="m/s") "Hub speed to each wheel's left";
  annotation (Documentation(info="<html>
<p>What the body of the steerable rover exchanges with its six steered wheels (limbs 1-3 front,
middle, rear on the left, 4-6 on the right). Inputs: the wheels' forces in their own frames,
<code>Fx[i]</code> and <code>Fy[i]</code> [N], their drive torques <code>tau[i]</code>
[N&middot;m] and steering angles <code>steer[i]</code> [rad]. Outputs: the wheel loads
<code>W[i]</code> [N] and the hub velocities in the wheel frames, <code>v_hub[i]</code> and
<code>v_lat[i]</code> [m/s], the inputs of <code>WheelHub</code>.</p>
<p>Physics: <code>Components.SteerableChassis</code>; FMU: <code>FMUs.SteerableRoverBody</code>.</p>
</html>"));
end SteerableBodyHubs;
