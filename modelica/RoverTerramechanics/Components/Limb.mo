within RoverTerramechanics.Components;
model Limb "Forward kinematics of a leg-wheel limb: the wheel hub, the ankle link's direction, the wheel's axle and the hub's geometric Jacobian in the body frame for the six joint angles"
  parameter RoverTerramechanics.Parameters.LimbParameters geometry "Mount and link lengths";
  input Real q[6](each unit="rad") "Hip yaw, hip pitch, knee pitch, ankle pitch, ankle steer, ankle roll";
  output Real hub[3](each unit="m") "Wheel hub in the body frame";
  output Real link[3](each unit="1") "Direction of the last link (ankle roll joint to hub), unit vector";
  output Real axle[3](each unit="1") "The wheel's axle, unit vector";
  output Real jacobian[3, 6](each unit="m") "d hub / d q: column k the hub's velocity per unit rate of joint k [m/rad]";
  output Real axes[3, 6](each unit="1") "Column k joint k's axis: the hub frame's angular velocity per unit rate of joint k";
  Real heading(unit="rad") "Direction of the limb's vertical plane: mount yaw + hip yaw";
  Real across[3](each unit="1") "The pitch joints' common axis (the limb plane's normal)";
  Real thigh[3](each unit="1") "Hip pitch joint to knee, unit vector";
  Real shank[3](each unit="1") "Knee to ankle pitch joint, unit vector";
  Real ankle[3](each unit="1") "Ankle pitch joint to the steer and roll joints, unit vector";
  Real ankleNormal[3](each unit="1") "The ankle pitch frame's z axis";
  Real steered[3](each unit="1") "The axle after the steer joint, before the roll joint";
  Real rollAxis[3](each unit="1") "The roll joint's axis";
  Real knee[3](each unit="m") "Knee (knee pitch joint) position";
  Real anklePitchJoint[3](each unit="m") "Ankle pitch joint position";
  Real ankleJoint[3](each unit="m") "Position of the ankle steer and roll joints";
  Real lever[3, 6](each unit="m") "Column k: the hub relative to joint k";
equation
  heading = geometry.mountYaw + q[1];
  across[1] = -sin(heading);
  across[2] = cos(heading);
  across[3] = 0;
  thigh[1] = cos(q[2])*cos(heading);
  thigh[2] = cos(q[2])*sin(heading);
  thigh[3] = -sin(q[2]);
  shank[1] = cos(q[2] + q[3])*cos(heading);
  shank[2] = cos(q[2] + q[3])*sin(heading);
  shank[3] = -sin(q[2] + q[3]);
  ankle[1] = cos(q[2] + q[3] + q[4])*cos(heading);
  ankle[2] = cos(q[2] + q[3] + q[4])*sin(heading);
  ankle[3] = -sin(q[2] + q[3] + q[4]);
  ankleNormal[1] = sin(q[2] + q[3] + q[4])*cos(heading);
  ankleNormal[2] = sin(q[2] + q[3] + q[4])*sin(heading);
  ankleNormal[3] = cos(q[2] + q[3] + q[4]);
  for i in 1:3 loop
    steered[i] = cos(q[5])*across[i] + sin(q[5])*ankleNormal[i];
    rollAxis[i] = -sin(q[5])*across[i] + cos(q[5])*ankleNormal[i];
    link[i] = cos(q[6])*ankle[i] + sin(q[6])*steered[i];
    axle[i] = -sin(q[6])*ankle[i] + cos(q[6])*steered[i];
    knee[i] = geometry.mount[i] + geometry.thigh*thigh[i];
    anklePitchJoint[i] = knee[i] + geometry.shank*shank[i];
    ankleJoint[i] = anklePitchJoint[i] + geometry.ankle*ankle[i];
    hub[i] = ankleJoint[i] + geometry.hubOffset*link[i];
  end for;
  for i in 1:3 loop
    axes[i, 1] = if i == 3 then 1 else 0;
    axes[i, 2] = across[i];
    axes[i, 3] = across[i];
    axes[i, 4] = across[i];
    axes[i, 5] = ankle[i];
    axes[i, 6] = rollAxis[i];
    lever[i, 1] = hub[i] - geometry.mount[i];
    lever[i, 2] = hub[i] - geometry.mount[i];
    lever[i, 3] = hub[i] - knee[i];
    lever[i, 4] = hub[i] - anklePitchJoint[i];
    lever[i, 5] = hub[i] - ankleJoint[i];
    lever[i, 6] = hub[i] - ankleJoint[i];
  end for;
  for k in 1:6 loop
    jacobian[1, k] = axes[2, k]*lever[3, k] - axes[3, k]*lever[2, k];
    jacobian[2, k] = axes[3, k]*lever[1, k] - axes[1, k]*lever[3, k];
    jacobian[3, k] = axes[1, k]*lever[2, k] - axes[2, k]*lever[1, k];
  end for;
  annotation (Documentation(info="<html>
<p>The chain of <code>Parameters.LimbParameters</code>, in closed form. The frame at the mount
(<code>geometry.mount</code>) is turned about z by <code>geometry.mountYaw</code> and the hip yaw
q<sub>1</sub>: the limb's vertical plane, at heading &psi;, with the pitch joints' common axis
a = (-sin &psi;, cos &psi;, 0). The hip pitch q<sub>2</sub>, knee q<sub>3</sub> and ankle pitch
q<sub>4</sub> turn the thigh, shank and ankle link in that plane, each at the sum of the pitch
angles before it (positive tips the link down: the thigh along (cos q<sub>2</sub> cos &psi;,
cos q<sub>2</sub> sin &psi;, -sin q<sub>2</sub>)). The ankle steer q<sub>5</sub> turns about the ankle
link, the ankle roll q<sub>6</sub> about the axis normal to the link and the axle; the hub lies
<code>geometry.hubOffset</code> beyond the roll joint along the last link. The Jacobian's column k
is a<sub>k</sub> &times; (p<sub>hub</sub> - o<sub>k</sub>) for joint k's axis a<sub>k</sub>
(<code>axes</code>, the rotational part of the geometric Jacobian) and position o<sub>k</sub>.
Written as equations, not as a function, so that it is one block of explicit assignments
in the FMUs. Cross-checked against <code>rover_cosim.limbs.forward</code> and
<code>jacobian</code> (numpy, rotation matrices) to 1e-9 (tests/test_limbs.py).</p>
</html>"));
end Limb;
