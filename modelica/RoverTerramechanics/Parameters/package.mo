within RoverTerramechanics;
package Parameters "Parameter records: soil, wheel and rover (Table 2 and documented choices)"
  annotation (Documentation(info="<html>
<p>Records whose field names mirror the Python reference <code>terramechanics.Soil</code> and
<code>terramechanics.Wheel</code>; <code>RoverParameters</code> holds every rover parameter the
paper does not give, each with its source or reasoning, in one place.</p>
</html>"));
end Parameters;
