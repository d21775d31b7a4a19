"""Identification of the torque -> slip -> Fx model from step-torque runs (paper Sec. 3).

- ``testbed``: SingleWheel.fmu as an experiment (torque profile in, recorded run out), driven
  through the engine's FMU participant;
  ``reference_plant``: the same test bed on the numpy reference wheel.
- ``sweep``: the (load, torque, slip angle) sweep on local processes, serially or on Dask,
  cached per run.
- ``fits``: first-order tau -> slip fits and their (W, tau) look-up tables, Fx(W, slip) fits,
  Eq. (15); ``model_set``: model.json, the identified models as one typed object with a schema
  version; ``validate``: Table 1 at 275, 575, 875 N; ``figures``: Figs. 5-8;
- ``lateral``: the lateral model Fy(W, beta, slip) and its forms; ``lateral_validation``: its
  Fit at 275, 575, 875 N and 7.5, 12.5 deg; ``lateral_figures``;
  ``make identify`` is the job ``rover_cosim.jobs.identify``.
"""

from rover_cosim.common.identity import require_root

require_root(__name__)

