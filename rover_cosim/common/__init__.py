"""Helpers every layer may import (and that import nothing else of ours): writing results with
their provenance (``outputs``), unit strings in SI base units (``units``) and the paper's
constants (``paper``)."""
