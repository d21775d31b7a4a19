"""Monte Carlo over soil uncertainty (``rover-cosim montecarlo``, ``make montecarlo``): study
files (study.py) and their seeded samples (sampling.py)."""
