within RoverTerramechanics;
package FMUs "The models exported as FMUs: each class here is fmus/<Name>.fmu, with the model identifier <Name>"
  annotation (Documentation(info="<html>
<p>The top levels of the six FMUs that <code>make fmus</code> (<code>rover-cosim
build-fmus</code>) builds, and only those: the class <code>FMUs.Wheel</code> becomes
<code>fmus/Wheel.fmu</code> with the model identifier <code>Wheel</code>, and the FMU's public
variables are this class's inputs, outputs, parameters and states under the names they have
here (<code>tau</code>, <code>soil.c</code>, <code>wheel.r</code>, ...). A sub-package of their
own, so that what an FMU is made from is visible in the package tree and the exporter maps an
FMU to its class in one place (<code>rover_cosim.fmubuild.source.fmu_class</code>).</p>
<ul>
<li><code>SingleWheel</code>: the single-wheel test bed of the identification (paper Sec. 3).</li>
<li><code>Rover</code>: the six-limb rover in the pitch plane, monolithic (Sec. 4).</li>
<li><code>RoverBody</code> and <code>Wheel</code>: the rover cut at the wheel hubs for
co-simulation (the cut: <code>Interfaces</code>); <code>Examples.RoverReconnected</code> wires
them back together.</li>
<li><code>SteerableRover</code>: the rover free in the plane, every wheel driven and steered;
<code>SteerableRoverBody</code>: its body alone, for co-simulation with six <code>Wheel</code>s.</li>
</ul>
<p>Inputs, outputs and parameters of each: <code>UsersGuide.Models</code>.</p>
</html>"));
end FMUs;
