within RoverTerramechanics.Functions;
function slipRatio "Longitudinal slip ratio, Eq. (4), both branches, event-free"
  input Real rOmega(unit="m/s") "Wheel circumferential speed r*omega";
  input Real v(unit="m/s") "Forward speed of the wheel hub";
  input Real vEps(unit="m/s") = 1e-3 "Regularising speed (> 0): floor of the denominator";
  output Real slip(unit="1") "Slip ratio in [-1, 1]";
protected
  Real denominator(unit="m/s");
algorithm
  denominator := noEvent(max(max(abs(rOmega), abs(v)), vEps));
  slip := noEvent(min(max((rOmega - v)/denominator, -1.0), 1.0));
  annotation (Documentation(info="<html>
<p>Eq. (4): (r&omega; - v)/(r&omega;) when driving (r&omega; &gt; v) and (r&omega; - v)/v when
skidding (r&omega; &lt; v) are the single expression (r&omega; - v)/max(|r&omega;|, |v|). The
denominator is floored at <code>vEps</code> so that the slip is defined at &omega; = 0, at v = 0
and at rest (slip 0); it is exactly Eq. (4) once either speed exceeds vEps. Reverse or mixed-sign
motion, outside the paper's scope, uses the same expression clipped to [-1, 1]. Same as
<code>terramechanics.slip_ratio(r_omega, v, v_eps)</code>.</p>
</html>"));
end slipRatio;
