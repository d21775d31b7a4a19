within RoverTerramechanics.Functions;
function destructiveAngle "Hegedus's destructive angle X_c of a soil: its given value, or 45 deg - phi/2 where it is 0"
  input Real xc(unit="rad") "The soil's X_c; 0: not given";
  input Real phi(unit="rad") "The soil's internal friction angle";
  output Real angle(unit="rad") "X_c in use";
algorithm
  angle := if noEvent(xc > 0) then xc else 0.7853981633974483 - phi/2;
  annotation (Documentation(info="<html>
<p>The angle of the failure wedge in front of the wheel's side (Hegedus 1960, as in Ishigami et al.
2007): a soil may give it; where it does not (0), the passive Rankine wedge's 45&deg; - &phi;/2. One
place for the rule: <code>contactForces</code> uses it, and <code>Components.RigidWheel</code> blends
each soil's own angle across a soil boundary. Same as the Python reference
(<code>terramechanics.parameters.xc_from_phi</code> and <code>Soil.blend</code>).</p>
</html>"));
end destructiveAngle;
