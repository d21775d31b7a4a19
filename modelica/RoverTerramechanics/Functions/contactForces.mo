within RoverTerramechanics.Functions;
function contactForces "Contact forces Fx, Fz and torque Tx of a rigid wheel at a given sinkage and slip, Eqs. (1)-(3), (11)-(13)"
  input Real h(unit="m") "Sinkage, clamped to [0, r]";
  input Real slip(unit="1") "Slip ratio";
  input RoverTerramechanics.Parameters.SoilParameters soil "Soil";
  input RoverTerramechanics.Parameters.WheelParameters wheel "Wheel";
  input Integer nPanels = 8 "Simpson panels on each side of thetaM (2 intervals, 3 nodes each)";
  input Real slipAngle(unit="rad") = 0 "Slip angle beta of the hub velocity (Ishigami et al. 2007), |beta| < pi/2";
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
  Real u "Position along a piece, 0..1";
  Real w "Simpson weight of a node, without the interval width";
  Real theta(unit="rad");
  Real sigma(unit="Pa");
  Real tau(unit="Pa");
  Real sumFz(unit="Pa");
  Real sumFx(unit="Pa");
  Real sumTau(unit="Pa");
  Real dFront(unit="rad") "Front interval width";
  Real dRear(unit="rad") "Rear interval width";
  Real kx(unit="m") "Shear deformation modulus at this slip angle";
  Real ky(unit="m") "Lateral shear deformation modulus at this slip angle";
  Real tanBeta(unit="1") "tan of the slip angle";
  Real sumFy(unit="Pa") "Sum of the lateral shear stress";
  Real sumPile(unit="N/m") "Sum of the sidewall resistance times its lever";
  Real depth(unit="m") "Depth of the soil piled against the side at theta";
  Real d1(unit="1") "Hegedus D1";
  Real d2(unit="1") "Hegedus D2";
algorithm
  kx := soil.kx + soil.kxBeta*noEvent(abs(slipAngle));
  ky := soil.ky + soil.kyBeta*noEvent(abs(slipAngle));
  tanBeta := tan(slipAngle);
  d1 := 1/tan(soil.xc) + tan(soil.xc + soil.phi);
  d2 := 1/tan(soil.xc) + tan(soil.phi)/tan(soil.xc)^2;
  sumFy := 0;
  sumPile := 0;
  hc := noEvent(min(max(h, 0.0), wheel.r));
  thetaF := acos(1 - hc/wheel.r);
  thetaR := -acos(1 - soil.lam*hc/wheel.r);
  thetaM := (soil.a0 + soil.a1*slip)*thetaF;
  dFront := (thetaF - thetaM)/(2*nPanels);
  dRear := (thetaM - thetaR)/(2*nPanels);
  Fx := 0;
  Fz := 0;
  Tx := 0;
  for i in 0:2*nPanels loop
    u := i/(2*nPanels);
    w := (if i == 0 or i == 2*nPanels then 1.0 else if mod(i, 2) == 1 then 4.0 else 2.0)/3.0;
    // Front piece [thetaM, thetaF], Eq. (5).
    theta := thetaM + (thetaF - thetaM)*u;
    sigma := normalStress(theta, thetaF, soil, wheel);
    tau := shearStress(sigma, theta, thetaF, slip, soil, wheel, kx);
    Fz := Fz + w*dFront*(sigma*cos(theta) + tau*sin(theta));
    Fx := Fx + w*dFront*(tau*cos(theta) - sigma*sin(theta));
    Tx := Tx + w*dFront*tau;
    sumFy := sumFy + w*dFront*lateralShear(sigma, theta, thetaF, slip, tanBeta, ky, soil, wheel);
    depth := noEvent(max(wheel.r*(cos(theta) - cos(thetaF)), 0.0));
    sumPile := sumPile + w*dFront*d1*(soil.c*depth + d2*soil.rho*soil.gravity*depth^2/2)*(wheel.r - depth*cos(theta));
    // Rear piece [thetaR, thetaM], Eq. (6): the equivalent front angle of this node is the
    // front node thetaF - (thetaF - thetaM)*u.
    theta := thetaR + (thetaM - thetaR)*u;
    sigma := normalStress(thetaF - (thetaF - thetaM)*u, thetaF, soil, wheel);
    tau := shearStress(sigma, theta, thetaF, slip, soil, wheel, kx);
    Fz := Fz + w*dRear*(sigma*cos(theta) + tau*sin(theta));
    Fx := Fx + w*dRear*(tau*cos(theta) - sigma*sin(theta));
    Tx := Tx + w*dRear*tau;
    sumFy := sumFy + w*dRear*lateralShear(sigma, theta, thetaF, slip, tanBeta, ky, soil, wheel);
    depth := noEvent(max(wheel.r*(cos(theta) - cos(thetaF)), 0.0));
    sumPile := sumPile + w*dRear*d1*(soil.c*depth + d2*soil.rho*soil.gravity*depth^2/2)*(wheel.r - depth*cos(theta));
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
&theta;<sub>f</sub>] are integrated separately, each by composite Simpson with
<code>nPanels</code> panels (2 nPanels + 1 nodes). With n = 1 and 8 panels the error against the
Python reference (Gauss-Legendre) is below 1e-4 relative for driving slips; the test suite
measures it.</p>
<p>Lateral force (Ishigami, Miwa, Nagatani, Yoshida, J. Field Robotics 24(3), 2007) at the slip
angle &beta;: k<sub>x</sub> and k<sub>y</sub> grow with |&beta;|; lateral shear from
j<sub>y</sub> = r(1 - s)(&theta;<sub>f</sub> - &theta;) tan &beta; (<code>lateralShear</code>);
the sidewall resistance of the soil piled against the side, R<sub>b</sub> = D<sub>1</sub>(c h +
D<sub>2</sub> &rho; g h<sup>2</sup>/2) with h = r(cos &theta; - cos &theta;<sub>f</sub>) (Hegedus
1960, as in Ishigami 2007), integrated with the lever r - h cos &theta; and mobilised by
1 - exp(-|j<sub>y</sub>(&theta;<sub>r</sub>)|/k<sub>y</sub>), so that it vanishes smoothly at
&beta; = 0. F<sub>y</sub> = F<sub>y,sidewall</sub> - r b &int;&tau;<sub>y</sub> d&theta; opposes
the sideways sliding. Same as <code>terramechanics.lateral</code>.</p>
</html>"));
end contactForces;
