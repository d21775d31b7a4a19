within RoverTerramechanics.UsersGuide;
class Models "Models: inputs, outputs, states and parameters of every FMU model; the parameter records"
  annotation (Documentation(info="<html>
<p>The classes of <code>FMUs</code>, each exported as the FMU of its name (<code>FMUs.Wheel</code>
as <code>Wheel.fmu</code>) with these variables under these names, and
<code>Examples.RoverReconnected</code>. Parameters <code>nNodes</code> (10),
<code>nIterations</code> (12), <code>vEps</code> [m/s] (1e-3), <code>vHold</code> [m/s] (1e-3)
and <code>vStick</code> [m/s] (1e-4) of the wheels:
<a href=\"modelica://RoverTerramechanics.UsersGuide.Physics\">Physics</a> and
<a href=\"modelica://RoverTerramechanics.UsersGuide.ParametersNotInPaper\">ParametersNotInPaper</a>.</p>

<h4>SingleWheel</h4>
<p><a href=\"modelica://RoverTerramechanics.FMUs.SingleWheel\">FMUs.SingleWheel</a>: the
single-wheel test bed. One wheel carrying the carriage weight <code>W</code> pushes a carriage
of mass W/g that moves freely along the ground, (W/g)&middot;dv/dt = Fx - W&middot;sin(slope),
with the load W&middot;cos(slope) normal to the ground on the wheel.</p>
<ul>
<li>inputs: <code>tau</code> [N&middot;m] drive torque; <code>trackAngle</code> [rad] (optional,
start 0) turns the carriage's track during a run, added to <code>slipAngle</code>;
<code>rutDepth</code> [m] (optional, start 0) the rut a previous pass left: repeated passes of the
test bed (multi-pass)</li>
<li>outputs: <code>Fx</code> [N], <code>Fz</code> [N], <code>Tx</code> [N&middot;m],
<code>Fy</code> [N] (lateral, wheel frame), <code>slip</code> [1], <code>sinkage</code> [m],
<code>omega</code> [rad/s], <code>entryAngle</code> [rad] (signed with the direction of travel),
<code>beta</code> [rad] (slip angle = slipAngle + trackAngle), <code>v</code> [m/s] (carriage
speed), <code>x</code> [m] (carriage position)</li>
<li>states with start values (a run can start in motion): <code>x</code>, <code>v</code>,
<code>omega</code></li>
<li>parameters: <code>W</code> [N] = 424, <code>g</code> [m/s<sup>2</sup>] = 1.62,
<code>slope</code> [rad] = 0 (positive uphill), <code>slipAngle</code> [rad] = 0 (the wheel set
at an angle to the carriage's track, as on Ishigami's test bed: the hub moves at v&middot;cos
along the wheel and v&middot;sin to its left), <code>soil</code> (SoilParameters),
<code>wheel</code> (WheelParameters), <code>nNodes</code> = 10, <code>nIterations</code> = 12,
<code>vEps</code> [m/s] = 1e-3, <code>vHold</code> [m/s] = 1e-3, <code>vStick</code> [m/s] =
1e-4</li>
<li>experiment: 10 s (the FMU's DefaultExperiment)</li>
</ul>

<h4>Rover</h4>
<p><a href=\"modelica://RoverTerramechanics.FMUs.Rover\">FMUs.Rover</a>: the six-limb rover,
monolithic: <code>Components.Chassis</code> plus six <code>Components.RigidWheel</code>s loaded
by the limb forces. Inputs and outputs: <code>Interfaces.PitchPlaneRover</code>.</p>
<ul>
<li>inputs: <code>tau[1..6]</code> [N&middot;m]; limb 1 front, 2 middle, 3 rear of one side,
4-6 mirror them; <code>rutDepth[1..6]</code> [m]: the depth of the rut a previous wheel left under each wheel, from a rut participant (multi-pass; optional, start 0: virgin soil)</li>
<li>outputs: <code>x</code> [m], <code>v</code> [m/s], <code>pitch</code> [rad] (nose up
positive), and per wheel <code>Fz[i]</code> [N] (= its load), <code>Fx[i]</code> [N],
<code>Tx[i]</code> [N&middot;m], <code>slip[i]</code> [1], <code>sinkage[i]</code> [m],
<code>omega[i]</code> [rad/s]</li>
<li>states with start values: <code>x</code>, <code>v</code>, <code>pitch</code>,
<code>omega[i]</code>, and <code>body.z</code>, <code>body.w</code>, <code>body.q</code></li>
<li>parameters: <code>soil</code>, <code>wheel</code>, <code>rover</code> (RoverParameters),
<code>slope</code> [rad] = 0, <code>nNodes</code>, <code>nIterations</code>, <code>vEps</code>,
<code>vHold</code>, <code>vStick</code>, <code>nWheels</code> = 2 <code>rover.nAxles</code> (the number of wheels, six; structural: an FMU is built for one count, rover-cosim builds others on first use)</li>
<li>experiment: 10 s</li>
</ul>

<h4>RoverBody</h4>
<p><a href=\"modelica://RoverTerramechanics.FMUs.RoverBody\">FMUs.RoverBody</a>: the rover body
cut at the wheel hubs, for co-simulation (the body side of the cut:
<code>Interfaces.BodyHubs</code>; physics: <code>Components.Chassis</code>).</p>
<ul>
<li>inputs: <code>Fx[1..6]</code> [N] hub forces from the wheels, <code>tau[1..6]</code>
[N&middot;m] the drive torques (their reaction on the body pitches it; the same signals go to the
wheels)</li>
<li>outputs: <code>W[1..6]</code> [N] wheel loads, <code>v_hub[1..6]</code> [m/s] hub speeds,
<code>x</code> [m], <code>v</code> [m/s], <code>z</code> [m] (heave from static equilibrium),
<code>pitch</code> [rad]; internal states <code>w</code> [m/s] (heave rate), <code>q</code>
[rad/s] (pitch rate)</li>
<li>parameters: <code>rover</code> (RoverParameters), <code>slope</code> [rad] = 0, <code>nWheels</code> = 2 <code>rover.nAxles</code> (the number of wheels, six; structural: an FMU is built for one count, rover-cosim builds others on first use)</li>
</ul>
<p>The drive torques are inputs of the body as well as of the wheels: without them the body would
miss the motors' reaction torque and the cut rover would not be the monolithic one.</p>

<h4>Wheel</h4>
<p><a href=\"modelica://RoverTerramechanics.FMUs.Wheel\">FMUs.Wheel</a>: one wheel for
co-simulation (the wheel side of the cut: <code>Interfaces.WheelHub</code>; physics:
<code>Components.RigidWheel</code>).</p>
<ul>
<li>inputs: <code>tau</code> [N&middot;m], <code>W</code> [N] load, <code>v_hub</code> [m/s] hub
speed, <code>v_lat</code> [m/s] the hub's speed to the wheel's left (start 0, optional: a system
may leave it unconnected), <code>soilShare</code> [1] the share of the second soil under the wheel
(start 0, optional: from a soil map), <code>rutDepth</code> [m] the depth of the rut a previous wheel
left under it (start 0, optional: from a rut participant; multi-pass)</li>
<li>outputs: <code>Fx</code> [N], <code>Fz</code> [N], <code>Tx</code> [N&middot;m],
<code>Fy</code> [N], <code>slipAngle</code> [rad], <code>slip</code> [1], <code>sinkage</code>
[m], <code>omega</code> [rad/s] (a state with a start value), <code>entryAngle</code> [rad]</li>
<li>parameters: <code>soil</code>, <code>soilB</code> (the second soil), <code>wheel</code>, <code>nNodes</code>,
<code>nIterations</code>, <code>vEps</code>, <code>vHold</code>, <code>vStick</code></li>
</ul>

<h4>SteerableRover</h4>
<p><a href=\"modelica://RoverTerramechanics.FMUs.SteerableRover\">FMUs.SteerableRover</a>: the
rover free in the plane, every wheel driven and steered (the paper's future work):
<code>Components.SteerableChassis</code> plus six <code>Components.RigidWheel</code>s, each fed
its hub's velocity in its own frame (<code>v_hub</code> along, <code>v_lat</code> to its left),
so each has a slip and a slip angle.</p>
<ul>
<li>inputs: <code>tau[1..6]</code> [N&middot;m], <code>steer[1..6]</code> [rad] steering angle
against the heading, positive to the left; <code>groundHeight[1..6]</code> [m], <code>groundHeightRate[1..6]</code> [m/s],
<code>groundGradientAlong[1..6]</code>, <code>groundGradientLateral[1..6]</code> [1]: a height map
over the ground plane hub by hub (<code>Interfaces.GroundContacts</code>; optional, start 0: the
plane itself); <code>soilShare[1..6]</code> [1]: the share of the second soil under each wheel
(optional, start 0: <code>soil</code> everywhere); <code>rutDepth[1..6]</code> [m]: the depth of the rut a previous wheel left under each wheel, from a rut participant (multi-pass; optional, start 0: virgin soil)</li>
<li>outputs: <code>x</code>, <code>y</code> [m], <code>yaw</code> [rad], <code>v</code>,
<code>vy</code> [m/s] (CoG velocity along and to the left of the heading), <code>yawRate</code>
[rad/s], <code>pitch</code>, <code>roll</code> [rad] (roll positive: left side up), per wheel
<code>Fx</code>, <code>Fy</code>, <code>Fz</code> [N], <code>Tx</code> [N&middot;m],
<code>slip</code> [1], <code>slipAngle</code> [rad], <code>sinkage</code> [m], <code>omega</code>
[rad/s]</li>
<li>states with start values (a run can start in motion): <code>body.x</code>,
<code>body.y</code>, <code>body.yaw</code>, <code>body.v</code>, <code>body.vy</code>,
<code>body.yawRate</code>, heave/pitch/roll and their rates, <code>wheels[i].omega</code></li>
<li>parameters: <code>soil</code>, <code>soilB</code> (the second soil), <code>wheel</code>, <code>rover</code> (RoverParameters, with
<code>yLimb</code>, <code>Ixx</code>, <code>Izz</code>), <code>terrain</code> (TerrainParameters:
<code>slope</code>, <code>downhill</code> [rad]; level by default), <code>nNodes</code>,
<code>nIterations</code>, <code>vEps</code>, <code>vHold</code>, <code>vStick</code>, <code>nWheels</code> = 2 <code>rover.nAxles</code> (the number of wheels, six; structural: an FMU is built for one count, rover-cosim builds others on first use)</li>
<li>limbs 1-3 front, middle, rear on the left (y = +yLimb), 4-6 on the right; the ground is the
plane of <code>terrain</code> (x, y, yaw measured in it) with an optional height map over it</li>
<li>with every <code>steer[i]</code> = 0 it is <code>Rover</code> on level ground (tests: equal to
rounding)</li>
<li>experiment: 10 s</li>
</ul>

<h4>SteerableRoverBody</h4>
<p><a href=\"modelica://RoverTerramechanics.FMUs.SteerableRoverBody\">FMUs.SteerableRoverBody</a>:
<code>Components.SteerableChassis</code> alone, for co-simulation with six <code>Wheel</code>s
(the body side of the cut: <code>Interfaces.SteerableBodyHubs</code>). Wired with the
<code>Wheel</code>s by the shipped <code>orchestrator/systems/steerable_rover_cosim.toml</code>.</p>
<ul>
<li>inputs: <code>Fx[1..6]</code>, <code>Fy[1..6]</code> [N] (wheel frames),
<code>tau[1..6]</code> [N&middot;m], <code>steer[1..6]</code> [rad]; <code>groundHeight[1..6]</code> [m], <code>groundHeightRate[1..6]</code> [m/s],
<code>groundGradientAlong[1..6]</code>, <code>groundGradientLateral[1..6]</code> [1]: a height map
over the ground plane hub by hub (<code>Interfaces.GroundContacts</code>; optional, start 0: the
plane itself); <code>soilShare[1..6]</code> [1]: the share of the second soil under each wheel
(optional, start 0: <code>soil</code> everywhere)</li>
<li>outputs: <code>W[1..6]</code> [N], <code>v_hub[1..6]</code>, <code>v_lat[1..6]</code> [m/s]
to the wheels; the body's pose and rates <code>x</code>, <code>y</code> [m], <code>yaw</code>
[rad], <code>v</code>, <code>vy</code> [m/s], <code>yawRate</code> [rad/s], <code>z</code> [m]
(heave from static equilibrium), <code>pitch</code>, <code>roll</code> [rad]; internal states
<code>w</code> [m/s] (heave rate), <code>q</code> [rad/s] (pitch rate), <code>p</code> [rad/s]
(roll rate)</li>
<li>parameters: <code>rover</code> (RoverParameters), <code>terrain</code>
(TerrainParameters), <code>nWheels</code> = 2 <code>rover.nAxles</code> (the number of wheels, six; structural: an FMU is built for one count, rover-cosim builds others on first use)</li>
</ul>

<h4>LegWheelRover</h4>
<p><a href=\"modelica://RoverTerramechanics.FMUs.LegWheelRover\">FMUs.LegWheelRover</a>: the paper's
plant (Sec. 2.1, Fig. 1), a leg-wheel robot with six joints per limb after NASA/JPL's ATHLETE:
<code>Components.LegWheelChassis</code> (the body on six limbs of six position-servoed joints,
<code>Components.Limb</code> the kinematics) with six <code>Components.RigidWheel</code>s. The
limb's joints (Wilcox et al. 2007 give six rotary joints per limb; the two ankle axes are our
reading): hip yaw about the body's z axis; hip, knee and ankle pitch about the limb's horizontal
axis; ankle steer about the ankle link; ankle roll normal to the link and the axle. Each joint's
servo has a stiffness, a damping and a torque limit; the limb's compliance along the ground's
normal carries the wheel's load (the load comes out of the limb, the sinkage is not fed back).</p>
<ul>
<li>inputs: the 36 joint set-points <code>hipYaw</code>, <code>hipPitch</code>, <code>kneePitch</code>, <code>anklePitch</code>, <code>ankleSteer</code>, <code>ankleRoll</code> [rad], six each (limbs 1-3 front, middle, rear on the left, 4-6 on the right; start: the paper's posture, hubs at x = 1.5, 0, -1.5 m, y = &plusmn;1.5 m, 1.0 m below the centre of gravity); their rates <code>hipYawRate</code>, <code>hipPitchRate</code>, <code>kneePitchRate</code>, <code>anklePitchRate</code>, <code>ankleSteerRate</code>, <code>ankleRollRate</code> [rad/s] (optional, start 0: the hubs move against the body at J q&#775;<sub>set</sub>, and the wheels roll or slide over it); <code>tau[1..6]</code> [N&middot;m] the drive torques; <code>groundHeight[1..6]</code> [m], <code>groundHeightRate[1..6]</code> [m/s], <code>groundGradientAlong[1..6]</code>, <code>groundGradientLateral[1..6]</code> [1]: the ground under each hub (<code>Interfaces.GroundContacts</code>; optional, start 0); <code>soilShare[1..6]</code>
[1] the share of the second soil under each wheel (optional, start 0); <code>rutDepth[1..6]</code> [m]: the depth of the rut a previous wheel left under each wheel, from a rut participant (multi-pass; optional, start 0: virgin soil)</li>
<li>outputs: joint angles <code>hipYawAngle</code>, <code>hipPitchAngle</code>, <code>kneePitchAngle</code>, <code>anklePitchAngle</code>, <code>ankleSteerAngle</code>, <code>ankleRollAngle</code> [rad] (the set-points deflected by the load), servo torques <code>hipYawTorque</code>, <code>hipPitchTorque</code>, <code>kneePitchTorque</code>, <code>anklePitchTorque</code>, <code>ankleSteerTorque</code>, <code>ankleRollTorque</code> [N&middot;m], hub positions <code>hubX</code>, <code>hubY</code>, <code>hubZ</code> [m] (body frame, from the joint angles), wheel headings <code>steer</code> [rad] (from the ankle steer joints); per wheel <code>Fz</code>, <code>Fx</code>, <code>Fy</code> [N],
<code>Tx</code> [N&middot;m], <code>slip</code> [1], <code>slipAngle</code> [rad],
<code>sinkage</code> [m], <code>omega</code> [rad/s]; the body's pose and velocity <code>x</code>, <code>y</code>, <code>z</code> [m] (z: the centre of gravity over the ground plane), <code>yaw</code>, <code>pitch</code>, <code>roll</code> [rad], <code>v</code>, <code>vy</code> [m/s], <code>yawRate</code> [rad/s], <code>heaveRate</code> [m/s], <code>pitchRate</code>, <code>rollRate</code> [rad/s]</li>
<li>parameters: <code>rover</code> (RoverParameters: <code>M</code>, <code>g</code>, <code>Iyy</code>, <code>Ixx</code>, <code>Izz</code>; its limb fields unused), <code>legs</code> (LegWheelParameters: six <code>LimbParameters</code>, <code>kJoint</code> [N&middot;m/rad] 2e4, <code>dJoint</code> [N&middot;m&middot;s/rad] 2e3, <code>tauJointMax</code> [N&middot;m] 2e3), <code>terrain</code> (TerrainParameters), <code>height0</code> [m] 1.0 (start height of the centre of gravity), <code>nWheels</code> = 6 (fixed); <code>soil</code>, <code>soilB</code> (SoilParameters), <code>wheel</code> (WheelParameters),
<code>nNodes</code>, <code>nIterations</code>, <code>vEps</code>, <code>vHold</code>, <code>vStick</code>
as <code>SteerableRover</code></li>
</ul>

<h4>LegWheelRoverBody</h4>
<p><a href=\"modelica://RoverTerramechanics.FMUs.LegWheelRoverBody\">FMUs.LegWheelRoverBody</a>:
<code>Components.LegWheelChassis</code> alone, cut at the hubs as the steerable rover is, for
co-simulation with six <code>Wheel</code>s (<code>W[i]</code>, <code>v_hub[i]</code>,
<code>v_lat[i]</code> to wheel i; its <code>Fx</code>, <code>Fy</code> back). The wheels are
steered by the ankle steer joints: a wheel has no steering input of its own.</p>
<ul>
<li>inputs: the 36 joint set-points <code>hipYaw</code>, <code>hipPitch</code>, <code>kneePitch</code>, <code>anklePitch</code>, <code>ankleSteer</code>, <code>ankleRoll</code> [rad], six each (limbs 1-3 front, middle, rear on the left, 4-6 on the right; start: the paper's posture, hubs at x = 1.5, 0, -1.5 m, y = &plusmn;1.5 m, 1.0 m below the centre of gravity); their rates <code>hipYawRate</code>, <code>hipPitchRate</code>, <code>kneePitchRate</code>, <code>anklePitchRate</code>, <code>ankleSteerRate</code>, <code>ankleRollRate</code> [rad/s] (optional, start 0); <code>Fx[1..6]</code>, <code>Fy[1..6]</code> [N] (wheel frames), <code>tau[1..6]</code>
[N&middot;m]; <code>groundHeight[1..6]</code> [m], <code>groundHeightRate[1..6]</code> [m/s], <code>groundGradientAlong[1..6]</code>, <code>groundGradientLateral[1..6]</code> [1]: the ground under each hub (<code>Interfaces.GroundContacts</code>; optional, start 0)</li>
<li>outputs: <code>W[1..6]</code> [N], <code>v_hub[1..6]</code>, <code>v_lat[1..6]</code> [m/s] to
the wheels; joint angles <code>hipYawAngle</code>, <code>hipPitchAngle</code>, <code>kneePitchAngle</code>, <code>anklePitchAngle</code>, <code>ankleSteerAngle</code>, <code>ankleRollAngle</code> [rad] (the set-points deflected by the load), servo torques <code>hipYawTorque</code>, <code>hipPitchTorque</code>, <code>kneePitchTorque</code>, <code>anklePitchTorque</code>, <code>ankleSteerTorque</code>, <code>ankleRollTorque</code> [N&middot;m], hub positions <code>hubX</code>, <code>hubY</code>, <code>hubZ</code> [m] (body frame, from the joint angles), wheel headings <code>steer</code> [rad] (from the ankle steer joints); the body's pose and velocity <code>x</code>, <code>y</code>, <code>z</code> [m] (z: the centre of gravity over the ground plane), <code>yaw</code>, <code>pitch</code>, <code>roll</code> [rad], <code>v</code>, <code>vy</code> [m/s], <code>yawRate</code> [rad/s], <code>heaveRate</code> [m/s], <code>pitchRate</code>, <code>rollRate</code> [rad/s]</li>
<li>parameters: <code>rover</code> (RoverParameters: <code>M</code>, <code>g</code>, <code>Iyy</code>, <code>Ixx</code>, <code>Izz</code>; its limb fields unused), <code>legs</code> (LegWheelParameters: six <code>LimbParameters</code>, <code>kJoint</code> [N&middot;m/rad] 2e4, <code>dJoint</code> [N&middot;m&middot;s/rad] 2e3, <code>tauJointMax</code> [N&middot;m] 2e3), <code>terrain</code> (TerrainParameters), <code>height0</code> [m] 1.0 (start height of the centre of gravity), <code>nWheels</code> = 6 (fixed)</li>
</ul>

<h4>RoverReconnected</h4>
<p><a href=\"modelica://RoverTerramechanics.Examples.RoverReconnected\">Examples.RoverReconnected</a>
(not an FMU): <code>FMUs.RoverBody</code> and six <code>FMUs.Wheel</code> instances wired only
through their public inputs and outputs, as the co-simulation wires the FMUs:
<code>body.W[i]</code> &rarr; <code>wheel_i.W</code>, <code>body.v_hub[i]</code> &rarr;
<code>wheel_i.v_hub</code>, <code>wheel_i.Fx</code> &rarr; <code>body.Fx[i]</code>,
<code>tau[i]</code> &rarr; <code>wheel_i.tau</code> and <code>body.tau[i]</code>. Same interface
as <code>Rover</code> (both extend <code>Interfaces.PitchPlaneRover</code>); the tests check the
two give the same trajectories.</p>

<h4>Records</h4>
<ul>
<li><code>SoilParameters</code> (Table 2): <code>c</code> [Pa] 800, <code>phi</code> [rad]
37.2&deg;, <code>kc</code> [N/m<sup>n+1</sup>] 1.37e3, <code>kphi</code> [N/m<sup>n+2</sup>]
8.14e5, <code>n</code> 1.0, <code>kx</code> [m] 0.036, <code>a0</code> 0.4, <code>a1</code>
0.15, <code>lam</code> 0.90; for the lateral force (Ishigami et al. 2007) <code>kxBeta</code>
[m/rad] 0.043, <code>ky</code> [m] 0.013, <code>kyBeta</code> [m/rad] 0.020, <code>rho</code>
[kg/m<sup>3</sup>] 1.6e3, <code>gravity</code> [m/s<sup>2</sup>] 1.62, <code>xc</code> [rad] 0 =
45&deg; - &phi;/2 of the soil's own &phi; (26.4&deg; for 37.2&deg;; a value in (0, &pi;/2) sets it
explicitly). Field names mirror <code>terramechanics.Soil</code> (<code>kx_beta</code>,
<code>ky_beta</code> there).</li>
<li><code>WheelParameters</code>: <code>r</code> [m] 0.355, <code>b</code> [m] 0.175 (Table 2),
<code>J</code> [kg&middot;m<sup>2</sup>] 0.5 (ours). Mirrors <code>terramechanics.Wheel</code>.</li>
<li><code>RoverParameters</code>: <code>M</code> [kg] 1570, <code>g</code> [m/s<sup>2</sup>]
1.62 (paper), and ours: <code>Iyy</code> [kg&middot;m<sup>2</sup>] 1120, <code>xLimb[3]</code>
[m] {1.5, 0, -1.5}, <code>hCoG</code> [m] 1.0, <code>kLimb</code> [N/m] 2.0e4,
<code>dLimb</code> [N&middot;s/m] 2.0e3; for the steerable rover <code>yLimb</code> [m] 1.5,
<code>Ixx</code> [kg&middot;m<sup>2</sup>] 1120, <code>Izz</code> [kg&middot;m<sup>2</sup>]
1980.</li>
</ul>
</html>"));
end Models;
