within RoverTerramechanics.Functions;
function contactForces "Contact forces Fx, Fz and torque Tx of a rigid wheel at a given sinkage and slip, Eqs. (1)-(3), (11)-(13)"
  input Real h(unit="m") "Sinkage, clamped to [0, r]";
  input Real slip(unit="1") "Slip ratio";
  input RoverTerramechanics.Parameters.SoilParameters soil "Soil";
  input RoverTerramechanics.Parameters.WheelParameters wheel "Wheel";
  input Integer nNodes = 10 "Gauss-Legendre nodes on each side of thetaM";
  input Real slipAngle(unit="rad") = 0 "Slip angle beta of the hub velocity (Ishigami et al. 2007), |beta| < pi/2";
  input Boolean lateralAtZero = false "true: evaluate the lateral terms at beta = 0 too (they are 0 there, their derivative is not)";
  input Real rutDepth(unit="m") = 0 "Depth of the rut a previous wheel left (multi-pass); h is then the sinkage below its floor";
  output Real Fx(unit="N") "Longitudinal force (drawbar pull), Eq. (12)";
  output Real Fz(unit="N") "Vertical force, Eq. (11)";
  output Real Tx(unit="N.m") "Resistance torque about the axle, Eq. (13)";
  output Real Fy(unit="N") "Lateral force along the wheel's left, opposing the hub's sideways sliding";
  output Real FySidewall(unit="N") "Sidewall (bulldozing) part of Fy";
protected
  Real hc(unit="m") "Clamped sinkage";
  Real thetaF(unit="rad") "Entry angle, Eq. (1)";
  Real thetaR(unit="rad") "Exit angle, Eq. (2), negative";
  Real thetaM(unit="rad") "Angle of maximum normal stress, Eq. (3)";
  Real u "Gauss-Legendre node on [0, 1]";
  Real w "Its weight";
  Real s "Position of the node along a piece, u^2, from the end where the stress vanishes";
  Real ds "Weight of the node in s: 2 u w";
  Real theta(unit="rad");
  Real sigma(unit="Pa");
  Real tau(unit="Pa");
  Real sumFz(unit="Pa");
  Real sumFx(unit="Pa");
  Real sumTau(unit="Pa");
  Real dFront(unit="rad") "Front piece, thetaF - thetaM";
  Real dRear(unit="rad") "Rear piece, thetaM - thetaR";
  Real kx(unit="m") "Shear deformation modulus at this slip angle";
  Real ky(unit="m") "Lateral shear deformation modulus at this slip angle";
  Real tanBeta(unit="1") "tan of the slip angle";
  Real sumFy(unit="Pa") "Sum of the lateral shear stress";
  Real sumPile(unit="N/m") "Sum of the sidewall resistance times its lever";
  Real depth(unit="m") "Depth of the soil piled against the side at theta";
  Real d1(unit="1") "Hegedus D1";
  Real d2(unit="1") "Hegedus D2";
  Real xc(unit="rad") "Destructive angle: soil.xc, or 45 deg - phi/2 where soil.xc is 0";
  Real exponent(unit="1") "Sinkage exponent at this slip: n + nSlip*|slip| (slip-sinkage)";
  Real engagement(unit="1") "Mean number of grousers in the patch, at most 1";
  Real radius(unit="m") "Shear radius r + engagement*grouserHeight";
  Real ratio(unit="1") "radius/r";
  Real scaleForce(unit="1") "Weight of the shear stress in Eqs. (11)-(12): ratio*(1 + 2 engagement grouserHeight/b); scaleForce*ratio in Eq. (13)";
algorithm
  kx := soil.kx + soil.kxBeta*noEvent(abs(slipAngle));
  ky := soil.ky + soil.kyBeta*noEvent(abs(slipAngle));
  tanBeta := tan(slipAngle);
  xc := destructiveAngle(soil.xc, soil.phi);
  d1 := 1/tan(xc) + tan(xc + soil.phi);
  d2 := 1/tan(xc) + tan(soil.phi)/tan(xc)^2;
  sumFy := 0;
  sumPile := 0;
  depth := 0;
  hc := noEvent(min(max(h, 0.0), wheel.r));
  thetaF := acos(1 - hc/wheel.r);
  thetaR := -acos(1 - soil.lam*hc/wheel.r);
  thetaM := (soil.a0 + soil.a1*slip)*thetaF;
  exponent := soil.n + soil.nSlip*noEvent(abs(slip));
  engagement := noEvent(min(1.0, wheel.grouserCount*(thetaF - thetaR)/(2*3.141592653589793)));
  radius := wheel.r + engagement*wheel.grouserHeight;
  ratio := radius/wheel.r;
  scaleForce := ratio*(1 + 2*engagement*wheel.grouserHeight/wheel.b);
  dFront := thetaF - thetaM;
  dRear := thetaM - thetaR;
  Fx := 0;
  Fz := 0;
  Tx := 0;
  u := 0;
  w := 0;
  for i in 1:nNodes loop
    (u, w) := gaussLegendre(nNodes, i);
    s := u*u;
    ds := 2*u*w;
    // Front piece [thetaM, thetaF], Eq. (5), nodes crowding at thetaF.
    theta := thetaF - dFront*s;
    sigma := normalStress(theta, thetaF, soil, wheel, exponent, rutDepth);
    tau := shearStress(sigma, theta, thetaF, slip, soil, wheel, kx, radius);
    Fz := Fz + ds*dFront*(sigma*cos(theta) + tau*scaleForce*sin(theta));
    Fx := Fx + ds*dFront*(tau*scaleForce*cos(theta) - sigma*sin(theta));
    Tx := Tx + ds*dFront*(tau*scaleForce*ratio);
    if lateralAtZero or noEvent(tanBeta <> 0) then
      // Lateral shear and sidewall: both vanish at beta = 0 (zero displacement), not computed then.
      sumFy := sumFy + ds*dFront*lateralShear(sigma, theta, thetaF, slip, tanBeta, ky, soil, wheel);
      depth := noEvent(max(wheel.r*(cos(theta) - cos(thetaF)), 0.0));
      sumPile := sumPile + ds*dFront*d1*(soil.c*depth + d2*soil.rho*soil.gravity*depth^2/2)*(wheel.r - depth*cos(theta));
    end if;
    // Rear piece [thetaR, thetaM], Eq. (6), nodes crowding at thetaR: the equivalent front
    // angle of this node, thetaF - (theta - thetaR)/dRear*dFront, is the front node's, so the
    // normal stress is the one just computed.
    theta := thetaR + dRear*s;
    tau := shearStress(sigma, theta, thetaF, slip, soil, wheel, kx, radius);
    Fz := Fz + ds*dRear*(sigma*cos(theta) + tau*scaleForce*sin(theta));
    Fx := Fx + ds*dRear*(tau*scaleForce*cos(theta) - sigma*sin(theta));
    Tx := Tx + ds*dRear*(tau*scaleForce*ratio);
    if lateralAtZero or noEvent(tanBeta <> 0) then
      sumFy := sumFy + ds*dRear*lateralShear(sigma, theta, thetaF, slip, tanBeta, ky, soil, wheel);
      depth := noEvent(max(wheel.r*(cos(theta) - cos(thetaF)), 0.0));
      sumPile := sumPile + ds*dRear*d1*(soil.c*depth + d2*soil.rho*soil.gravity*depth^2/2)*(wheel.r - depth*cos(theta));
    end if;
  end for;
  Fz := wheel.r*wheel.b*Fz;
  Fx := wheel.r*wheel.b*Fx;
  Tx := wheel.r*wheel.r*wheel.b*Tx;
  // Sidewall: Hegedus's bulldozing resistance, mobilised like the shear by the lateral
  // displacement of the whole patch (0 at beta = 0, proportional to beta near it).
  FySidewall := -(if noEvent(slipAngle >= 0) then 1 - exp(-wheel.r*(1 - slip)*(thetaF - thetaR)*tanBeta/ky)
    else exp(wheel.r*(1 - slip)*(thetaF - thetaR)*tanBeta/ky) - 1)*sumPile;
  Fy := FySidewall - wheel.r*wheel.b*sumFy;
  annotation (Documentation(info="<html>
<p>Entry and exit angles &theta;<sub>f</sub> = acos(1 - h/r) (Eq. 1) and &theta;<sub>r</sub> =
-acos(1 - &lambda;h/r) (Eq. 2, negative behind the axle), angle of maximum stress
&theta;<sub>m</sub> = (a<sub>0</sub> + a<sub>1</sub>&kappa;)&theta;<sub>f</sub> (Eq. 3), then</p>
<ul>
<li>Eq. (11): F<sub>z</sub> = r b &int;(&sigma; cos &theta; + &tau; sin &theta;) d&theta;</li>
<li>Eq. (12): F<sub>x</sub> = r b &int;(&tau; cos &theta; - &sigma; sin &theta;) d&theta;</li>
<li>Eq. (13): T<sub>x</sub> = r<sup>2</sup> b &int;&tau; d&theta;</li>
</ul>
<p>over &theta;<sub>r</sub> &le; &theta; &le; &theta;<sub>f</sub>. The normal stress has a kink at
&theta;<sub>m</sub>, so [&theta;<sub>r</sub>, &theta;<sub>m</sub>] and [&theta;<sub>m</sub>,
&theta;<sub>f</sub>] are integrated separately, each by Gauss-Legendre with <code>nNodes</code>
nodes (<code>gaussLegendre</code>) in s = u<sup>2</sup>, measured from the end of the piece where
&sigma; vanishes (&theta;<sub>f</sub> in front, &theta;<sub>r</sub> behind), as the Python
reference does: the substitution turns the end-point behaviour (&theta;<sub>f</sub> -
&theta;)<sup>n</sup> of &sigma; into a smooth integrand for n = 1 and a milder singularity for
other n. With the same s on both pieces the rear node's equivalent front angle of Eq. (6) is the
front node's, so &sigma; is evaluated once per pair. Measured against 96 nodes of the Python
reference on the Table 2 soil (sinkage 1 mm to 0.3 m), the largest error of F<sub>x</sub> and
F<sub>z</sub> relative to F<sub>z</sub> with 10 nodes (the models' default) and 16: driving 8e-8
and 4e-13; while skidding, where &tau; has a kink at j<sub>x</sub> = 0 inside the patch that these
pieces do not split at (the Python reference does), 2.2e-5 and 6e-6 up to h = 0.1 m, 4.2e-4 and
1.1e-4 up to h = r/2, 2.2e-3 and 5.5e-4 deeper (composite Simpson with 17 nodes per piece, used
before: 1e-4 driving). The test suite measures it against the Python reference.</p>
<p>Wheel effects (issue 48; each off by default, and then the results are the paper's bit for bit):
<b>grousers</b> shear the soil at r<sub>s</sub> = r + e h<sub>g</sub> (Eq. 10 with r<sub>s</sub>,
Ding et al., J. Terramechanics 48, 2011) and on the trapped soil's sides, so the shear stress counts
(r<sub>s</sub>/r) g in Eqs. (11)-(12) and (r<sub>s</sub>/r)<sup>2</sup> g in Eq. (13), g = 1 + 2 e
h<sub>g</sub>/b, e = min(1, N<sub>g</sub>(&theta;<sub>f</sub> - &theta;<sub>r</sub>)/2&pi;);
<b>slip-sinkage</b> makes the exponent of Eq. (5) n + nSlip |&kappa;|; in a <b>rut</b> of depth
<code>rutDepth</code> the normal stress is that of <code>normalStress</code> with the rut (h is then the
sinkage below the rut's floor). The Python reference: <code>terramechanics.grousers</code>,
<code>Soil.sinkage_exponent</code>, <code>terramechanics.multipass</code>.</p>
<p>Lateral force (Ishigami, Miwa, Nagatani, Yoshida, J. Field Robotics 24(3), 2007) at the slip
angle &beta;: k<sub>x</sub> and k<sub>y</sub> grow with |&beta;|; lateral shear from
j<sub>y</sub> = r(1 - s)(&theta;<sub>f</sub> - &theta;) tan &beta; (<code>lateralShear</code>);
the sidewall resistance of the soil piled against the side, R<sub>b</sub> = D<sub>1</sub>(c h +
D<sub>2</sub> &rho; g h<sup>2</sup>/2) with h = r(cos &theta; - cos &theta;<sub>f</sub>) (Hegedus
1960, as in Ishigami 2007), integrated with the lever r - h cos &theta; and mobilised by
1 - exp(-|j<sub>y</sub>(&theta;<sub>r</sub>)|/k<sub>y</sub>), so that it vanishes smoothly at
&beta; = 0. F<sub>y</sub> = F<sub>y,sidewall</sub> - r b &int;&tau;<sub>y</sub> d&theta; opposes
the sideways sliding. Same as <code>terramechanics.lateral</code>. At &beta; = 0 both lateral parts are
zero (no lateral displacement) and are not computed: a third of the exponentials of an evaluation;
<code>lateralAtZero</code> = true computes them there too, for their derivative with respect to
&beta; (the cornering stiffness), which is not zero (<code>contactResidual</code>).</p>
</html>"));
end contactForces;
