"""The pipeline jobs behind the Makefile targets, one module each: ``fig3``, ``identify``,
``simulate``, ``cosim_study``. A job computes, writes all of its files or none, and returns a
typed result; the command line (``rover_cosim.cli``) only parses arguments and prints."""
