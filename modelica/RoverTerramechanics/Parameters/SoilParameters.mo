within RoverTerramechanics.Parameters;
record SoilParameters "Loose lunar-simulant soil of the paper's Table 2 (Bekker, Janosi-Hanamoto, Wong-Reece)"
  parameter Real c(unit="Pa", min=0) = 800 "Cohesion stress, Eq. (8)";
  parameter Real phi(unit="rad", displayUnit="deg", min=0, max=1.5707963267948966) = 0.6492624817418906 "Internal friction angle (37.2 deg), Eq. (8)";
  parameter Real kc(unit="N/m2", min=0) = 1.37e3 "Cohesive pressure-sinkage modulus, Eq. (5); unit N/m^(n+1), N/m2 for n = 1";
  parameter Real kphi(unit="N/m3", min=0) = 8.14e5 "Frictional pressure-sinkage modulus, Eq. (5); unit N/m^(n+2), N/m3 for n = 1";
  parameter Real n(unit="1", min=0) = 1.0 "Sinkage exponent, Eq. (5)";
  parameter Real kx(unit="m", min=0) = 0.036 "Shear deformation modulus, Eq. (9)";
  parameter Real a0(unit="1", min=0, max=1.0) = 0.4 "Constant of the maximum-stress angle, Eq. (3)";
  parameter Real a1(unit="1", min=0, max=1.0) = 0.15 "Slip coefficient of the maximum-stress angle, Eq. (3)";
  parameter Real lam(unit="1", min=0, max=1.0) = 0.90 "Wheel sinkage ratio of the exit angle, Eq. (2)";
  parameter Real kxBeta(unit="m/rad", min=0) = 0.043 "Growth of kx with the slip angle: kx + kxBeta*|beta| (Ishigami et al. 2007)";
  parameter Real ky(unit="m", min=0) = 0.013 "Lateral shear deformation modulus at zero slip angle (Ishigami et al. 2007)";
  parameter Real kyBeta(unit="m/rad", min=0) = 0.020 "Growth of ky with the slip angle: ky + kyBeta*|beta| (Ishigami et al. 2007)";
  parameter Real rho(unit="kg/m3", min=0) = 1.6e3 "Dry density of the soil, for the sidewall resistance (Ishigami et al. 2007)";
  parameter Real gravity(unit="m/s2", min=0) = 1.62 "Gravity acting on the soil (lunar): rho*gravity is its weight density";
  parameter Real xc(unit="rad", displayUnit="deg", min=0, max=1.5707963267948966) = 0 "Destructive angle of the soil piled against the wheel's side; 0 (the default): 45 deg - phi/2 of this soil's phi (26.4 deg for 37.2 deg)";
  parameter Real nSlip(unit="1", min=0) = 0 "Slip-sinkage: growth of the sinkage exponent with the slip ratio, n + nSlip*|slip| (Ding et al. 2011); 0: the paper's soil";
  annotation (Documentation(info="<html>
<p>Table 2 of Yoshikawa et al. Field names match <code>terramechanics.Soil</code>. The units of
<code>kc</code> and <code>kphi</code> depend on <code>n</code> (N/m<sup>n+1</sup> and
N/m<sup>n+2</sup>); the declared units are those for the paper's n = 1.</p>
<p>Valid ranges (the Python reference rejects others): c &ge; 0, 0 &lt; phi &lt; &pi;/2,
kphi &gt; 0, n &gt; 0, kx &gt; 0, 0 &le; a1 &lt; a0, a0 + a1 &lt; 1, 0 &lt; lam &le; 1; for the lateral
force kxBeta &ge; 0, ky &gt; 0, kyBeta &ge; 0, rho &ge; 0, gravity &ge; 0, 0 &le; xc &lt; pi/2.</p>
<p>X<sub>c</sub> follows &phi;: left at 0 it is 45&deg; - &phi;/2 of the soil's own &phi; (Hegedus, as Ishigami
et al. use it), so changing <code>phi</code> alone changes it too; a value in (0, &pi;/2) sets it explicitly.</p>
<p>Slip-sinkage (off by default): the sinkage exponent of Eq. (5) is n + nSlip |&kappa;| at the
slip ratio &kappa; (Ding, Gao, Deng et al., J. Terramechanics 48, 2011, who fit n = n<sub>0</sub> +
n<sub>1</sub> s on single-wheel tests; |&kappa;| so that a skidding wheel sinks like a driven one).
With nSlip = 0 the results are the paper's, bit for bit.</p>
<p>The lateral parameters are Ishigami, Miwa, Nagatani and Yoshida (J. Field Robotics 24(3), 2007):
kx = 0.043|&beta;| + 0.036 m, ky = 0.020|&beta;| + 0.013 m (&beta; in rad; the paper's kx is the
&beta; = 0 case), dry density 1.6e3 kg/m<sup>3</sup>, destructive angle 45&deg; - &phi;/2.</p>
</html>"));
end SoilParameters;
