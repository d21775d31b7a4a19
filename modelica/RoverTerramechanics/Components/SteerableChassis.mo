within RoverTerramechanics.Components;
model SteerableChassis "Rover body moving in the plane (x, y, yaw) with heave, pitch and roll on six compliant limbs, every wheel steered, cut at the wheel hubs"
  extends RoverTerramechanics.Interfaces.SteerableBodyHubs(final nWheels=2*rover.nAxles);
  parameter RoverTerramechanics.Parameters.RoverParameters rover "Rover mass, inertia, geometry and limbs";
  parameter RoverTerramechanics.Parameters.TerrainParameters terrain "Ground plane: slope and downhill direction (default level)";
  output Real x(unit="m", start=0, fixed=true) "Position of the centre of gravity along the ground's x axis (world x on level ground)";
  output Real y(unit="m", start=0, fixed=true) "Position of the centre of gravity along the ground's y axis (world y on level ground)";
  output Real yaw(unit="rad", start=0, fixed=true) "Heading of the body against the ground's x axis, about the ground's normal, positive to the left";
  output Real v(unit="m/s", start=0, fixed=true) "Forward velocity of the centre of gravity, along the heading";
  output Real vy(unit="m/s", start=0, fixed=true) "Lateral velocity of the centre of gravity, to the left of the heading";
  output Real yawRate(unit="rad/s", start=0, fixed=true) "Yaw rate";
  output Real z(unit="m", start=0, fixed=true) "Heave of the centre of gravity from static equilibrium";
  output Real pitch(unit="rad", start=0, fixed=true) "Pitch angle, nose up positive";
  output Real roll(unit="rad", start=0, fixed=true) "Roll angle, left side up positive";
  Real w(unit="m/s", start=0, fixed=true) "Heave velocity";
  Real q(unit="rad/s", start=0, fixed=true) "Pitch rate";
  Real p(unit="rad/s", start=0, fixed=true) "Roll rate";
  Real deflection[nWheels](each unit="m") "Limb compression";
  Real deflectionRate[nWheels](each unit="m/s") "Limb compression rate";
  Real yRolled[nWheels](each unit="m") "Hub position to the left of the centre of gravity after the roll";
  Real zRolled[nWheels](each unit="m") "Hub height relative to the centre of gravity after the roll";
  Real xHubWorld[nWheels](each unit="m") "Hub position ahead of the centre of gravity (heading frame)";
  Real zHubWorld[nWheels](each unit="m") "Hub height relative to the centre of gravity";
  Real vxHub[nWheels](each unit="m/s") "Hub velocity along the heading";
  Real vyHub[nWheels](each unit="m/s") "Hub velocity to the left of the heading";
  Real FxBody[nWheels](each unit="N") "Hub force along the heading";
  Real FyBody[nWheels](each unit="N") "Hub force to the left of the heading";
  Real FxHub[nWheels](each unit="N") "Force of the ground on each hub along the heading: FxBody and the load's component on the local gradient";
  Real FyHub[nWheels](each unit="N") "Force of the ground on each hub to the left of the heading: FyBody and the load's component on the local gradient";
  Real gAlong(unit="m/s2") "Gravity's component along the heading, in the ground plane (TerrainParameters)";
  Real gLateral(unit="m/s2") "Gravity's component to the left of the heading, in the ground plane (TerrainParameters)";
protected
  parameter Real gNormal(unit="m/s2") = rover.g*cos(terrain.slope) "Gravity's component into the ground, along its normal";
  parameter Real staticDeflection(unit="m") = rover.M*gNormal/(nWheels*rover.kLimb) "Limb compression at rest";
equation
  gAlong = rover.g*sin(terrain.slope)*cos(terrain.downhill - yaw);
  gLateral = rover.g*sin(terrain.slope)*sin(terrain.downhill - yaw);
  der(x) = v*cos(yaw) - vy*sin(yaw);
  der(y) = v*sin(yaw) + vy*cos(yaw);
  der(yaw) = yawRate;
  der(z) = w;
  der(pitch) = q;
  der(roll) = p;
  for j in 1:rover.nAxles loop
    yRolled[j] = rover.yLimb*cos(roll) + rover.hCoG*sin(roll) "limbs 1..nAxles: the left side";
    zRolled[j] = rover.yLimb*sin(roll) - rover.hCoG*cos(roll);
    xHubWorld[j] = rover.xLimb[j]*cos(pitch) - zRolled[j]*sin(pitch);
    zHubWorld[j] = rover.xLimb[j]*sin(pitch) + zRolled[j]*cos(pitch);
    yRolled[j + rover.nAxles] = (-rover.yLimb)*cos(roll) + rover.hCoG*sin(roll) "the right side mirrors the left";
    zRolled[j + rover.nAxles] = (-rover.yLimb)*sin(roll) - rover.hCoG*cos(roll);
    xHubWorld[j + rover.nAxles] = rover.xLimb[j]*cos(pitch) - zRolled[j + rover.nAxles]*sin(pitch);
    zHubWorld[j + rover.nAxles] = rover.xLimb[j]*sin(pitch) + zRolled[j + rover.nAxles]*cos(pitch);
  end for;
  for i in 1:nWheels loop
    deflection[i] = staticDeflection - z - (zHubWorld[i] + rover.hCoG) + groundHeight[i];
    deflectionRate[i] = -w - q*xHubWorld[i] - p*cos(pitch)*yRolled[i] + groundHeightRate[i];
    W[i] = noEvent(max(rover.kLimb*deflection[i] + rover.dLimb*deflectionRate[i], 0.0));
    vxHub[i] = v - q*zHubWorld[i] - p*sin(pitch)*yRolled[i] - yawRate*yRolled[i];
    vyHub[i] = vy - p*zRolled[i] + yawRate*xHubWorld[i];
    v_hub[i] = vxHub[i]*cos(steer[i]) + vyHub[i]*sin(steer[i]);
    v_lat[i] = vyHub[i]*cos(steer[i]) - vxHub[i]*sin(steer[i]);
    FxBody[i] = Fx[i]*cos(steer[i]) - Fy[i]*sin(steer[i]);
    FyBody[i] = Fx[i]*sin(steer[i]) + Fy[i]*cos(steer[i]);
    FxHub[i] = FxBody[i] - W[i]*groundGradientAlong[i];
    FyHub[i] = FyBody[i] - W[i]*groundGradientLateral[i];
  end for;
  rover.M*(der(v) - yawRate*vy) = sum(FxHub) + rover.M*gAlong;
  rover.M*(der(vy) + yawRate*v) = sum(FyHub) + rover.M*gLateral;
  rover.Izz*der(yawRate) = sum(xHubWorld[i]*FyHub[i] - yRolled[i]*FxHub[i] for i in 1:nWheels);
  rover.M*der(w) = sum(W) - rover.M*gNormal;
  rover.Iyy*der(q) = sum(xHubWorld[i]*W[i] - zHubWorld[i]*FxHub[i] + tau[i]*cos(steer[i]) for i in 1:nWheels);
  rover.Ixx*der(p) = sum(yRolled[i]*W[i] - zHubWorld[i]*FyHub[i] + tau[i]*sin(steer[i]) for i in 1:nWheels);
  assert(rover.M > 0, "rover.M: the mass must be > 0 kg");
  assert(rover.g > 0, "rover.g: the gravity must be > 0 m/s2");
  assert(rover.Iyy > 0, "rover.Iyy: the pitch inertia must be > 0 kg.m2");
  assert(rover.Ixx > 0, "rover.Ixx: the roll inertia must be > 0 kg.m2");
  assert(rover.Izz > 0, "rover.Izz: the yaw inertia must be > 0 kg.m2");
  assert(rover.yLimb > 0, "rover.yLimb: the half track width must be > 0 m");
  assert(rover.hCoG >= 0, "rover.hCoG: the centre of gravity must be at or above the hubs, hCoG >= 0 m");
  assert(terrain.slope >= 0 and terrain.slope < 1.5707963267948966, "terrain.slope: the inclination of the ground must be in [0, pi/2) rad");
  assert(abs(terrain.downhill) < 1e6, "terrain.downhill: the downhill direction must be a finite angle in rad");
  assert(rover.kLimb > 0, "rover.kLimb: the limb stiffness must be > 0 N/m");
  assert(rover.dLimb >= 0, "rover.dLimb: the limb damping must be >= 0 N.s/m");
  annotation (Documentation(info="<html>
<p>The rover body of <code>Chassis</code> set free in the plane: a rigid body of mass M and
inertias Ixx, Iyy, Izz whose centre of gravity moves in x, y with heading yaw, and which heaves,
pitches and rolls on six vertical spring-damper limbs (limbs 1-3 front, middle, rear on the left
at y = +yLimb, 4-6 on the right). Each wheel is steered by <code>steer[i]</code> about its
vertical axis. In the heading frame (x forward, y left, z up), with the hub at
p<sub>i</sub> = R<sub>pitch</sub> R<sub>roll</sub> (x<sub>i</sub>, y<sub>i</sub>, -h<sub>CoG</sub>):</p>
<ul>
<li>M (dv/dt - r v<sub>y</sub>) = &Sigma; F<sub>x,i</sub><sup>hub</sup> + M g<sub>x</sub>,
M (dv<sub>y</sub>/dt + r v) = &Sigma; F<sub>y,i</sub><sup>hub</sup> + M g<sub>y</sub> (F<sup>hub</sup>: F<sup>body</sup> and the
load's component on a height map, below), with the wheel-frame
forces turned by the steering: F<sup>body</sup> = R(steer) (F<sub>x</sub>, F<sub>y</sub>), and
gravity's components in the ground plane g<sub>x</sub> = g sin &theta; cos(&psi;<sub>d</sub> - yaw),
g<sub>y</sub> = g sin &theta; sin(&psi;<sub>d</sub> - yaw) (<code>Parameters.TerrainParameters</code>:
slope &theta;, downhill direction &psi;<sub>d</sub>);</li>
<li>Izz dr/dt = &Sigma; (p<sub>x,i</sub> F<sub>y,i</sub><sup>body</sup> - p<sub>y,i</sub>
F<sub>x,i</sub><sup>body</sup>);</li>
<li>M dw/dt = &Sigma; W<sub>i</sub> - M g cos &theta;; Iyy dq/dt = &Sigma; (p<sub>x,i</sub> W<sub>i</sub> -
p<sub>z,i</sub> F<sub>x,i</sub><sup>body</sup> + &tau;<sub>i</sub> cos steer<sub>i</sub>);
Ixx dp/dt = &Sigma; (p<sub>y,i</sub> W<sub>i</sub> - p<sub>z,i</sub> F<sub>y,i</sub><sup>body</sup> +
&tau;<sub>i</sub> sin steer<sub>i</sub>): the loads, the hub forces below the centre of gravity
and the reaction of the wheel motors about their steered axles;</li>
<li>hub velocity = body velocity + rates &times; p<sub>i</sub>, given to each wheel in its own
frame (<code>v_hub</code> along, <code>v_lat</code> to its left), which sets its slip and slip
angle.</li>
</ul>
<p>The ground is the plane of <code>terrain</code>: x, y, yaw are measured in it, the limbs and
the loads W<sub>i</sub> act along its normal, the wheel frames (slip, slip angle) lie in it, and
heave, pitch and roll are relative to it; gravity acts at the centre of gravity, so it has no
moment about it: on a side slope the wheels' lateral forces, acting at the hubs h<sub>CoG</sub>
below, roll the body and load the downhill wheels. On level ground (slope 0) the gravity terms
are exactly 0 and g cos 0 = g: the equations and their arithmetic are those of the level rover.</p>
<p>A height map over the plane comes in hub by hub (<code>Interfaces.GroundContacts</code>, all 0
on the plane): the ground's height h<sub>i</sub> under hub i compresses its limb
(deflection + h<sub>i</sub>, rate + dh<sub>i</sub>/dt), and the load, normal to the local ground
of gradients s<sub>x,i</sub>, s<sub>y,i</sub> against the plane, pushes the hub by
-W<sub>i</sub> (s<sub>x,i</sub>, s<sub>y,i</sub>) along and across the heading
(F<sub>hub</sub> = F<sup>body</sup> - W<sub>i</sub> s<sub>i</sub>, to first order in the
gradients: a local slope of 0.2 is 11&deg;, where the first order is within 2 %). The wheels' slip and
slip angle stay in the plane's frame (to the same order). With the inputs 0 the terms are exactly 0.</p>
<p>Pitch and roll stay small (a few degrees): their rates are taken as body rates and the
gyroscopic coupling of yaw with pitch and roll is neglected. Turning and braking move the loads:
a lateral acceleration rolls the body and loads the outer limbs. With every steering angle
zero and no lateral force the equations are <code>Chassis</code>'s on level ground. Parameters:
<code>Parameters.RoverParameters</code>.</p>
</html>"));
end SteerableChassis;
