within RoverTerramechanics.Parameters;
record SoilParameters "Loose lunar-simulant soil of the paper's Table 2 (Bekker, Janosi-Hanamoto, Wong-Reece)"
  parameter Real c(unit="Pa") = 800 "Cohesion stress, Eq. (8)";
  parameter Real phi(unit="rad", displayUnit="deg") = 0.6492624817418906 "Internal friction angle (37.2 deg), Eq. (8)";
  parameter Real kc(unit="N/m2") = 1.37e3 "Cohesive pressure-sinkage modulus, Eq. (5); unit N/m^(n+1), N/m2 for n = 1";
  parameter Real kphi(unit="N/m3") = 8.14e5 "Frictional pressure-sinkage modulus, Eq. (5); unit N/m^(n+2), N/m3 for n = 1";
  parameter Real n(unit="1") = 1.0 "Sinkage exponent, Eq. (5)";
  parameter Real kx(unit="m") = 0.036 "Shear deformation modulus, Eq. (9)";
  parameter Real a0(unit="1") = 0.4 "Constant of the maximum-stress angle, Eq. (3)";
  parameter Real a1(unit="1") = 0.15 "Slip coefficient of the maximum-stress angle, Eq. (3)";
  parameter Real lam(unit="1") = 0.90 "Wheel sinkage ratio of the exit angle, Eq. (2)";
  annotation (Documentation(info="<html>
<p>Table 2 of Yoshikawa et al. Field names match <code>terramechanics.Soil</code>. The units of
<code>kc</code> and <code>kphi</code> depend on <code>n</code> (N/m<sup>n+1</sup> and
N/m<sup>n+2</sup>); the declared units are those for the paper's n = 1.</p>
<p>Valid ranges (the Python reference rejects others): c &ge; 0, 0 &lt; phi &lt; &pi;/2,
kphi &gt; 0, n &gt; 0, kx &gt; 0, 0 &le; a1 &lt; a0, a0 + a1 &lt; 1, 0 &lt; lam &le; 1.</p>
</html>"));
end SoilParameters;
