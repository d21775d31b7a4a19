within RoverTerramechanics.Functions;
function normalStress "Normal stress under the wheel: front branch Eq. (5) evaluated at a (possibly equivalent) angle"
  input Real theta(unit="rad") "Angle (for the rear branch: the equivalent front angle of Eq. (6))";
  input Real thetaF(unit="rad") "Entry angle";
  input RoverTerramechanics.Parameters.SoilParameters soil "Soil";
  input RoverTerramechanics.Parameters.WheelParameters wheel "Wheel";
  input Real exponent(unit="1") "Sinkage exponent: soil.n, or n + nSlip*|slip| with slip-sinkage";
  input Real rutDepth(unit="m") = 0 "Depth of the rut a previous wheel left: the soil under its floor carried the pressure of that depth (multi-pass); thetaF measured from the floor";
  output Real sigma(unit="Pa") "Normal stress, zero outside the contact patch";
protected
  Real depth(unit="1") "Depth of the soil under the node over r: rutDepth/r + cos(theta) - cos(thetaF), at least rutDepth/r";
algorithm
  depth := rutDepth/wheel.r + noEvent(max(cos(theta) - cos(thetaF), 0.0));
  // n = 1 without slip-sinkage (the exponent then depends on no variable): the closed form, no exp or log.
  sigma := (soil.kc/wheel.b + soil.kphi)*(if noEvent(exponent == 1 and soil.nSlip == 0) then wheel.r*depth
    else wheel.r^exponent*depth^exponent);
  annotation (Documentation(info="<html>
<p>Eq. (5): &sigma;<sub>f</sub>(&theta;) = r<sup>n</sup> (k<sub>c</sub>/b + k<sub>&phi;</sub>)
(cos &theta; - cos &theta;<sub>f</sub>)<sup>n</sup>. Multi-pass: in a rut of depth z<sub>r</sub> left by a
previous wheel, r<sup>n</sup> (k<sub>c</sub>/b + k<sub>&phi;</sub>) (z<sub>r</sub>/r + cos &theta; -
cos &theta;<sub>f</sub>)<sup>n</sup>: the soil under the rut's floor already carried the pressure of
depth z<sub>r</sub> and is loaded on from there (Wong's repetitive loading with a rigid reload).
With n = 1 and no slip-sinkage (the Table 2 soil) the power is computed as the product it is,
without exp and log (the same value to the last place or two; a third of the contact's elementary
function calls). The rear branch, Eq. (6), is this function
at the equivalent angle &theta;<sub>f</sub> - (&theta; - &theta;<sub>r</sub>)/(&theta;<sub>m</sub>
- &theta;<sub>r</sub>) (&theta;<sub>f</sub> - &theta;<sub>m</sub>).</p>
</html>"));
end normalStress;
