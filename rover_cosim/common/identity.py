"""One identity per class: the layer folders at the repository's top level (``orchestrator/``,
``terramechanics/``, ...) are linked into the one import root, ``rover_cosim``. Imported by their
folder name (``import orchestrator`` from a checkout, where the working folder is on sys.path) they
would load a second copy of every module, whose classes and exceptions are not the package's
(an ``except rover_cosim.orchestrator.participants.RunError`` would not catch ``orchestrator``'s)."""

from __future__ import annotations


def require_root(name: str) -> None:
    """ImportError unless the package ``name`` is imported under ``rover_cosim``."""
    if name.partition(".")[0] != "rover_cosim":
        raise ImportError(f"import rover_cosim.{name}, not {name}: the folder {name}/ is part of the rover_cosim "
                          "package, and importing it by its folder name would load a second copy of it whose "
                          "classes are not rover_cosim's")
