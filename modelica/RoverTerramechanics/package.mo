package RoverTerramechanics "Terramechanics rigid wheel, single-wheel test bed and six-limb rover on loose lunar soil (Yoshikawa et al.)"
  annotation (
    version="0.1.0",
    Documentation(info="<html>
<p>Plant models of the paper: the Wong-Reece/Ishigami rigid wheel on loose soil (Sec. 2,
Eqs. 1-13), the single-wheel test bed used for identification (Sec. 3) and the six-limb
ATHLETE-like rover (Sec. 4), as the single source from which the FMUs are built.</p>
<ul>
<li><code>SingleWheel</code>: input tau; outputs Fx, Fz, Tx, slip, sinkage, omega, v.</li>
<li><code>Rover</code>: inputs tau[1..6]; outputs x, v, pitch, Fz[i], Fx[i], Tx[i], slip[i], sinkage[i], omega[i].</li>
<li><code>RoverBody</code> and <code>Wheel</code>: the rover cut at the wheel hubs for
co-simulation; <code>RoverReconnected</code> wires them back together.</li>
</ul>
<p>Standard Modelica 3.x; no Modelica Standard Library is used. All variables carry SI units.</p>
</html>"));
end RoverTerramechanics;
