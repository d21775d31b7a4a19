within RoverTerramechanics.Components;
model Chassis "Rover body in the pitch plane (x, z, pitch) on six vertical compliant limbs, cut at the wheel hubs"
  extends RoverTerramechanics.Interfaces.BodyHubs(final nWheels=2*rover.nAxles);
  parameter RoverTerramechanics.Parameters.RoverParameters rover "Rover mass, geometry and limbs";
  parameter Real slope(unit="rad") = 0 "Slope of the ground along x, positive uphill";
  output Real x(unit="m", start=0, fixed=true) "Position of the centre of gravity";
  output Real v(unit="m/s", start=0, fixed=true) "Forward velocity of the centre of gravity";
  output Real z(unit="m", start=0, fixed=true) "Heave of the centre of gravity from static equilibrium";
  output Real pitch(unit="rad", start=0, fixed=true) "Pitch angle, nose up positive";
  Real w(unit="m/s", start=0, fixed=true) "Heave velocity";
  Real q(unit="rad/s", start=0, fixed=true) "Pitch rate";
  Real deflection[nWheels](each unit="m") "Limb compression";
  Real deflectionRate[nWheels](each unit="m/s") "Limb compression rate";
  Real xHubWorld[nWheels](each unit="m") "Hub position ahead of the centre of gravity";
  Real zHubWorld[nWheels](each unit="m") "Hub height relative to the centre of gravity";
protected
  parameter Real staticDeflection(unit="m") = rover.M*rover.g*cos(slope)/(nWheels*rover.kLimb) "Limb compression at rest";
equation
  der(x) = v;
  der(z) = w;
  der(pitch) = q;
  for j in 1:rover.nAxles loop
    xHubWorld[j] = rover.xLimb[j]*cos(pitch) + rover.hCoG*sin(pitch);
    zHubWorld[j] = rover.xLimb[j]*sin(pitch) - rover.hCoG*cos(pitch);
    xHubWorld[j + rover.nAxles] = rover.xLimb[j]*cos(pitch) + rover.hCoG*sin(pitch) "the right side mirrors the left";
    zHubWorld[j + rover.nAxles] = rover.xLimb[j]*sin(pitch) - rover.hCoG*cos(pitch);
  end for;
  for i in 1:nWheels loop
    deflection[i] = staticDeflection - z - (zHubWorld[i] + rover.hCoG);
    deflectionRate[i] = -w - q*xHubWorld[i];
    W[i] = noEvent(max(rover.kLimb*deflection[i] + rover.dLimb*deflectionRate[i], 0.0));
    v_hub[i] = v - q*zHubWorld[i];
  end for;
  rover.M*der(v) = sum(Fx) - rover.M*rover.g*sin(slope);
  rover.M*der(w) = sum(W) - rover.M*rover.g*cos(slope);
  rover.Iyy*der(q) = sum(xHubWorld[i]*W[i] - zHubWorld[i]*Fx[i] + tau[i] for i in 1:nWheels);
  assert(rover.M > 0, "rover.M: the mass must be > 0 kg");
  assert(rover.g > 0, "rover.g: the gravity must be > 0 m/s2");
  assert(rover.Iyy > 0, "rover.Iyy: the pitch inertia must be > 0 kg.m2");
  assert(rover.hCoG >= 0, "rover.hCoG: the centre of gravity must be at or above the hubs, hCoG >= 0 m");
  assert(rover.kLimb > 0, "rover.kLimb: the limb stiffness must be > 0 N/m");
  assert(rover.dLimb >= 0, "rover.dLimb: the limb damping must be >= 0 N.s/m");
  assert(slope > -1.5707963267948966 and slope < 1.5707963267948966, "slope: must be in (-pi/2, pi/2) rad");
  annotation (Documentation(info="<html>
<p>A rigid body of mass M and pitch inertia Iyy with three limbs per side (limb 1 front,
2 middle, 3 rear; 4-6 mirror them). Each limb is a vertical spring-damper between the body and a
wheel hub that rides at a fixed height over the undisturbed soil; its force is the wheel load
W<sub>i</sub> = max(k&delta;<sub>i</sub> + d d&delta;<sub>i</sub>/dt, 0) (a wheel can lift, not
pull). With hub position p<sub>i</sub> = R(pitch)(x<sub>i</sub>, -h<sub>CoG</sub>) relative to the
centre of gravity:</p>
<ul>
<li>M dv/dt = &Sigma; F<sub>x,i</sub> - M g sin(slope)</li>
<li>M dw/dt = &Sigma; W<sub>i</sub> - M g cos(slope)</li>
<li>Iyy dq/dt = &Sigma; (p<sub>x,i</sub> W<sub>i</sub> - p<sub>z,i</sub> F<sub>x,i</sub> +
&tau;<sub>i</sub>): loads, hub forces below the centre of gravity, and the reaction of the wheel
motors.</li>
</ul>
<p>Driving forward, the hub forces and motor reactions pitch the nose up: the front limbs extend
and unload, the rear limbs compress and load (paper Fig. 10c). On a slope (positive uphill) the body frame is the ground's: the weight's
component along the slope acts on the body, the normal one is carried by the limbs; the hub
forces that hold the body then pitch it and load the downhill limbs. Parameters and their reasoning:
<code>Parameters.RoverParameters</code>.</p>
</html>"));
end Chassis;
