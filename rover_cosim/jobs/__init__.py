"""The pipeline jobs behind the Makefile targets, one module each: ``fig3``, ``identify``,
``simulate`` (the paper's straight run), ``path_following`` (the steerable rover, run by
``simulate`` after the straight run), ``terrain`` (side slopes, a crater, a soil crossing; run by
``simulate`` after the paths), ``cosim_study``, ``montecarlo`` (a package: study files, sampling,
runs, metrics, sensitivity, figures), ``estimate_soil`` (soil estimation and test-bed data).
``campaign`` is the skeleton the closed-loop jobs share (their runs, record and files); ``plants``
builds the plants they run (the rover's hub wiring, written once) through the engine's
SystemBuilder; ``ground`` holds the ground and soil participants; ``straight_run`` the straight
run's time grid and the check of its options, light enough for the command line to refuse a bad
option before it imports a job. A job computes, refuses what it cannot run, writes all of its
files or none, and returns a typed result; the command line (``rover_cosim.cli``) only parses
arguments, calls the job and prints."""
