within RoverTerramechanics.Functions;
function normalStress "Normal stress under the wheel: front branch Eq. (5) evaluated at a (possibly equivalent) angle"
  input Real theta(unit="rad") "Angle (for the rear branch: the equivalent front angle of Eq. (6))";
  input Real thetaF(unit="rad") "Entry angle";
  input RoverTerramechanics.Parameters.SoilParameters soil "Soil";
  input RoverTerramechanics.Parameters.WheelParameters wheel "Wheel";
  output Real sigma(unit="Pa") "Normal stress, zero outside the contact patch";
algorithm
  sigma := (soil.kc/wheel.b + soil.kphi)*wheel.r^soil.n*noEvent(max(cos(theta) - cos(thetaF), 0.0))^soil.n;
  annotation (Documentation(info="<html>
<p>Eq. (5): &sigma;<sub>f</sub>(&theta;) = r<sup>n</sup> (k<sub>c</sub>/b + k<sub>&phi;</sub>)
(cos &theta; - cos &theta;<sub>f</sub>)<sup>n</sup>. The rear branch, Eq. (6), is this function
at the equivalent angle &theta;<sub>f</sub> - (&theta; - &theta;<sub>r</sub>)/(&theta;<sub>m</sub>
- &theta;<sub>r</sub>) (&theta;<sub>f</sub> - &theta;<sub>m</sub>).</p>
</html>"));
end normalStress;
