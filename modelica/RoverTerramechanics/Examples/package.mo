within RoverTerramechanics;
package Examples "Runnable experiments: torque step on the test bed, open-loop rover runs"
  annotation (Documentation(info="<html>
<p>Each example binds every input by an equation and carries an <code>experiment</code>
annotation, so any Modelica tool (and rumoca) can simulate it as is. The inputs are smooth
functions of time, so the examples have no events.</p>
</html>"));
end Examples;
