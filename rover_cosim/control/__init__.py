"""Closed-loop rover control (paper Sec. 4): ``controller``, the inverse-identified-model
controller as an engine block; ``figures``, Fig. 10. The 20 s runs are the ``simulate`` job
(``rover_cosim.jobs.simulate``)."""
