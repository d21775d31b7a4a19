within RoverTerramechanics.Functions;
function shearStress "Shear stress from normal stress and shear displacement, Eqs. (7)-(10)"
  input Real sigma(unit="Pa") "Normal stress";
  input Real theta(unit="rad") "Angle";
  input Real thetaF(unit="rad") "Entry angle";
  input Real slip(unit="1") "Slip ratio";
  input RoverTerramechanics.Parameters.SoilParameters soil "Soil";
  input RoverTerramechanics.Parameters.WheelParameters wheel "Wheel";
  input Real kx(unit="m") "Shear deformation modulus (soil.kx, grown with the slip angle)";
  input Real radius(unit="m") "Radius at which the soil is sheared: wheel.r, or the grousers' shear radius";
  output Real tau(unit="Pa") "Shear stress";
protected
  Real j(unit="m") "Soil shear displacement, Eq. (10)";
algorithm
  j := radius*(thetaF - theta - (1 - slip)*(sin(thetaF) - sin(theta)));
  tau := (soil.c + sigma*tan(soil.phi))*(if noEvent(j >= 0) then 1 - exp(-j/kx) else exp(j/kx) - 1);
  annotation (Documentation(info="<html>
<p>Eq. (10): j<sub>x</sub> = r[&theta;<sub>f</sub> - &theta; - (1 - &kappa;)(sin &theta;<sub>f</sub>
- sin &theta;)]; Eqs. (8)-(9): &tau;<sub>x</sub> = (c + &sigma; tan &phi;)(1 - exp(-j<sub>x</sub>/k<sub>x</sub>)).
Where the soil is sheared backwards (j<sub>x</sub> &lt; 0, while skidding) the law is applied with
the sign of the displacement so that |&tau;<sub>x</sub>| never exceeds the Mohr-Coulomb strength
c + &sigma; tan &phi;; read literally, Eq. (9) would grow like exp(|j<sub>x</sub>|/k<sub>x</sub>)
there. Same choice as the Python reference <code>terramechanics.shear_stress</code>.</p>
</html>"));
end shearStress;
