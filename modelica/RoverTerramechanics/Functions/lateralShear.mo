within RoverTerramechanics.Functions;
function lateralShear "Lateral shear stress from normal stress and lateral shear displacement (Ishigami et al. 2007)"
  input Real sigma(unit="Pa") "Normal stress";
  input Real theta(unit="rad") "Angle";
  input Real thetaF(unit="rad") "Entry angle";
  input Real slip(unit="1") "Slip ratio";
  input Real tanBeta(unit="1") "tan of the slip angle";
  input Real ky(unit="m") "Lateral shear deformation modulus at this slip angle";
  input RoverTerramechanics.Parameters.SoilParameters soil "Soil";
  input RoverTerramechanics.Parameters.WheelParameters wheel "Wheel";
  output Real tau(unit="Pa") "Lateral shear stress, with the sign of the displacement";
protected
  Real j(unit="m") "Lateral shear displacement";
algorithm
  j := wheel.r*(1 - slip)*(thetaF - theta)*tanBeta;
  tau := (soil.c + sigma*tan(soil.phi))*(if noEvent(j >= 0) then 1 - exp(-j/ky) else exp(j/ky) - 1);
  annotation (Documentation(info="<html>
<p>Ishigami et al. (2007): j<sub>y</sub> = r(1 - s)(&theta;<sub>f</sub> - &theta;) tan &beta;,
&tau;<sub>y</sub> = (c + &sigma; tan &phi;)(1 - exp(-|j<sub>y</sub>|/k<sub>y</sub>)) sign(j<sub>y</sub>),
bounded by the Mohr-Coulomb strength. Same as <code>terramechanics.lateral</code>.</p>
</html>"));
end lateralShear;
