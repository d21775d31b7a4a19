"""Closed-loop rover control (paper Sec. 4): the inverse-identified-model controller as an
orchestrator block (``control.controller``), the 20 s runs on the monolithic and the
co-simulated rover (``control.simulate``, ``make simulate``) and the HTML report
(``control.report``, ``make report``)."""
