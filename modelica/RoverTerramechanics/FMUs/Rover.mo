within RoverTerramechanics.FMUs;
model Rover "ATHLETE-like six-limb rover in the pitch plane with six terramechanics wheels (monolithic)"
  extends RoverTerramechanics.Interfaces.PitchPlaneRover(final nWheels=2*rover.nAxles);
  parameter RoverTerramechanics.Parameters.SoilParameters soil "Soil (Table 2)";
  parameter RoverTerramechanics.Parameters.WheelParameters wheel "Wheel (Table 2)";
  parameter RoverTerramechanics.Parameters.RoverParameters rover "Rover mass, geometry and limbs";
  parameter Real slope(unit="rad") = 0 "Slope of the ground along x, positive uphill";
  parameter Integer nNodes = 10 "Gauss-Legendre nodes per piece of the contact patch";
  parameter Integer nIterations = 12 "Bound on the force evaluations of the sinkage solve";
  parameter Real vEps(unit="m/s") = 1e-3 "Regularising speed of the slip ratio";
  parameter Real vHold(unit="m/s") = 1e-3 "Transition speed: below it the steady forces blend into the static regime";
  parameter Real vStick(unit="m/s") = 1e-4 "Slip speed at which the static shear reaches tanh(1) of its limit";
  input Real rutDepth[nWheels](each unit="m", each min=0, each start=0) "Depth of the rut a previous wheel left under each wheel, from a rut participant (0: virgin soil)";
  RoverTerramechanics.Components.Chassis body(rover=rover, slope=slope) "Body and limbs";
  RoverTerramechanics.Components.RigidWheel wheels[nWheels](each soil=soil, each soilB=soil, each wheel=wheel, each nNodes=nNodes, each nIterations=nIterations, each vEps=vEps, each vHold=vHold, each vStick=vStick) "Wheels 1-6";
equation
  for i in 1:nWheels loop
    wheels[i].tau = tau[i];
    wheels[i].W = body.W[i];
    wheels[i].v_hub = body.v_hub[i];
    wheels[i].v_lat = 0 "pitch-plane rover: no sideways motion";
    wheels[i].soilShare = 0 "one soil under every wheel";
    wheels[i].rutDepth = rutDepth[i];
    body.Fx[i] = wheels[i].Fx;
    body.tau[i] = tau[i];
    Fz[i] = wheels[i].Fz;
    Fx[i] = wheels[i].Fx;
    Tx[i] = wheels[i].Tx;
    slip[i] = wheels[i].slip;
    sinkage[i] = wheels[i].sinkage;
    omega[i] = wheels[i].omega;
  end for;
  x = body.x;
  v = body.v;
  pitch = body.pitch;
  annotation (
    experiment(StartTime=0, StopTime=10, Interval=0.01),
    Documentation(info="<html>
<p>Paper Sec. 4: a 1570 kg rover under lunar gravity on six wheels. Body:
<code>Components.Chassis</code> (x, z, pitch; three compliant limbs per side, mirror-symmetric);
wheels: <code>Components.RigidWheel</code> (Eqs. 1-13) loaded by the limb forces. Inputs
<code>tau[1..6]</code>; limb 1 is the front, 3 the rear of one side, 4-6 mirror them.
Accelerating pitches the nose up: limb 1 unloads and limb 3 loads (paper Fig. 10c). Every
parameter the paper does not give is in <code>Parameters.RoverParameters</code> and
<code>Parameters.WheelParameters</code>. Parameter <code>slope</code> tilts the ground (positive
uphill); the states <code>x</code>, <code>v</code>, <code>pitch</code> and <code>omega[i]</code>
take start values, so a run can start in motion.</p>
</html>"));
end Rover;
