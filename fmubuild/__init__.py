"""FMU build from the Modelica source in ``modelica/`` (the built-in backend; issue 4, in progress).

- ``fmubuild.source``: locates the Modelica package, loads classes with rumoca (the Modelica front
  end) and runs rumoca's own simulation, the reference the FMUs are checked against.
- ``fmubuild.expressions``, ``fmubuild.functions``: rumoca flat expressions and Modelica function
  algorithms → CasADi.
- ``fmubuild.ode``: a flat model → explicit ODE xdot = f(t, x, u, p), y = g(t, x, u, p) by matching
  and BLT, with clear errors for what it cannot translate.

Not yet: C code generation, the FMI 2.0 runtime, modelDescription.xml, packaging, ``make fmus``.
"""
