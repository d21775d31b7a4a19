package RoverTerramechanics "Terramechanics rigid wheel, single-wheel test bed and six-limb rover on loose lunar soil (Yoshikawa et al.)"
  annotation (
    version="0.1.0",
    Documentation(info="<html>
<p>Plant models of the paper: the Wong-Reece/Ishigami rigid wheel on loose soil (Sec. 2,
Eqs. 1-13), the single-wheel test bed used for identification (Sec. 3) and the six-limb
ATHLETE-like rover (Sec. 4), as the single source from which the FMUs are built. Start with the
<a href=\"modelica://RoverTerramechanics.UsersGuide\">UsersGuide</a>.</p>
<ul>
<li><code>Interfaces</code>: the cut at the wheel hubs (wheel side, body side) and the rover's
own inputs and outputs, declared once.</li>
<li><code>Parameters</code>, <code>Functions</code>, <code>Components</code>: the records, the
terramechanics as event-free functions, the wheel and the rover bodies.</li>
<li><code>FMUs</code>: the models exported as FMUs: <code>SingleWheel</code>,
<code>Rover</code>, <code>RoverBody</code> and <code>Wheel</code> (the rover cut at the wheel hubs
for co-simulation), <code>SteerableRover</code>, <code>SteerableRoverBody</code>.</li>
<li><code>Examples</code>: runnable experiments, and <code>RoverReconnected</code>, which wires
<code>RoverBody</code> and six <code>Wheel</code>s back together.</li>
</ul>
<p>Standard Modelica 3.x; no Modelica Standard Library is used. All variables carry SI units.</p>
</html>"));
end RoverTerramechanics;
