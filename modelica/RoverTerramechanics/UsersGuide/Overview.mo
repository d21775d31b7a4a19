within RoverTerramechanics.UsersGuide;
class Overview "Overview: structure, loading, simulating, building the FMUs"
  annotation (Documentation(info="<html>
<p>Standard Modelica 3.x, one class per file with <code>package.order</code>; no Modelica
Standard Library (the physics needs none), so the package loads on its own. Every variable and
parameter carries an SI <code>unit</code>; the documentation annotations cite the paper's
equation numbers.</p>

<h4>Structure</h4>
<table border=\"1\" cellpadding=\"3\">
<tr><th>package</th><th>what</th></tr>
<tr><td><code>UsersGuide</code></td><td>this guide</td></tr>
<tr><td><code>Interfaces</code></td><td>partial models of the cut at the wheel hubs, declared
once: <code>WheelHub</code> (the wheel side), <code>BodyHubs</code> and
<code>SteerableBodyHubs</code> (the body side), <code>PitchPlaneRover</code> (the rover's own
inputs and outputs)</td></tr>
<tr><td><code>Parameters</code></td><td><code>SoilParameters</code>, <code>WheelParameters</code>
(Table 2), <code>RoverParameters</code> (our choices)</td></tr>
<tr><td><code>Functions</code></td><td><code>slipRatio</code> (Eq. 4), <code>normalStress</code>
(Eqs. 5-6), <code>shearStress</code> (Eqs. 7-10), <code>lateralShear</code> (Ishigami 2007),
<code>contactForces</code> (Eqs. 1-3, 11-13, and Fy), <code>wheelContact</code> (Fz(h) = W solved
inside), <code>wheelForces</code> (every motion regime: reverse, braking, free rolling,
standstill)</td></tr>
<tr><td><code>Components</code></td><td><code>RigidWheel</code> (spin dynamics + contact),
<code>Chassis</code> (pitch-plane body on 6 limbs), <code>SteerableChassis</code> (body in x,
y, yaw with heave, pitch, roll; wheels steered)</td></tr>
<tr><td><code>FMUs</code></td><td>the models exported as FMUs, and only those:
<code>SingleWheel</code>, <code>Rover</code>, <code>RoverBody</code>, <code>Wheel</code>,
<code>SteerableRover</code>, <code>SteerableRoverBody</code></td></tr>
<tr><td><code>Examples</code></td><td><code>SingleWheelStep</code>, <code>RoverOpenLoop</code>,
<code>RoverReconnectedOpenLoop</code>, <code>SteerableRoverTurn</code>, the torque profile
<code>openLoopTorque</code>, and <code>RoverReconnected</code> (body and six wheels wired through
the cut)</td></tr>
</table>

<h4>In a Modelica tool</h4>
<p>Open <code>modelica/RoverTerramechanics/package.mo</code> of the repository (OpenModelica:
<code>loadFile</code>, or File &gt; Open Model/Library File in OMEdit). rover-cosim installed by
pip carries the same files as package data; this prints where:</p>
<pre>
python -c \"from rover_cosim.fmubuild import source
print(source.package_file())\"
</pre>
<p>Every class of <code>Examples</code> with an <code>experiment</code> annotation simulates as
it is.</p>

<h4>From Python</h4>
<p>With rover-cosim installed (it pins rumoca, the Modelica compiler on PyPI), any class loads,
flattened by rumoca, and any example simulates:</p>
<pre>
from rover_cosim.fmubuild import source
model = source.load(\"RoverTerramechanics.FMUs.Rover\")  # flattened
print(model.structure())           # balanced, no algebraic loops
df = source.simulate(\"RoverTerramechanics.Examples.SingleWheelStep\",
                     params={\"W\": 575.0})  # one column per variable
</pre>

<h4>The FMUs</h4>
<p><code>rover-cosim build-fmus</code> (in the repository: <code>make fmus</code>) exports each
class of <code>FMUs</code> as an FMI 2.0 FMU, Model Exchange and Co-Simulation:
<code>FMUs.Wheel</code> becomes <code>fmus/Wheel.fmu</code> with the model identifier
<code>Wheel</code>, and the FMU's variables are the class's, by the same names
(<code>tau</code>, <code>omega</code>, <code>soil.c</code>, <code>wheel.r</code>, ...).
<code>source.fmu_class(\"Wheel\")</code> names the class of an FMU. Options
(<code>--fmi-version 3</code>, <code>--platforms all</code>, <code>--backend omc</code>) and what
every FMU provides: the page <em>FMUs</em> of the documentation site.</p>

<h4>More documentation</h4>
<p>rover-cosim's documentation site (<code>make docs</code>; its pages are the Markdown files in
<code>docs/</code>):</p>
<ul>
<li><em>The terramechanics wheel</em> (<code>docs/guide/wheel.md</code>): the numpy reference
wheel the Modelica functions are checked against, the choices where the paper is silent, the
wheel in every motion regime, the lateral force;</li>
<li><em>FMUs</em> (<code>docs/guide/fmus.md</code>): the FMU table, what every FMU provides, the
binaries for every host;</li>
<li><em>Co-simulation</em> (<code>docs/guide/cosimulation.md</code>): the system files that wire
<code>RoverBody</code>, <code>SteerableRoverBody</code> and six <code>Wheel</code>s;</li>
<li><em>The Modelica library</em> (<code>docs/guide/modelica.md</code>): this guide on the
site;</li>
<li><em>Layout, architecture, lint, benchmarks</em> (<code>docs/design/development.md</code>):
where the exporter, the engine and this package sit in the repository.</li>
</ul>

<h4>Licence and citation</h4>
<p>Apache-2.0, as rover-cosim (<code>LICENSE</code>). Cite rover-cosim and the paper as
<code>CITATION.cff</code> says.</p>
</html>"));
end Overview;
