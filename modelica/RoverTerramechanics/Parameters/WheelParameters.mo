within RoverTerramechanics.Parameters;
record WheelParameters "Rigid wheel geometry (Table 2) and spin inertia"
  parameter Real r(unit="m", min=0) = 0.355 "Wheel radius (Table 2)";
  parameter Real b(unit="m", min=0) = 0.175 "Wheel width, 'tread' in Table 2";
  parameter Real J(unit="kg.m2", min=0) = 0.5 "Polar moment of inertia about the axle (not in the paper: uniform 8 kg disc of radius r)";
  annotation (Documentation(info="<html>
<p>Field names match <code>terramechanics.Wheel</code>. The paper does not give the wheel inertia;
J = 0.5 kg&middot;m<sup>2</sup> is a uniform 8 kg disc of radius 0.355 m (J = m r<sup>2</sup>/2),
the order of an ATHLETE-class wheel rim. It only affects the wheel spin dynamics.</p>
</html>"));
end WheelParameters;
