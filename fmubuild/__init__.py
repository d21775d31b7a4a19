"""FMU build from the Modelica source in ``modelica/`` (``rover_cosim.fmubuild``).

- ``fmubuild.source``: locates the Modelica package, loads classes with rumoca (the Modelica front
  end) and runs rumoca's own simulation, the reference the FMUs are checked against.
- ``fmubuild.expressions``, ``fmubuild.functions``: rumoca flat expressions and Modelica function
  algorithms → CasADi.
- ``fmubuild.ode``: a flat model → explicit ODE xdot = f(t, x, u, p), y = g(t, x, u, p) by matching
  and BLT, with clear errors for what it cannot translate.
- ``fmubuild.codegen``: the ODE → C (CasADi) and the value-reference layout;
  ``fmubuild.description``: modelDescription.xml (units via ``rover_cosim.common.units``).
- ``fmubuild.runtime``: the FMI 2.0 C runtime (ME + CS, Rosenbrock integrator) the FMUs link.
- ``fmubuild.elementary``: ``--elementary own``, the FMUs' own exp, log, sin, ... (``runtime/elementary.h``,
  its constants from ``fmubuild.elementary_constants``): the same bits on every host.
- ``fmubuild.artifact``: what an FMU is made from (input digest) and its build record;
  ``fmubuild.build``: compile and package, incremental and atomic; ``fmubuild.omc``: the
  OpenModelica backend.
"""

from rover_cosim.common.identity import require_root

require_root(__name__)

