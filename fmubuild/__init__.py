"""FMU build from the Modelica source in ``modelica/``.

So far: ``fmubuild.source`` locates the Modelica package, loads its classes with rumoca (the
Modelica front end) and runs rumoca's own simulation of them, the reference the FMUs are
checked against. The exporter itself (CasADi code generation and the FMI 2.0 runtime) comes next.
"""
