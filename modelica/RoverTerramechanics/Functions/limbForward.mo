within RoverTerramechanics.Functions;
function limbForward "Forward kinematics of a leg-wheel limb: the wheel hub, the ankle link's direction and the wheel's axle in the body frame for the six joint angles"
  input RoverTerramechanics.Parameters.LimbParameters limb "Mount and link lengths";
  input Real q[6](each unit="rad") "Hip yaw, hip pitch, knee pitch, ankle pitch, ankle steer, ankle roll";
  output Real hub[3](each unit="m") "Wheel hub in the body frame";
  output Real link[3](each unit="1") "Direction of the last link (ankle roll joint to hub), unit vector";
  output Real axle[3](each unit="1") "The wheel's axle, unit vector";
  output Real jacobian[3, 6](each unit="m") "d hub / d q: column k the hub's velocity per unit rate of joint k [m/rad]";
protected
  Real origin[6, 3](each unit="m") "Joint k's position";
  Real axis[6, 3](each unit="1") "Joint k's axis";
  Real R[3, 3] "Rotation of the current joint frame into the body frame";
  Real Rn[3, 3];
  Real E[3, 3] "The joint's elementary rotation";
  Real c;
  Real s;
  Real length(unit="m") "Link after the joint";
algorithm
  c := cos(limb.mountYaw);
  s := sin(limb.mountYaw);
  R := {{c, -s, 0}, {s, c, 0}, {0, 0, 1}};
  hub := limb.mount;
  for k in 1:6 loop
    for i in 1:3 loop
      origin[k, i] := hub[i];
      axis[k, i] := if k == 1 or k == 6 then R[i, 3] elseif k == 5 then R[i, 1] else R[i, 2];
    end for;
    c := cos(q[k]);
    s := sin(q[k]);
    if k == 1 or k == 6 then
      E := {{c, -s, 0}, {s, c, 0}, {0, 0, 1}} "about z";
    elseif k == 5 then
      E := {{1, 0, 0}, {0, c, -s}, {0, s, c}} "about x";
    else
      E := {{c, 0, s}, {0, 1, 0}, {-s, 0, c}} "about y: positive tips x down";
    end if;
    for i in 1:3 loop
      for j in 1:3 loop
        Rn[i, j] := R[i, 1]*E[1, j] + R[i, 2]*E[2, j] + R[i, 3]*E[3, j];
      end for;
    end for;
    R := Rn;
    length := if k == 2 then limb.thigh elseif k == 3 then limb.shank elseif k == 4 then limb.ankle elseif k == 6 then limb.hubOffset else 0;
    for i in 1:3 loop
      hub[i] := hub[i] + length*R[i, 1];
    end for;
  end for;
  link := {R[1, 1], R[2, 1], R[3, 1]};
  axle := {R[1, 2], R[2, 2], R[3, 2]};
  for k in 1:6 loop
    jacobian[1, k] := axis[k, 2]*(hub[3] - origin[k, 3]) - axis[k, 3]*(hub[2] - origin[k, 2]);
    jacobian[2, k] := axis[k, 3]*(hub[1] - origin[k, 1]) - axis[k, 1]*(hub[3] - origin[k, 3]);
    jacobian[3, k] := axis[k, 1]*(hub[2] - origin[k, 2]) - axis[k, 2]*(hub[1] - origin[k, 1]);
  end for;
  annotation (Documentation(info="<html>
<p>The chain of <code>Parameters.LimbParameters</code>: from the mount at <code>limb.mount</code>
turned by <code>limb.mountYaw</code> about z, the frames turn by R<sub>z</sub>(q<sub>1</sub>),
R<sub>y</sub>(q<sub>2</sub>), R<sub>y</sub>(q<sub>3</sub>), R<sub>y</sub>(q<sub>4</sub>),
R<sub>x</sub>(q<sub>5</sub>), R<sub>z</sub>(q<sub>6</sub>); after the hip pitch, knee and ankle
pitch joints the thigh, shank and ankle link extend along the frame's x axis, after the roll joint
the hub offset. R<sub>y</sub>(&theta;) tips x down for &theta; &gt; 0. The Jacobian's column k is
a<sub>k</sub> &times; (p<sub>hub</sub> - o<sub>k</sub>) for joint k's axis a<sub>k</sub> and position
o<sub>k</sub>. Cross-checked against
<code>rover_cosim.limbs.forward</code> (numpy) to 1e-9 m (tests/test_limbs.py).</p>
</html>"));
end limbForward;
