"""``tlmpc check FILE...``: validate mission files (fast enough for a pre-commit hook).

Imports only the mission loader (lark, PyYAML, jsonschema, shapely); never scipy, clarabel or
triangle.  Exit 0 when every file is valid, 1 when some file is invalid, 2 when some file
could not be read (unreadable wins over invalid: the run could not do its job).
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any, TextIO

from tlmpc.artifacts import json_text

NAME = "check"
HELP = "validate mission files: schema, geometry and task (pre-commit hook)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the command's flags."""
    parser.add_argument("files", nargs="+", type=Path, metavar="FILE", help="mission files")
    parser.add_argument(
        "--explain", action="store_true", help="print the LTL formula each valid mission means"
    )
    parser.add_argument(
        "--json", action="store_true", help="print one JSON document with every result"
    )


def run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Check every file; report all problems of all files."""
    from tlmpc import __version__
    from tlmpc.errors import UsageError
    from tlmpc.ltl.printer import to_text
    from tlmpc.mission.load import inspect_file

    results: list[dict[str, Any]] = []
    unreadable = invalid = 0
    for path in args.files:
        entry: dict[str, Any] = {"file": str(path), "ok": False, "diagnostics": [], "ltl": None}
        try:
            mission, diagnostics = inspect_file(path)
        except UsageError as exc:
            unreadable += 1
            diagnostics = list(exc.diagnostics)
        else:
            if diagnostics:
                invalid += 1
            else:
                entry["ok"] = True
                if mission is not None:
                    entry["ltl"] = to_text(mission.formula)
        entry["diagnostics"] = [d.to_json() for d in diagnostics]
        results.append(entry)
        for diagnostic in diagnostics:
            err.write(diagnostic.format() + "\n")
        if entry["ok"] and args.explain and not args.json:
            out.write(f"{path}: {entry['ltl']}\n")
    code = 2 if unreadable else (1 if invalid else 0)
    if args.json:
        document = {
            "tool": "tlmpc",
            "version": __version__,
            "command": "check",
            "ok": code == 0,
            "files": results,
        }
        out.write(json_text(document))
    else:
        valid = len(results) - invalid - unreadable
        summary = f"{valid} of {len(results)} mission file(s) valid"
        if invalid:
            summary += f", {invalid} invalid"
        if unreadable:
            summary += f", {unreadable} unreadable"
        err.write(summary + "\n")
    return code
