"""The system a command names: a system file, an SSP archive, one FMU, or a shipped example."""

from __future__ import annotations

from pathlib import Path

from rover_cosim.orchestrator.examples import examples

#: Example systems shipped with the package (FMU paths relative to --fmu-dir, default fmus/).
EXAMPLES = examples()


def system_path(system: str, fmu_dir: Path | None) -> tuple[Path, Path | None]:
    """The system file and FMU folder of ``system`` and ``fmu_dir`` (a shipped example by name,
    unless a file of that name exists)."""
    path = Path(system)
    if not path.is_file() and system in EXAMPLES:
        path, fmu_dir = EXAMPLES[system], fmu_dir or Path("fmus")
    return path, fmu_dir
