"""``rover-cosim export-ssp``: a system file as an SSP 1.0 archive."""

from __future__ import annotations

import argparse
from pathlib import Path

from .command import Command, no_result_set
from .options import fail, output_file, path, path_text
from .systems import EXAMPLES, system_path


def arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("system", type=path_text,
                        help="system file, or the name of a shipped example: " + ", ".join(EXAMPLES))
    parser.add_argument("-o", "--output", type=path, required=True, help="the .ssp archive to write")
    parser.add_argument("--overwrite", action="store_true",
                        help="replace --output even if it is not an archive this command wrote")
    parser.add_argument("--fmu-dir", type=path, default=None,
                        help="folder for relative FMU paths (default: the system file's folder; fmus/ for examples)")


def owns(target: Path) -> bool:
    """Whether ``target`` is an archive this command wrote (its annotation names us)."""
    import zipfile

    try:
        with zipfile.ZipFile(target) as archive:
            return b"org.rover-cosim" in archive.read("SystemStructure.ssd")
    except zipfile.BadZipFile:
        return False


def run(args: argparse.Namespace) -> int:
    from rover_cosim.orchestrator.ssp import SspError, export_ssp, validate_ssd
    from rover_cosim.orchestrator.system import SystemFileError, load_system

    system_file, fmu_dir = system_path(args.system, args.fmu_dir)
    if not output_file(args.output, "export-ssp", 0.0, owns, args.overwrite, "-o"):
        return 2
    try:
        exported = export_ssp(load_system(system_file, fmu_dir=fmu_dir), args.output)
        validate_ssd(exported.path)
    except (SystemFileError, SspError) as error:
        fail("export-ssp", str(error))
        return 2
    print(f"wrote {exported.path} (SystemStructure.ssd valid against the SSP 1.0 schema)")
    if exported.folded:
        print(f"constant blocks {', '.join(exported.folded)}: folded into the start values of the inputs they drive")
    if exported.external:
        print(f"blocks {', '.join(exported.external)}: Python, kept in an org.rover-cosim annotation (rover-cosim "
              "run restores them); other tools see their signals as the system's connectors <block>_<signal>")
    return 0


COMMAND = Command(
    "export-ssp", help="write a system file (TOML) as an SSP 1.0 archive (.ssp) that FMPy, libcosim and OMSimulator "
    "read",
    summary="Write a system file as an SSP 1.0 archive that FMPy, libcosim and OMSimulator read.",
    examples=("rover-cosim export-ssp rover_cosim --fmu-dir fmus -o rover.ssp",),
    arguments=arguments, run=run, result_sets=no_result_set, owns=owns)
