within RoverTerramechanics.FMUs;
model SteerableRoverBody "Steerable rover body alone for co-simulation: inputs Fx[i], Fy[i], tau[i], steer[i]; outputs wheel loads W[i] and hub velocities v_hub[i], v_lat[i]"
  extends RoverTerramechanics.Interfaces.SteerableBodyHubs(final nWheels=2*rover.nAxles);
  extends RoverTerramechanics.Components.SteerableChassis;
  annotation (
    experiment(StartTime=0, StopTime=10, Interval=0.01),
    Documentation(info="<html>
<p>The body side of the steerable rover cut at the wheel hubs (FMU
<code>SteerableRoverBody</code>). Inputs: hub forces <code>Fx[1..6]</code>,
<code>Fy[1..6]</code> [N] from the six <code>Wheel</code>s (in their frames), drive torques
<code>tau[1..6]</code> [N&middot;m] and steering angles <code>steer[1..6]</code> [rad]. Outputs:
<code>W[1..6]</code> [N], <code>v_hub[1..6]</code> and <code>v_lat[1..6]</code> [m/s] to the
wheels; the body's pose and rates. The cut: <code>Interfaces.SteerableBodyHubs</code>; physics:
<code>Components.SteerableChassis</code>, which extends the same interface.</p>
</html>"));
end SteerableRoverBody;
