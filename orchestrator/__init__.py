"""Pipeline driver: the ``rover-cosim`` command and the jobs behind the Makefile targets."""
