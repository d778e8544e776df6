"""``tlmpc new TEMPLATE [-o FILE]``: write a mission to start from."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TextIO

NAME = "new"
HELP = "write a mission template (reach-avoid, patrol, map) to start from"
DESCRIPTION = """\
Write a small mission of the kind TEMPLATE names, ready to edit: reach-avoid (go somewhere
without entering a region, come back), patrol (visit places again and again) or map (a mission
on a ROS occupancy-grid map).  The file starts with a yaml-language-server line naming the
mission schema installed with tlmpc, so editors with a YAML language server (VS Code's YAML
extension, Neovim, Helix ...) complete and check the keys as you type.  Without -o the mission
is printed.  An existing file is never overwritten (exit 2)."""

TEMPLATES = ("reach-avoid", "patrol", "map")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the command's flags."""
    parser.add_argument("template", choices=TEMPLATES, help="which mission to start from")
    parser.add_argument("-o", "--output", type=Path, help="the file to write (default: print)")


def schema_line() -> str:
    """The modeline that points a YAML language server at the installed mission schema."""
    from tlmpc.io.schema_check import schema_dir

    return f"# yaml-language-server: $schema={(schema_dir() / 'mission.schema.json').as_uri()}\n"


def template_text(name: str) -> str:
    """The template ``name`` with the schema line on top."""
    from importlib import resources

    body = (resources.files("tlmpc.templates") / f"{name}.yaml").read_text(encoding="utf-8")
    return schema_line() + body


def run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Print the template or write it to a new file."""
    from tlmpc.base.errors import EXIT_OK, UsageError, error
    from tlmpc.io.outdir import replace_file
    from tlmpc.io.report import Reporter

    text = template_text(args.template)
    reporter = Reporter.for_args(args, out, err)
    if args.output is None:
        return reporter.finish(EXIT_OK, text=text)
    target: Path = args.output
    if target.exists() or target.is_symlink():
        raise UsageError(
            error(
                "U094",
                f"{target} exists: tlmpc new never overwrites a file",
                hint="choose another name with -o, or remove the file first",
                file=str(target),
            )
        )
    if not target.parent.is_dir():
        raise UsageError(
            error(
                "U093",
                f"cannot write {target}: {target.parent} is not a directory",
                hint="create the directory first, or choose another file with -o",
                file=str(target),
            )
        )
    replace_file(target, text.encode("utf-8"))
    reporter.note(f"wrote {target}: edit it, then `tlmpc check {target}`")
    return reporter.finish(EXIT_OK)
