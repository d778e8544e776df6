"""``tlmpc check FILE...``: validate mission files (fast enough for a pre-commit hook).

Imports only the mission loader (lark, PyYAML, jsonschema, shapely) and tlmpc's own pure-Python
automata (for the contradiction check); never scipy, clarabel, triangle, cvxpy or matplotlib.
A ROS map_server map YAML among the files (the map a mission names, a keepout mask: a hook's
``files:`` pattern picks them up beside the missions) is checked as a map, with the reader
``tlmpc import-map`` uses (which also loads numpy and Pillow).
Exit 0 when every file is valid, 1 when some file is invalid, 2 when some file could not be read
(unreadable wins over invalid: the run could not do its job).
"""

from __future__ import annotations

import argparse
from collections import Counter
from pathlib import Path
from typing import Any, TextIO

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
    from tlmpc.base.errors import EXIT_NEGATIVE, EXIT_OK, EXIT_USAGE
    from tlmpc.io.report import Reporter

    report = Reporter.for_args(args, out, err)
    results: list[dict[str, Any]] = []
    explained: list[str] = []
    tally: Counter[tuple[str, str]] = Counter()  # (kind, status): how many files
    for path in args.files:
        entry, diagnostics, notices, status, kind = check_source(path)
        tally[kind, status] += 1
        entry["diagnostics"] = [d.to_json() for d in [*diagnostics, *notices]]
        results.append(entry)
        report.diagnose([*diagnostics, *notices])
        if entry["ok"] and args.explain and kind == "mission":  # a map has no formula
            explained.append(f"{path}: {entry['ltl']}\n")
            explained.extend(f"  {scope}\n" for scope in entry.get("avoid_scopes", []))
            explained.extend(f"  {line}\n" for line in entry.get("gr1", []))
    statuses = {status for _, status in +tally}
    # unreadable wins over invalid: the run could not do its job
    code = (
        EXIT_USAGE
        if "unreadable" in statuses
        else (EXIT_NEGATIVE if "invalid" in statuses else EXIT_OK)
    )
    report.finish(code, {"files": results}, "".join(explained))
    if not args.json:  # the tally comes last, after the explanations
        report.note(_summary(tally))
    return code


def _summary(tally: Counter[tuple[str, str]]) -> str:
    """``3 of 4 mission file(s) valid, 1 invalid``, and the maps' own count when there are
    any (an unreadable file counts as a mission: what it is was never seen)."""
    parts = []
    for kind in ("mission", "map"):
        total = sum(n for (k, _), n in tally.items() if k == kind)
        if not total and (kind == "map" or tally):
            continue
        part = f"{tally[kind, 'valid']} of {total} {kind} file(s) valid"
        for status in ("invalid", "unreadable"):
            if tally[kind, status]:
                part += f", {tally[kind, status]} {status}"
        parts.append(part)
    return "; ".join(parts)


def _entry(path: Path) -> dict[str, Any]:
    """A file's entry in the JSON result, before it is checked."""
    return {"file": str(path), "ok": False, "diagnostics": [], "ltl": None}


def check_source(
    path: Path, text: str | None = None
) -> tuple[dict[str, Any], list[Any], list[Any], str, str]:
    """Check one mission (or map) as ``tlmpc check`` does: its JSON entry, its problems (best
    first) and its notes, whether it is ``"valid"``, ``"invalid"`` or ``"unreadable"``, and
    whether it is a ``"mission"`` or a ``"map"``.  ``text``, when given, is the mission's YAML,
    read instead of the file ``path`` (which then only names it in diagnostics)."""
    from tlmpc.base.errors import error

    try:
        return _check_file(path, text)
    except RecursionError:  # deeper than any stage handles: this file, not the batch
        problem = error(
            "U036",
            "the mission is nested too deeply to process",
            hint="flatten it (split a long sequence of steps, or nest fewer formulas)",
            file=str(path),
        )
        return _entry(path), [problem], [], "unreadable", "mission"


def _inspect_text(text: str, file: str) -> tuple[Any, list[Any]]:
    """The mission in ``text`` (None when invalid) and its problems, best first, as
    :func:`tlmpc.mission.load.inspect_file` gives them for a file."""
    from tlmpc.base.errors import InvalidInputError
    from tlmpc.mission.load import load_mission_text

    try:
        return load_mission_text(text, file), []
    except InvalidInputError as exc:
        return None, list(exc.diagnostics)


def _check_file(
    path: Path, text: str | None = None
) -> tuple[dict[str, Any], list[Any], list[Any], str, str]:
    from tlmpc.base.errors import UsageError, best_first
    from tlmpc.ltl.printer import to_text
    from tlmpc.mission.load import inspect_file

    entry = _entry(path)
    notices: list[Any] = []
    try:
        if text is None:
            mission, diagnostics = inspect_file(path)
        else:
            mission, diagnostics = _inspect_text(text, str(path))
    except UsageError as exc:
        return entry, list(exc.diagnostics), notices, "unreadable", "mission"
    if mission is None and text is None and _is_map(path):
        return (*_check_map(path, entry), "map")
    if mission is not None and not diagnostics:
        diagnostics = _contradictions(path, mission)
        if not diagnostics and mission.reactive is not None:
            diagnostics, entry["gr1"] = _gr1_reading(mission)
        # the geometry is checked whatever the task says: compile reports its problems
        # (R001, G030, G031) at load and abstraction, before it ever looks for a plan
        geometry, notices = _geometry(mission, text)
        # best first over the whole file, as compile reports them (errors, then by place)
        diagnostics = best_first(diagnostics + geometry)
    if diagnostics:
        return entry, diagnostics, notices, "invalid", "mission"
    entry["ok"] = True
    if mission is not None:
        entry["ltl"] = to_text(mission.formula)
        entry["avoid_scopes"] = _scopes(mission)
    return entry, diagnostics, notices, "valid", "mission"


def _is_map(path: Path) -> bool:
    """Whether the file that is no valid mission is a map_server map YAML: map keys and
    none of a mission's top-level keys (a mission with a typo stays a mission)."""
    from tlmpc.importers.map_keys import looks_like_map
    from tlmpc.io.schema_check import load_schema

    return looks_like_map(path, foreign_keys=frozenset(load_schema("mission")["properties"]))


def _check_map(
    path: Path, entry: dict[str, Any]
) -> tuple[dict[str, Any], list[Any], list[Any], str]:
    """A map YAML checked as ``tlmpc import-map`` reads it (M001-M006, at their keys); when
    it reads, a note (M020) that it is a map, not a mission, and was checked as one."""
    from tlmpc.base.errors import Diagnostic, UsageError
    from tlmpc.importers.occupancy import read_map

    try:
        grid = read_map(path)
    except UsageError as exc:
        problems = list(exc.diagnostics)
        # the YAML itself unreadable, or Pillow missing: the map could not be checked at all
        unreadable = any(d.code in ("M001", "U060") for d in problems)
        return entry, problems, [], "unreadable" if unreadable else "invalid"
    rows, cols = grid.shape
    note = Diagnostic(
        code="M020",
        severity="note",
        message=f"a ROS map_server map, not a mission: checked as a map ({cols}x{rows} cells "
        f"of {grid.resolution:g} m), valid",
        hint="a mission uses a map through `workspace: {map: FILE}`; to leave maps out of a "
        "pre-commit hook, narrow its `files:` or add `exclude:`",
        file=str(path),
    )
    entry["ok"] = True
    return entry, [], [note], "valid"


def _geometry(mission: Any, text: str | None = None) -> tuple[list[Any], list[Any]]:
    """The workspace's problems as compile's load and abstraction stages find them: the
    body's (R001) first, then, when the body fits, features snapping would reshape
    (G030/G031); and the notes (merged holes, narrow passages).  ``text`` is the mission's
    YAML when it is not read from its file: they are placed on its lines."""
    from tlmpc.mission.body import body_radius
    from tlmpc.mission.holes import workspace_notes

    merged, notices = workspace_notes(mission, text)
    problems: list[Any] = []
    if body_radius(mission.robot) > 0.0:  # shapely only for a body
        from tlmpc.mission.cspace import body_diagnostics

        body = body_diagnostics(merged, text)
        problems = [d for d in body if d.severity == "error"]
        notices += [d for d in body if d.severity != "error"]
    if not problems:
        problems = _subgrid(merged, text)
    return problems, notices


def _subgrid(mission: Any, text: str | None) -> list[Any]:
    """What compile refuses before triangulating (G030/G031): features snapping would
    reshape.  A pure-Python look first: when every coordinate is on the grid (decimals, the
    usual case) nothing moves and numpy and shapely stay unloaded."""
    from tlmpc.mission.grid import features_on_grid

    if features_on_grid(mission):
        return []
    from tlmpc.mission.placement import placed
    from tlmpc.mission.resolution import subgrid_problems

    # placed on the file's lines already, or (``text``, no file) on the text's
    return list(placed(subgrid_problems(mission), mission.source, text))


def _gr1_reading(mission: Any) -> tuple[list[Any], list[str]]:
    """Q102 for each part of a reactive mission outside GR(1); else each part's GR(1) pieces
    in words (``assume``: the environment's, ``guarantee``: the robot's)."""
    from tlmpc.reactive.fragment import reading
    from tlmpc.reactive.parts import mission_parts

    pieces, problems = reading(mission_parts(mission), mission.source)
    lines = [
        f"{'assume' if piece.owner == 'env' else 'guarantee'} [{piece.part.text}]: "
        + piece.describe()
        for piece in pieces
    ]
    return problems, lines


def _scopes(mission: Any) -> list[str]:
    """Every avoidance of the mission's phrases with its scope in words."""
    from tlmpc.tasks import avoid_scopes

    scopes: list[str] = []
    for phrase in mission.task:
        scopes.extend(avoid_scopes(phrase, groups=mission.groups))
    return scopes


def _contradictions(path: Path, mission: Any) -> list[Any]:
    """A T011/L020 diagnostic when no behaviour at all satisfies the mission's task."""
    from tlmpc.base.errors import UsageError
    from tlmpc.mission.load import place_translation_refusal
    from tlmpc.tasks import compile_phrase
    from tlmpc.tasks.contradiction import TaskPart, find_contradiction

    file = str(path)
    parts: list[TaskPart] = []
    # where each phrase, then the `ltl` string, starts: the loader kept them (no second read)
    positions = list(mission.task_positions)
    for index, phrase in enumerate(mission.task):
        line, col = positions[index]
        formula = compile_phrase(phrase, groups=mission.groups, file=file, line=line, col=col)
        parts.append(TaskPart(formula=formula, text=phrase, kind="phrase", line=line, col=col))
    if mission.ltl and mission.ltl.strip():
        from tlmpc.ltl.parser import parse_ltl  # lark: only for missions with `ltl`

        line, col = positions[len(mission.task)]
        parts.append(
            TaskPart(
                formula=parse_ltl(mission.ltl),
                text=mission.ltl.strip(),
                kind="ltl",
                line=line,
                col=col,
            )
        )
    try:
        found = find_contradiction(parts, groups=mission.groups, file=file)
    except UsageError as exc:
        if any(d.code != "P041" for d in exc.diagnostics):
            raise
        # the task's automaton is beyond the translation's budget: this file's problem, at
        # the entry to blame, not the run's
        return [place_translation_refusal(d, mission) for d in exc.diagnostics]
    return [found] if found is not None else []
