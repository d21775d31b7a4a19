within RoverTerramechanics;
package Functions "Terramechanics of a rigid wheel on loose soil as event-free functions (paper Sec. 2)"
  annotation (Documentation(info="<html>
<p>Pure functions, no events and no algebraic loops: <code>slipRatio</code> (Eq. 4),
<code>normalStress</code> (Eqs. 5-6), <code>shearStress</code> (Eqs. 7-10),
<code>contactForces</code> (Eqs. 1-3 and 11-13 by quadrature) and <code>wheelContact</code>,
which solves Fz(h) = W for the sinkage h with a bounded number of safeguarded steps, so that a
model using it has no nonlinear algebraic equation.</p>
<p>Angles are measured from the downward vertical through the axle, positive towards the
direction of travel: the entry angle is positive, the exit angle negative.</p>
</html>"));
end Functions;
