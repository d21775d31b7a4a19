"""The pipeline jobs behind the Makefile targets, one module each: ``fig3``, ``identify``,
``simulate`` (the paper's straight run), ``path_following`` (the steerable rover, run by
``simulate`` after the straight run), ``cosim_study``, ``montecarlo`` (a package: study files,
sampling, runs, metrics, sensitivity, figures). ``plants`` builds the plants they run (the
rover's hub wiring, written once) through the engine's SystemBuilder. A job computes, writes all of
its files or none, and returns a typed result; the command line (``rover_cosim.cli``) only parses
arguments and prints."""
