within RoverTerramechanics.Parameters;
record RoverParameters "ATHLETE-like rover body: mass, gravity, inertia, geometry, limb compliance"
  parameter Real M(unit="kg") = 1570 "Total rover mass (paper Sec. 4), carried by the six limbs";
  parameter Real g(unit="m/s2") = 1.62 "Lunar gravity (paper Sec. 4)";
  parameter Real Iyy(unit="kg.m2") = 1120 "Pitch moment of inertia about the centre of gravity";
  parameter Integer nAxles = 3 "Number of wheels on each side (structural: an FMU is built for one value): wheels 1..nAxles on the left from front to rear, nAxles+1..2 nAxles mirror them on the right";
  parameter Real xLimb[nAxles](each unit="m") = {1.5, 0.0, -1.5} "Longitudinal wheel-hub position of the limbs of a side from front to rear, relative to the centre of gravity";
  parameter Real hCoG(unit="m") = 1.0 "Height of the centre of gravity above the wheel hubs";
  parameter Real yLimb(unit="m") = 1.5 "Lateral wheel-hub position of the limbs of a side (half the track width): limbs 1-3 at +yLimb (left), 4-6 at -yLimb (right); used by the steerable rover";
  parameter Real Ixx(unit="kg.m2") = 1120 "Roll moment of inertia about the centre of gravity (steerable rover)";
  parameter Real Izz(unit="kg.m2") = 1980 "Yaw moment of inertia about the centre of gravity (steerable rover)";
  parameter Real kLimb(unit="N/m") = 2.0e4 "Vertical stiffness of one limb";
  parameter Real dLimb(unit="N.s/m") = 2.0e3 "Vertical damping of one limb";
  annotation (Documentation(info="<html>
<p>The paper gives only the mass (1570 kg) and the gravity (1.62 m/s<sup>2</sup>). Every other
rover parameter is chosen here, in one place:</p>
<table border=\"1\" cellpadding=\"3\">
<tr><th>parameter</th><th>value</th><th>source or reasoning</th></tr>
<tr><td>nAxles</td><td>3</td><td>wheels per side, six in all (the paper's rover). Structural: it sizes
the arrays of the rover models, so an FMU is built for one value; <code>rover-cosim</code> builds the
rover FMUs for another rover's count on first use (<code>fmus/wheels&lt;N&gt;/</code>). Wheels 1..nAxles
are the left side from front to rear, nAxles+1..2 nAxles mirror them on the right.</td></tr>
<tr><td>xLimb</td><td>+1.5, 0, -1.5 m</td><td>ATHLETE's hexagonal frame is about 2.75 m across
(JPL); with the legs splayed the wheels of a side sit about 1.5 m ahead of, under, and behind the
centre. Limbs 1-3 are front, middle and rear of one side; limbs 4-6 mirror them at the same x.
Front and rear symmetric about the CoG so that the static loads are equal (M g / 6 = 424 N, the
paper's nominal load).</td></tr>
<tr><td>hCoG</td><td>1.0 m</td><td>ATHLETE's deck stands roughly 1.5-2 m above the ground in its
driving posture; with 0.355 m wheels a CoG 1.0 m above the hubs is a middle value. It sets the
load transfer under acceleration (paper Fig. 10c).</td></tr>
<tr><td>Iyy</td><td>1120 kg&middot;m<sup>2</sup></td><td>uniform box 2.75 m long and 1.0 m
high: M (2.75<sup>2</sup> + 1.0<sup>2</sup>) / 12.</td></tr>
<tr><td>yLimb</td><td>1.5 m</td><td>half the track width of the steerable rover: with the
wheels of a side at x = +1.5, 0, -1.5 m the footprint is a 3 m square, about the splayed ATHLETE
(hexagonal frame 2.75 m across, legs reaching outwards); left and right symmetric so that the
static loads stay equal. The pitch-plane rover does not use it.</td></tr>
<tr><td>Ixx</td><td>1120 kg&middot;m<sup>2</sup></td><td>roll: the same box seen from the front,
2.75 m wide and 1.0 m high: M (2.75<sup>2</sup> + 1.0<sup>2</sup>) / 12.</td></tr>
<tr><td>Izz</td><td>1980 kg&middot;m<sup>2</sup></td><td>yaw: a 2.75 m by 2.75 m deck,
M (2.75<sup>2</sup> + 2.75<sup>2</sup>) / 12.</td></tr>
<tr><td>kLimb</td><td>2.0e4 N/m</td><td>static deflection 21 mm under 424 N; heave mode
sqrt(6 k / M) = 1.4 Hz, pitch mode 2.0 Hz: a compliant but not floppy limb, slow enough that
the wheel spin dynamics stay the fastest physics.</td></tr>
<tr><td>dLimb</td><td>2.0e3 N&middot;s/m</td><td>damping ratio 0.44 in heave and 0.63 in
pitch.</td></tr>
</table>
<p>Where the hubs sit: the limbs are vertical spring-dampers between the body and hubs that ride
at a fixed height above the undisturbed soil. The wheel sinkage (a few cm, changing by less than
a centimetre during a run) is not fed back into the limb length: doing so would close a
nonlinear algebraic loop between load and sinkage.</p>
</html>"));
end RoverParameters;
