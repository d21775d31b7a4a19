within RoverTerramechanics.UsersGuide;
class LegWheelRover "The leg-wheel rover: six joints per limb, their kinematics, the limbs' compliance and the contact"
  annotation (Documentation(info="<html>
<p>The paper's plant (Sec. 2.1, Fig. 1) is a leg-wheel robot after NASA/JPL's ATHLETE (Wilcox et
al., J. Field Robotics 24, 2007): six limbs of six rotary joints, a driven wheel at the end of
each. <code>FMUs.LegWheelRover</code> and <code>FMUs.LegWheelRoverBody</code> are that rover;
<code>Components.Limb</code> its limb's kinematics, <code>Components.LegWheelChassis</code> the body
on the six limbs.</p>
<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"520\" height=\"250\" viewBox=\"0 0 520 250\" font-family=\"sans-serif\" font-size=\"11\">
<rect x=\"10\" y=\"40\" width=\"120\" height=\"16\" fill=\"#888\"/>
<text x=\"20\" y=\"34\">body (hexagonal frame)</text>
<line x1=\"130\" y1=\"48\" x2=\"230\" y2=\"20\" stroke=\"#1f77b4\" stroke-width=\"5\"/>
<line x1=\"230\" y1=\"20\" x2=\"300\" y2=\"170\" stroke=\"#1f77b4\" stroke-width=\"5\"/>
<line x1=\"300\" y1=\"170\" x2=\"300\" y2=\"200\" stroke=\"#1f77b4\" stroke-width=\"4\"/>
<circle cx=\"130\" cy=\"48\" r=\"6\" fill=\"#d62728\"/>
<circle cx=\"230\" cy=\"20\" r=\"6\" fill=\"#d62728\"/>
<circle cx=\"300\" cy=\"170\" r=\"6\" fill=\"#d62728\"/>
<circle cx=\"300\" cy=\"186\" r=\"4\" fill=\"#2ca02c\"/>
<circle cx=\"300\" cy=\"205\" r=\"32\" fill=\"none\" stroke=\"#333\" stroke-width=\"3\"/>
<circle cx=\"300\" cy=\"205\" r=\"3\" fill=\"#333\"/>
<line x1=\"180\" y1=\"237\" x2=\"420\" y2=\"237\" stroke=\"#8b4513\" stroke-width=\"2\"/>
<text x=\"60\" y=\"80\">1 hip yaw (body z), 2 hip pitch</text>
<text x=\"240\" y=\"16\">3 knee pitch</text>
<text x=\"310\" y=\"166\">4 ankle pitch</text>
<text x=\"310\" y=\"186\">5 ankle steer (about the link), 6 ankle roll</text>
<text x=\"340\" y=\"215\">hub (wheel, radius r)</text>
<text x=\"150\" y=\"110\">thigh 1.0 m</text>
<text x=\"270\" y=\"110\">shank 1.0 m</text>
<text x=\"200\" y=\"250\">ground: the load W comes out of the limb's compliance</text>
</svg>
<p><b>Joints</b> (from the body out; a limb's joint vector q = (q<sub>1</sub> .. q<sub>6</sub>)):
hip yaw q<sub>1</sub> about the body's z axis at the mount; hip pitch q<sub>2</sub>, knee pitch
q<sub>3</sub> and ankle pitch q<sub>4</sub> about the limb's horizontal axis a (positive tips the
link down); ankle steer q<sub>5</sub> about the ankle link; ankle roll q<sub>6</sub> about the axis
normal to the link and the axle. ATHLETE's six rotary joints per limb are in Wilcox et al.; the
axes of the two ankle joints and every length are our reading: a hexagonal frame 2.75 m across,
the mounts at its corners (<code>Parameters.LegWheelParameters</code>), thigh and shank 1.0 m, ankle
link 0.25 m, the hub 0.15 m beyond the roll joint (<code>Parameters.LimbParameters</code>). The
links' masses are not modelled (the body's mass carries them).</p>
<p><b>Forward kinematics</b> (<code>Components.Limb</code>): with &psi; = mountYaw + q<sub>1</sub>,
a = (-sin &psi;, cos &psi;, 0); a link after pitch angles summing to &beta; points along
(cos &beta; cos &psi;, cos &beta; sin &psi;, -sin &beta;): thigh &beta; = q<sub>2</sub>, shank
q<sub>2</sub> + q<sub>3</sub>, ankle link q<sub>2</sub> + q<sub>3</sub> + q<sub>4</sub>; the steer
turns the axle about the ankle link, the roll the link about the roll axis; the hub lies
hubOffset beyond the roll joint. The hub's geometric Jacobian: column k is
a<sub>k</sub> &times; (p<sub>hub</sub> - o<sub>k</sub>) and, for the rotation, a<sub>k</sub> (joint
k's axis a<sub>k</sub> and position o<sub>k</sub>). The same in Python,
<code>rover_cosim.limbs</code> (rotation matrices; cross-checked to 1e-9).</p>
<p><b>The limbs' compliance.</b> Each joint is a position servo about its set-point, stiffness
k<sub>joint</sub>, damping d<sub>joint</sub>, torque limit &tau;<sub>max</sub>. At the hub the
compliance is C = J K<sup>-1</sup> J<sup>T</sup>; along the ground's normal n the limb is the spring
k<sub>n</sub> = k<sub>joint</sub> / &Sigma;<sub>k</sub>(n&middot;J<sub>k</sub>)<sup>2</sup>. Six limbs
carry the body with more contacts than it needs, so how the weight spreads among them follows
the compliance: in the paper's posture the middle limbs (25.9 kN/m) carry 419.0 N, the front and
rear (26.4 kN/m) 426.4 N. The servos hold the wheel's force F and its motor's reaction M with
&tau; = -J<sup>T</sup>(F, M) (virtual work) and deflect to q = q<sub>set</sub> - &tau; / k<sub>joint</sub>.
Beyond W<sub>limit</sub> = &tau;<sub>max</sub> / max<sub>k</sub>|n&middot;J<sub>k</sub>| the most loaded
joint is at its limit and the limb yields.</p>
<p><b>Contact causality.</b> The load comes out of the compliant limb (from the height of the
set-points' hub over the ground); the wheel's sinkage is not fed back into the hub's height (it
would close an algebraic loop between load and sinkage). So the co-simulation cut is the
steerable rover's: <code>LegWheelRoverBody</code> gives each <code>Wheel</code> W, v_hub, v_lat and
takes its F<sub>x</sub>, F<sub>y</sub>; the ankle steer joints steer.</p>
<p><b>Posture.</b> The inputs are the 36 joint set-points; they start in the paper's posture
(hubs at x = 1.5, 0, -1.5 m, y = &plusmn;1.5 m, 1.0 m below the centre of gravity). A posture
(body height, roll, lateral shift, a lift per hub) becomes set-points by the inverse kinematics
of <code>rover_cosim.limbs</code>; <code>rover_cosim.control.posture.PostureController</code> does
that in the co-simulation, levelling the body on a side slope and sharing the load among the
six wheels.</p>
</html>"));
end LegWheelRover;
