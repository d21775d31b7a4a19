within RoverTerramechanics.UsersGuide;
class ReleaseNotes "Release notes"
  annotation (Documentation(info="<html>
<p>The package's version is rover-cosim's (the <code>version</code> annotation of
<code>RoverTerramechanics</code>); rover-cosim's <code>CHANGELOG.md</code> lists every change for
its users. For a Modelica user:</p>

<h4>Unreleased</h4>
<ul>
<li>The leg-wheel rover (<code>UsersGuide.LegWheelRover</code>): <code>Components.Limb</code>,
<code>Components.LegWheelChassis</code>, <code>Parameters.LimbParameters</code>,
<code>Parameters.LegWheelParameters</code>, the FMUs <code>LegWheelRover</code> and
<code>LegWheelRoverBody</code>, <code>Examples.LimbKinematics</code> and
<code>Examples.LegWheelStance</code>. The other models are unchanged. <code>LegWheelChassis</code>
takes the set-points' rates (<code>hipYawRate</code> ... <code>ankleRollRate</code>, start 0): a model
that instantiates it binds them (<code>zeros(6)</code> where its limbs hold still).</li>
<li>The models exported as FMUs moved into the sub-package <code>FMUs</code>, and
<code>RoverReconnected</code> (not an FMU) into <code>Examples</code>. A model of your own that
uses them changes its class names; the FMUs keep their file names, model identifiers and every
variable name:
<table border=\"1\" cellpadding=\"3\">
<tr><th>before</th><th>now</th></tr>
<tr><td><code>RoverTerramechanics.SingleWheel</code></td><td><code>RoverTerramechanics.FMUs.SingleWheel</code></td></tr>
<tr><td><code>RoverTerramechanics.Rover</code></td><td><code>RoverTerramechanics.FMUs.Rover</code></td></tr>
<tr><td><code>RoverTerramechanics.RoverBody</code></td><td><code>RoverTerramechanics.FMUs.RoverBody</code></td></tr>
<tr><td><code>RoverTerramechanics.Wheel</code></td><td><code>RoverTerramechanics.FMUs.Wheel</code></td></tr>
<tr><td><code>RoverTerramechanics.SteerableRover</code></td><td><code>RoverTerramechanics.FMUs.SteerableRover</code></td></tr>
<tr><td><code>RoverTerramechanics.SteerableRoverBody</code></td><td><code>RoverTerramechanics.FMUs.SteerableRoverBody</code></td></tr>
<tr><td><code>RoverTerramechanics.RoverReconnected</code></td><td><code>RoverTerramechanics.Examples.RoverReconnected</code></td></tr>
</table></li>
<li>New package <code>Interfaces</code>: the signals of the cut at the wheel hubs, declared once
(<code>WheelHub</code>, <code>BodyHubs</code>, <code>SteerableBodyHubs</code>) and the rover's
own inputs and outputs (<code>PitchPlaneRover</code>), extended by the components and the FMU
models. The flattened models are unchanged.</li>
<li>New package <code>UsersGuide</code>: this guide, which replaces
<code>modelica/README.md</code>.</li>
</ul>
</html>"));
end ReleaseNotes;
