within RoverTerramechanics.Interfaces;
partial model WheelHub "The wheel side of the cut at a wheel hub: drive torque, load and hub velocity in; contact forces, slip and spin out"
  input Real tau(unit="N.m") "Drive torque applied to the wheel by its motor";
  input Real W(unit="N") "Vertical load on the wheel";
  input Real v_hub(unit="m/s") "Forward speed of the wheel hub";
  input Real v_lat(unit="m/s", start=0) "Speed of the hub to the wheel's left (lateral, in the wheel frame)";
  input Real soilShare(unit="1", min=0, max=1, start=0) "Share of the second soil in the soil under the wheel: 0 the first soil, 1 the second, between them a blend of their parameters";
  input Real rutDepth(unit="m", min=0, start=0) "Depth of the rut a previous wheel left where this one rolls (multi-pass, from a rut participant); 0: virgin soil";
  output Real omega(unit="rad/s", start=0, fixed=true) "Wheel angular velocity";
  output Real slip(unit="1") "Slip ratio, Eq. (4)";
  output Real sinkage(unit="m") "Sinkage at which Fz = W, below the undisturbed surface (a rut's depth included)";
  output Real Fx(unit="N") "Longitudinal force of the soil on the wheel, Eq. (12) when rolling";
  output Real Fz(unit="N") "Vertical force of the soil on the wheel, Eq. (11)";
  output Real Tx(unit="N.m") "Resistance torque of the soil about the axle, Eq. (13) when rolling";
  output Real entryAngle(unit="rad") "Entry angle, Eq. (1), signed with the direction of travel";
  output Real Fy(unit="N") "Lateral force of the soil on the wheel, along its left (Ishigami et al. 2007)";
  output Real slipAngle(unit="rad") "Slip angle of the hub velocity, seen from the direction of travel";
  annotation (Documentation(info="<html>
<p>What one wheel exchanges with the body it carries. Inputs: the motor's drive torque
<code>tau</code> [N&middot;m], the load <code>W</code> [N] the limb presses the wheel into the
soil with, and the hub velocity in the wheel frame, <code>v_hub</code> [m/s] along the wheel and
<code>v_lat</code> [m/s] to its left (start 0: optional, a pitch-plane system leaves it
unconnected), and the share of the second soil under the wheel, <code>soilShare</code> [1] (start 0:
optional, from a soil map; 0 is the first soil), and the depth of the rut a previous wheel left under
it, <code>rutDepth</code> [m] (start 0: optional, from a rut participant; 0 is virgin soil). Outputs: the soil's forces on the wheel <code>Fx</code> (forward, what the hub
passes on to the body), <code>Fy</code> (to the wheel's left) and <code>Fz</code> [N] (= W), the
resistance torque <code>Tx</code> [N&middot;m], the slip ratio <code>slip</code> (Eq. 4), the
slip angle <code>slipAngle</code> [rad], the <code>sinkage</code> [m], the entry angle
<code>entryAngle</code> [rad] and the spin <code>omega</code> [rad/s].</p>
<p>Physics: <code>Components.RigidWheel</code>; FMU: <code>FMUs.Wheel</code>.</p>
</html>"));
end WheelHub;
