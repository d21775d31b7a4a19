within RoverTerramechanics.UsersGuide;
class ParametersNotInPaper "Parameters the paper does not give: values and reasoning"
  annotation (Documentation(info="<html>
<p>All in one place, <code>Parameters.RoverParameters</code> and
<code>Parameters.WheelParameters</code>, each with its reasoning in the documentation
annotation:</p>
<table border=\"1\" cellpadding=\"3\">
<tr><th>parameter</th><th>value</th><th>reasoning</th></tr>
<tr><td>wheel inertia <code>J</code></td><td>0.5 kg&middot;m<sup>2</sup></td><td>uniform 8 kg
disc of radius 0.355 m</td></tr>
<tr><td>limb positions <code>xLimb</code></td><td>+1.5, 0, -1.5 m</td><td>ATHLETE's hexagonal
frame is about 2.75 m across; wheels of a side ahead of, under and behind the CoG, symmetric so
static loads are equal (424 N)</td></tr>
<tr><td>CoG height <code>hCoG</code></td><td>1.0 m above the hubs</td><td>ATHLETE's deck stands
about 1.5-2 m over the ground when driving</td></tr>
<tr><td>pitch inertia <code>Iyy</code></td><td>1120 kg&middot;m<sup>2</sup></td><td>uniform box
2.75 m &times; 1.0 m: M(2.75<sup>2</sup> + 1<sup>2</sup>)/12</td></tr>
<tr><td>half track <code>yLimb</code></td><td>1.5 m</td><td>steerable rover: a 3 m &times; 3 m
footprint, about the splayed ATHLETE; left and right symmetric</td></tr>
<tr><td>roll inertia <code>Ixx</code></td><td>1120 kg&middot;m<sup>2</sup></td><td>box 2.75 m
wide &times; 1.0 m high</td></tr>
<tr><td>yaw inertia <code>Izz</code></td><td>1980 kg&middot;m<sup>2</sup></td><td>deck 2.75 m
&times; 2.75 m: M(2.75<sup>2</sup> + 2.75<sup>2</sup>)/12</td></tr>
<tr><td>limb stiffness <code>kLimb</code></td><td>2.0e4 N/m</td><td>21 mm static deflection;
heave 1.4 Hz, pitch 2.0 Hz</td></tr>
<tr><td>limb damping <code>dLimb</code></td><td>2.0e3 N&middot;s/m</td><td>damping ratio 0.44
heave, 0.63 pitch</td></tr>
<tr><td>slip regularisation <code>vEps</code></td><td>1e-3 m/s</td><td>slip defined at rest;
exact Eq. (4) above 1 mm/s</td></tr>
<tr><td>transition speed <code>vHold</code></td><td>1e-3 m/s</td><td>the paper's forces exactly
from 1 mm/s on, where the slip ratio is Eq. (4) itself; below it the static regime</td></tr>
<tr><td>stick speed <code>vStick</code></td><td>1e-4 m/s</td><td>static shear at 76 % of its
limit at 0.1 mm/s slip speed: a holding wheel creeps its spin by a fraction of that while the
hub stays (60 s on a 20&deg; slope: the carriage moves &lt; 1 &micro;m)</td></tr>
</table>
<p>The limbs are vertical spring-dampers; the hubs ride at a fixed height over the undisturbed
soil (the sinkage, a few cm, is not fed back into the limb length: that would close a nonlinear
loop between load and sinkage). A limb force cannot pull: W = max(k&middot;&delta; +
d&middot;d&delta;/dt, 0).</p>
</html>"));
end ParametersNotInPaper;
