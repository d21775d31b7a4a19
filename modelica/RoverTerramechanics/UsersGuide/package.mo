within RoverTerramechanics;
package UsersGuide "User's Guide"
  annotation (DocumentationClass=true, Documentation(info="<html>
<p><code>RoverTerramechanics</code> is the plant physics of Yoshikawa, Oda, Nonaka and Sekiguchi,
<em>Modeling and Simulation of Wheel Driving Systems based on Terramechanics for Planetary
Exploration Rover using Modelica</em> (12th International Modelica Conference, Prague, 2017), in
Modelica: the Wong-Reece/Ishigami rigid wheel on loose lunar soil, the single-wheel test bed of
the identification and the six-limb ATHLETE-like rover. It is the single source from which
rover-cosim builds its FMUs. This guide:</p>
<ol>
<li><a href=\"modelica://RoverTerramechanics.UsersGuide.Overview\">Overview</a>: the
package's structure; opening it in a Modelica tool, loading and simulating it from Python,
building its FMUs; where the rest of the documentation is.</li>
<li><a href=\"modelica://RoverTerramechanics.UsersGuide.Physics\">Physics</a>: how the physics
is written (no events, no algebraic loops), the quadrature, every motion regime, the parameter
checks.</li>
<li><a href=\"modelica://RoverTerramechanics.UsersGuide.Models\">Models</a>: every FMU model's
inputs, outputs, states and parameters, and the parameter records.</li>
<li><a href=\"modelica://RoverTerramechanics.UsersGuide.ParametersNotInPaper\">Parameters the
paper does not give</a>: each with its value and reasoning.</li>
<li><a href=\"modelica://RoverTerramechanics.UsersGuide.Examples\">Examples</a>: the runnable
experiments.</li>
<li><a href=\"modelica://RoverTerramechanics.UsersGuide.ReleaseNotes\">Release notes</a>:
what changed, with the classes that moved.</li>
</ol>
</html>"));
end UsersGuide;
