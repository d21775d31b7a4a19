within RoverTerramechanics.FMUs;
model RoverBody "Rover body alone for co-simulation: inputs Fx[i] and tau[i], outputs wheel loads W[i] and hub speeds v_hub[i]"
  extends RoverTerramechanics.Interfaces.BodyHubs(final nWheels=2*rover.nAxles);
  extends RoverTerramechanics.Components.Chassis;
  annotation (
    experiment(StartTime=0, StopTime=10, Interval=0.01),
    Documentation(info="<html>
<p>The body side of the rover cut at the wheel hubs (FMU <code>RoverBody</code>). Inputs: hub
forces <code>Fx[1..6]</code> [N] from the six <code>Wheel</code>s and the drive torques
<code>tau[1..6]</code> [N&middot;m] (the same signals the wheels get; their reaction pitches the
body). Outputs: <code>W[1..6]</code> [N] and <code>v_hub[1..6]</code> [m/s] to the wheels,
<code>x</code> [m], <code>v</code> [m/s], <code>z</code> [m], <code>pitch</code> [rad]. The
cut: <code>Interfaces.BodyHubs</code>; physics: <code>Components.Chassis</code>, which extends
the same interface.</p>
</html>"));
end RoverBody;
