"""``tlmpc stage NAME DIR``: run one stage alone on the input artifacts of an output directory."""

from __future__ import annotations

import argparse
from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING, Any, TextIO

if TYPE_CHECKING:
    from tlmpc.pipeline.stages import CompileResult

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
    from tlmpc.io.outdir import MARKER, is_tlmpc_output, output_lock, replace_files
    from tlmpc.io.report import Reporter
    from tlmpc.pipeline.stages import run_stage_from_artifacts
    from tlmpc.reactive.unrealizable import UnrealizableError

    if not args.directory.is_dir():
        raise UsageError(
            error(
                "U020",
                f"{args.directory} is not a directory: there are no artifacts to read",
                hint="pass the directory given to `tlmpc compile -o`",
                file=str(args.directory),
            )
        )
    target: Path = args.out if args.out is not None else args.directory
    if not target.is_dir():
        raise UsageError(
            error("U074", f"{target} is not a directory", hint="create it first", file=str(target))
        )
    reporter = Reporter.for_args(args, out, err)
    # the folder written into is held from the reading to the last file, as `tlmpc compile`
    # holds it: a compile replacing it meanwhile would drop what this stage wrote
    with output_lock(target):

        def refuse_foreign(names: Iterable[str]) -> None:
            if args.out is None or args.force or is_tlmpc_output(target):
                return
            existing = sorted(name for name in names if (target / name).exists())
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

        try:
            result = run_stage_from_artifacts(args.name, args.directory)
        except UnrealizableError as failure:
            # as `tlmpc compile` does: the environment's winning play is written (tlmpc
            # plot / view draw it), and the answer is still exit 1
            refuse_foreign(failure.produced)
            replace_files(
                {target / name: _bytes(failure.artifacts[name]) for name in failure.produced}
            )
            if not args.json and failure.produced:
                reporter.note(
                    f"{args.name}: wrote {', '.join(sorted(failure.produced))} to {target} "
                    "(the environment's winning play: tlmpc plot / tlmpc view)"
                )
            raise
        reporter.diagnose(result.warnings)
        refuse_foreign(result.artifacts)
        files = {target / name: _bytes(content) for name, content in result.artifacts.items()}
        summary = _summary_after(target, result)
        if summary is not None:
            files[target / "summary.json"] = _bytes(summary)
        # all or none: a refused or failed file leaves the others as they were
        replace_files(files)
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


def _summary_after(target: Path, result: CompileResult) -> dict[str, Any] | None:
    """The summary.json of ``target`` with what this stage determined replaced: its own stage
    record, the plan or the verdict it wrote, its summary keys; None when ``target`` holds no
    summary (or one that does not match its schema, which is left as it is)."""
    from tlmpc.base.errors import UsageError
    from tlmpc.io.artifacts import read_artifact

    path = target / "summary.json"
    if not path.is_file():
        return None
    try:
        summary = read_artifact(path, "summary")
    except UsageError:
        return None
    fresh = result.summary()
    record = fresh["stages"][0]
    names = [stage["name"] for stage in summary["stages"]]
    if record["name"] in names:
        summary["stages"][names.index(record["name"])] = record
    else:
        summary["stages"].append(record)
    summary["total_seconds"] = round(sum(stage["seconds"] for stage in summary["stages"]), 6)
    summary["artifacts"] = sorted({*summary["artifacts"], *result.artifacts})
    for key in ("plan", "verdict", *result.extras):
        if key in fresh:
            summary[key] = fresh[key]
    return summary


def _plain(value: Any) -> Any:
    """A stage size as JSON: numbers and strings as they are, anything else as text."""
    if hasattr(value, "item"):  # a numpy scalar
        value = value.item()
    if isinstance(value, bool | int | float | str) or value is None:
        return value
    return str(value)
