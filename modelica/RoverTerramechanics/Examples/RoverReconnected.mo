within RoverTerramechanics.Examples;
model RoverReconnected "RoverBody and six Wheel models reconnected at the hubs: must behave as Rover (a check of the cut)"
  extends RoverTerramechanics.Interfaces.PitchPlaneRover;
  parameter RoverTerramechanics.Parameters.SoilParameters soil "Soil (Table 2)";
  parameter RoverTerramechanics.Parameters.WheelParameters wheel "Wheel (Table 2)";
  parameter RoverTerramechanics.Parameters.RoverParameters rover "Rover mass, geometry and limbs";
  parameter Integer nNodes = 10 "Gauss-Legendre nodes per piece of the contact patch";
  parameter Integer nIterations = 12 "Bound on the force evaluations of the sinkage solve";
  parameter Real slope(unit="rad") = 0 "Slope of the ground along x, positive uphill";
  parameter Real vEps(unit="m/s") = 1e-3 "Regularising speed of the slip ratio";
  parameter Real vHold(unit="m/s") = 1e-3 "Transition speed: below it the steady forces blend into the static regime";
  parameter Real vStick(unit="m/s") = 1e-4 "Slip speed at which the static shear reaches tanh(1) of its limit";
  RoverTerramechanics.FMUs.RoverBody body(rover=rover, slope=slope) "The body FMU's model";
  RoverTerramechanics.FMUs.Wheel wheel1(soil=soil, wheel=wheel, nNodes=nNodes, nIterations=nIterations, vEps=vEps, vHold=vHold, vStick=vStick);
  RoverTerramechanics.FMUs.Wheel wheel2(soil=soil, wheel=wheel, nNodes=nNodes, nIterations=nIterations, vEps=vEps, vHold=vHold, vStick=vStick);
  RoverTerramechanics.FMUs.Wheel wheel3(soil=soil, wheel=wheel, nNodes=nNodes, nIterations=nIterations, vEps=vEps, vHold=vHold, vStick=vStick);
  RoverTerramechanics.FMUs.Wheel wheel4(soil=soil, wheel=wheel, nNodes=nNodes, nIterations=nIterations, vEps=vEps, vHold=vHold, vStick=vStick);
  RoverTerramechanics.FMUs.Wheel wheel5(soil=soil, wheel=wheel, nNodes=nNodes, nIterations=nIterations, vEps=vEps, vHold=vHold, vStick=vStick);
  RoverTerramechanics.FMUs.Wheel wheel6(soil=soil, wheel=wheel, nNodes=nNodes, nIterations=nIterations, vEps=vEps, vHold=vHold, vStick=vStick);
equation
  // The connections of the co-simulated rover, one wheel instance per FMU instance:
  // body.W[i] -> wheel_i.W, body.v_hub[i] -> wheel_i.v_hub, wheel_i.Fx -> body.Fx[i],
  // tau[i] -> wheel_i.tau and body.tau[i].
  wheel1.W = body.W[1]; wheel1.v_hub = body.v_hub[1]; wheel1.v_lat = 0; wheel1.soilShare = 0; wheel1.rutDepth = 0; body.Fx[1] = wheel1.Fx; wheel1.tau = tau[1]; body.tau[1] = tau[1];
  wheel2.W = body.W[2]; wheel2.v_hub = body.v_hub[2]; wheel2.v_lat = 0; wheel2.soilShare = 0; wheel2.rutDepth = 0; body.Fx[2] = wheel2.Fx; wheel2.tau = tau[2]; body.tau[2] = tau[2];
  wheel3.W = body.W[3]; wheel3.v_hub = body.v_hub[3]; wheel3.v_lat = 0; wheel3.soilShare = 0; wheel3.rutDepth = 0; body.Fx[3] = wheel3.Fx; wheel3.tau = tau[3]; body.tau[3] = tau[3];
  wheel4.W = body.W[4]; wheel4.v_hub = body.v_hub[4]; wheel4.v_lat = 0; wheel4.soilShare = 0; wheel4.rutDepth = 0; body.Fx[4] = wheel4.Fx; wheel4.tau = tau[4]; body.tau[4] = tau[4];
  wheel5.W = body.W[5]; wheel5.v_hub = body.v_hub[5]; wheel5.v_lat = 0; wheel5.soilShare = 0; wheel5.rutDepth = 0; body.Fx[5] = wheel5.Fx; wheel5.tau = tau[5]; body.tau[5] = tau[5];
  wheel6.W = body.W[6]; wheel6.v_hub = body.v_hub[6]; wheel6.v_lat = 0; wheel6.soilShare = 0; wheel6.rutDepth = 0; body.Fx[6] = wheel6.Fx; wheel6.tau = tau[6]; body.tau[6] = tau[6];
  Fz = {wheel1.Fz, wheel2.Fz, wheel3.Fz, wheel4.Fz, wheel5.Fz, wheel6.Fz};
  Fx = {wheel1.Fx, wheel2.Fx, wheel3.Fx, wheel4.Fx, wheel5.Fx, wheel6.Fx};
  Tx = {wheel1.Tx, wheel2.Tx, wheel3.Tx, wheel4.Tx, wheel5.Tx, wheel6.Tx};
  slip = {wheel1.slip, wheel2.slip, wheel3.slip, wheel4.slip, wheel5.slip, wheel6.slip};
  sinkage = {wheel1.sinkage, wheel2.sinkage, wheel3.sinkage, wheel4.sinkage, wheel5.sinkage, wheel6.sinkage};
  omega = {wheel1.omega, wheel2.omega, wheel3.omega, wheel4.omega, wheel5.omega, wheel6.omega};
  x = body.x;
  v = body.v;
  pitch = body.pitch;
  annotation (Documentation(info="<html>
<p>The co-simulated rover as one Modelica model: <code>RoverBody</code> and six separate
<code>Wheel</code> instances (as six Wheel FMU instances would be), wired only through their
public inputs and outputs. Same inputs and outputs as <code>FMUs.Rover</code>
(both extend <code>Interfaces.PitchPlaneRover</code>); the test suite checks that the two give
the same trajectories, i.e. that the cut interface loses nothing.</p>
</html>"));
end RoverReconnected;
