"""``tlmpc stage NAME DIR``: run one stage alone on the input artifacts of an output directory."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any, TextIO

NAME = "stage"
HELP = "run one compiler stage alone from its input artifacts"
DESCRIPTION = """\
Run the stage NAME (load is the only stage that reads the mission file; every other stage
reads its inputs from the artifacts in DIR, each checked against its schema) and write the
artifacts it produces into DIR, or into OUT with -o.  Each file is replaced atomically, so a
failed run leaves DIR as it was.  For example, after editing controllers.json by hand,
`tlmpc stage simulate out` re-simulates and `tlmpc stage verify out` re-checks."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the command's flags."""
    from tlmpc.pipeline.stages import STAGES

    names = [stage.name for stage in STAGES if stage.requires]
    parser.add_argument("name", choices=names, metavar="NAME", help="one of: %(choices)s")
    parser.add_argument("directory", type=Path, metavar="DIR", help="a tlmpc output directory")
    parser.add_argument(
        "-o", "--out", type=Path, help="write the new artifacts here instead (an existing dir)"
    )
    parser.add_argument(
        "--force",
        action="store_true",
        help="with -o: replace files of the same names in a folder tlmpc did not write",
    )
    parser.add_argument("--json", action="store_true", help="print the stage report as JSON")


def _bytes(content: Any) -> bytes:
    from tlmpc.io.artifacts import dumps

    if isinstance(content, bytes):
        return content
    if isinstance(content, str):
        return content.encode("utf-8")
    return dumps(content).encode("utf-8")


def run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Run the stage and write what it produced."""
    from tlmpc.base.errors import EXIT_OK, UsageError, error
    from tlmpc.io.outdir import MARKER, is_tlmpc_output, replace_file
    from tlmpc.io.report import Reporter
    from tlmpc.pipeline.stages import run_stage_from_artifacts

    target: Path = args.out if args.out is not None else args.directory
    if not target.is_dir():
        raise UsageError(
            error("U074", f"{target} is not a directory", hint="create it first", file=str(target))
        )
    reporter = Reporter.for_args(args, out, err)
    result = run_stage_from_artifacts(args.name, args.directory)
    reporter.diagnose(result.warnings)
    if args.out is not None and not args.force and not is_tlmpc_output(target):
        existing = sorted(name for name in result.artifacts if (target / name).exists())
        if existing:
            raise UsageError(
                error(
                    "U012",
                    f"{target} is not a tlmpc output (it has no {MARKER} file) and holds "
                    f"{', '.join(existing)}, which this stage would replace",
                    hint="choose another -o, or pass --force to replace those files",
                    file=str(target),
                )
            )
    for name, content in result.artifacts.items():
        replace_file(target / name, _bytes(content))
    report = result.reports[0]
    if not args.json:
        written = ", ".join(sorted(result.artifacts)) or "nothing"
        reporter.note(f"{report.name}: {report.seconds:.3f} s; wrote {written} to {target}")
    document = {
        "stage": report.name,
        "seconds": report.seconds,
        "sizes": {key: _plain(value) for key, value in report.sizes.items()},
        "artifacts": sorted(result.artifacts),
        "directory": str(target),
    }
    return reporter.finish(EXIT_OK, document)


def _plain(value: Any) -> Any:
    """A stage size as JSON: numbers and strings as they are, anything else as text."""
    if hasattr(value, "item"):  # a numpy scalar
        value = value.item()
    if isinstance(value, bool | int | float | str) or value is None:
        return value
    return str(value)
