within RoverTerramechanics;
package Examples "Runnable experiments: torque step on the test bed, open-loop rover runs"
  annotation (Documentation(info="<html>
<p>Each example binds every input by an equation and carries an <code>experiment</code>
annotation, so any Modelica tool (and rumoca) can simulate it as is. The inputs are smooth
functions of time, so the examples have no events. <code>RoverReconnected</code> is the exception
that is not run on its own: the co-simulated rover as one model, with the inputs of
<code>FMUs.Rover</code>, run by <code>RoverReconnectedOpenLoop</code>.</p>
</html>"));
end Examples;
