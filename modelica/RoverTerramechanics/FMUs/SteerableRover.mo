within RoverTerramechanics.FMUs;
model SteerableRover "ATHLETE-like six-limb rover moving in the plane, every wheel driven and steered, with six terramechanics wheels (monolithic)"
  extends RoverTerramechanics.Interfaces.GroundContacts(final nWheels=2*rover.nAxles);
  parameter RoverTerramechanics.Parameters.SoilParameters soil "Soil (Table 2): the soil under a wheel where its soilShare = 0";
  parameter RoverTerramechanics.Parameters.SoilParameters soilB "Second soil: the soil under a wheel where its soilShare = 1 (default Table 2's)";
  parameter RoverTerramechanics.Parameters.WheelParameters wheel "Wheel (Table 2)";
  parameter RoverTerramechanics.Parameters.RoverParameters rover "Rover mass, inertia, geometry and limbs";
  parameter RoverTerramechanics.Parameters.TerrainParameters terrain "Ground plane: slope and downhill direction (default level)";
  parameter Integer nNodes = 10 "Gauss-Legendre nodes per piece of the contact patch";
  parameter Integer nIterations = 12 "Bound on the force evaluations of the sinkage solve";
  parameter Real vEps(unit="m/s") = 1e-3 "Regularising speed of the slip ratio";
  parameter Real vHold(unit="m/s") = 1e-3 "Transition speed: below it the steady forces blend into the static regime";
  parameter Real vStick(unit="m/s") = 1e-4 "Slip speed at which the static shear reaches tanh(1) of its limit";
  input Real tau[nWheels](each unit="N.m") "Drive torque of each wheel";
  input Real steer[nWheels](each unit="rad") "Steering angle of each wheel, positive to the left";
  input Real soilShare[nWheels](each unit="1", each min=0, each max=1, each start=0) "Share of the second soil (soilB) in the soil under each wheel, from a soil map (0: soil)";
  input Real rutDepth[nWheels](each unit="m", each min=0, each start=0) "Depth of the rut a previous wheel left under each wheel, from a rut participant (0: virgin soil)";
  output Real x(unit="m") "Position of the centre of gravity along the ground's x axis (world x on level ground)";
  output Real y(unit="m") "Position of the centre of gravity along the ground's y axis (world y on level ground)";
  output Real yaw(unit="rad") "Heading against the ground's x axis, positive to the left";
  output Real v(unit="m/s") "Forward velocity of the centre of gravity, along the heading";
  output Real vy(unit="m/s") "Lateral velocity of the centre of gravity, to the left";
  output Real yawRate(unit="rad/s") "Yaw rate";
  output Real pitch(unit="rad") "Pitch angle, nose up positive";
  output Real roll(unit="rad") "Roll angle, left side up positive";
  output Real Fz[nWheels](each unit="N") "Vertical force of each wheel, Eq. (11) (= its load)";
  output Real Fx[nWheels](each unit="N") "Longitudinal force of each wheel, along its heading";
  output Real Fy[nWheels](each unit="N") "Lateral force of each wheel, to its left";
  output Real Tx[nWheels](each unit="N.m") "Resistance torque of each wheel, Eq. (13)";
  output Real slip[nWheels](each unit="1") "Slip ratio of each wheel, Eq. (4)";
  output Real slipAngle[nWheels](each unit="rad") "Slip angle of each wheel's hub velocity";
  output Real sinkage[nWheels](each unit="m") "Sinkage of each wheel";
  output Real omega[nWheels](each unit="rad/s") "Angular velocity of each wheel";
  RoverTerramechanics.Components.SteerableChassis body(rover=rover, terrain=terrain) "Body and limbs";
  RoverTerramechanics.Components.RigidWheel wheels[nWheels](each soil=soil, each soilB=soilB, each wheel=wheel, each nNodes=nNodes, each nIterations=nIterations, each vEps=vEps, each vHold=vHold, each vStick=vStick) "Wheels 1-6";
equation
  for i in 1:nWheels loop
    wheels[i].tau = tau[i];
    wheels[i].W = body.W[i];
    wheels[i].v_hub = body.v_hub[i];
    wheels[i].v_lat = body.v_lat[i];
    wheels[i].soilShare = soilShare[i];
    wheels[i].rutDepth = rutDepth[i];
    body.Fx[i] = wheels[i].Fx;
    body.Fy[i] = wheels[i].Fy;
    body.tau[i] = tau[i];
    body.steer[i] = steer[i];
    body.groundHeight[i] = groundHeight[i];
    body.groundHeightRate[i] = groundHeightRate[i];
    body.groundGradientAlong[i] = groundGradientAlong[i];
    body.groundGradientLateral[i] = groundGradientLateral[i];
    Fz[i] = wheels[i].Fz;
    Fx[i] = wheels[i].Fx;
    Fy[i] = wheels[i].Fy;
    Tx[i] = wheels[i].Tx;
    slip[i] = wheels[i].slip;
    slipAngle[i] = wheels[i].slipAngle;
    sinkage[i] = wheels[i].sinkage;
    omega[i] = wheels[i].omega;
  end for;
  x = body.x;
  y = body.y;
  yaw = body.yaw;
  v = body.v;
  vy = body.vy;
  yawRate = body.yawRate;
  pitch = body.pitch;
  roll = body.roll;
  annotation (
    experiment(StartTime=0, StopTime=10, Interval=0.01),
    Documentation(info="<html>
<p>The paper's future work: the rover of <code>Rover</code> free in the plane with every wheel
steered (ATHLETE steers every wheel). Body: <code>Components.SteerableChassis</code> (x, y, yaw;
heave, pitch, roll on three compliant limbs per side); wheels: <code>Components.RigidWheel</code>,
each fed its hub's velocity in its own frame, so it gets a slip and a slip angle and gives Fx,
Fy (Ishigami et al. 2007) and Fz. Inputs <code>tau[1..6]</code> and <code>steer[1..6]</code>;
limbs 1-3 front, middle, rear on the left, 4-6 on the right. With every steering angle zero it
is <code>Rover</code> on level ground. The ground is the plane of <code>terrain</code>
(<code>Parameters.TerrainParameters</code>: slope and downhill direction; level by default):
the loads act along its normal and the wheels' frames lie in it. A height map over the plane comes
in hub by hub (<code>Interfaces.GroundContacts</code>: height, its rate, gradients; 0 by default)
from a terrain participant. The soil under each wheel is <code>soil</code>, or where its input
<code>soilShare[i]</code> (start 0) is above 0 a blend with <code>soilB</code>
(<code>Components.RigidWheel</code>), given wheel by wheel from a soil map by a soil
participant. The states <code>x</code>, <code>y</code>,
<code>yaw</code>, <code>v</code>, <code>vy</code>, <code>yawRate</code> and <code>omega[i]</code>
take start values, so a run can start in motion.</p>
</html>"));
end SteerableRover;
