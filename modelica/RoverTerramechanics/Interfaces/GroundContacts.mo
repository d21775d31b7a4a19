within RoverTerramechanics.Interfaces;
partial model GroundContacts "The ground under each hub of the steerable rover relative to its ground plane: height, its rate and the local gradients (inputs; all 0 on the plane itself)"
  parameter Integer nWheels = 6 "Number of wheels (structural: an FMU is built for one value; wheels 1..nWheels/2 on the left from front to rear, the others mirror them on the right)";
  input Real groundHeight[nWheels](each unit="m", each start=0) "Height of the ground under each hub above the ground plane (TerrainParameters), along the plane's normal";
  input Real groundHeightRate[nWheels](each unit="m/s", each start=0) "Rate of groundHeight as the hub moves over the ground";
  input Real groundGradientAlong[nWheels](each unit="1", each start=0) "Gradient of the ground under each hub against the plane, along the body's heading (uphill ahead > 0)";
  input Real groundGradientLateral[nWheels](each unit="1", each start=0) "Gradient of the ground under each hub against the plane, to the body's left (uphill to the left > 0)";
  annotation (Documentation(info="<html>
<p>A height map over the ground plane of <code>Parameters.TerrainParameters</code>, given hub by
hub (limbs 1-3 front, middle, rear on the left, 4-6 on the right) by a terrain participant that
knows the hubs' positions: the height h<sub>i</sub> [m] of the ground under hub i above the plane,
its rate dh<sub>i</sub>/dt [m/s] and its gradients s<sub>x,i</sub>, s<sub>y,i</sub> [1] along and
across the body's heading. With every input 0 the ground is the plane.</p>
<p>Used by <code>Components.SteerableChassis</code> (and so <code>FMUs.SteerableRoverBody</code>) and
<code>FMUs.SteerableRover</code>; <code>rover_cosim.terramechanics.terrain.HeightMap</code> computes
them from a grid file.</p>
</html>"));
end GroundContacts;
