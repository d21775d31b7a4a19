within RoverTerramechanics.Parameters;
record WheelParameters "Rigid wheel geometry (Table 2) and spin inertia"
  parameter Real r(unit="m", min=0) = 0.355 "Wheel radius (Table 2)";
  parameter Real b(unit="m", min=0) = 0.175 "Wheel width, 'tread' in Table 2";
  parameter Real J(unit="kg.m2", min=0) = 0.5 "Polar moment of inertia about the axle (not in the paper: uniform 8 kg disc of radius r)";
  parameter Real grouserHeight(unit="m", min=0) = 0 "Height of the grousers above the rim (0: a smooth wheel, the paper's)";
  parameter Real grouserCount(unit="1", min=0, max=360) = 0 "Number of grousers around the rim, a whole number (0: a smooth wheel)";
  annotation (Documentation(info="<html>
<p>Field names match <code>terramechanics.Wheel</code>. The paper does not give the wheel inertia;
J = 0.5 kg&middot;m<sup>2</sup> is a uniform 8 kg disc of radius 0.355 m (J = m r<sup>2</sup>/2),
the order of an ATHLETE-class wheel rim. It only affects the wheel spin dynamics.</p>
<p>Grousers (<code>grouserHeight</code> h<sub>g</sub>, <code>grouserCount</code> N<sub>g</sub>;
<code>Functions.contactForces</code>): the soil is sheared at the radius r<sub>s</sub> = r + e
h<sub>g</sub> through the grouser tips (Ding et al., J. Terramechanics 48, 2011) and on the sides of
the soil trapped between grousers, a factor g = 1 + 2 e h<sub>g</sub>/b on the shear stress (the
grouser correction of a track's thrust, Wong, Theory of Ground Vehicles), with the engagement e =
min(1, N<sub>g</sub> (&theta;<sub>f</sub> - &theta;<sub>r</sub>)/2&pi;), the mean number of
grousers in the contact patch (our assumption). A smooth wheel (either 0) gives the paper's
results, bit for bit.</p>
</html>"));
end WheelParameters;
