"""The Python facade of tlmpc: compile missions, read outputs, verify trajectories, translate LTL.

Everything here is also what the command line does, minus the printing::

    import tlmpc

    result = tlmpc.compile({"version": 1, "name": "demo", ...})   # a dict, YAML text or a path
    result.summary["plan"]                                        # plan shape and cost
    result.write("out")                                           # the artifacts, atomically
    verdict = tlmpc.verify_trace(result)                          # re-check the trajectory
    automaton = tlmpc.translate("G F a & G F b")

Failures raise :class:`~tlmpc.base.errors.TlmpcError` subclasses carrying the same diagnostics the
command line prints (``error.diagnostics``); ``error.exit_code`` is the CLI's exit code.
Results render in Jupyter (``_repr_svg_`` / ``_repr_html_``).

This module imports only the standard library at import time; each function imports the stages
it needs, so ``import tlmpc`` stays cheap.
"""

from __future__ import annotations

import html
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from tlmpc.base.errors import Diagnostic, UsageError, error

if TYPE_CHECKING:
    from tlmpc.automata.model import Automaton
    from tlmpc.runtime import Executor
    from tlmpc.runtime.reactive import ReactiveExecutor
    from tlmpc.verify.model import Verdict

MissionSource = str | os.PathLike[str] | Mapping[str, Any]
"""A mission: a path to a YAML file, YAML text, or the mission as a dict."""


def _expect(value: Any, kinds: tuple[type, ...], what: str, function: str) -> None:
    """Refuse (U075) an argument of the wrong type with a diagnostic, not a bare TypeError
    from deep inside a stage."""
    if isinstance(value, kinds) and not isinstance(value, bool):
        return
    from tlmpc.io.outputs import plain_name

    raise UsageError(
        error(
            "U075",
            f"tlmpc.{function}: {what}, not {type(value).__name__} {plain_name(repr(value)[:60])}",
            hint=f"see help(tlmpc.{function})",
        )
    )


_PATH = (str, os.PathLike)


def _expect_path(value: Any, what: str, function: str) -> None:
    """:func:`_expect` a path, and refuse (U075) one holding a NUL character (the operating
    system cannot name such a file; Python would raise a bare ValueError)."""
    _expect(value, _PATH, what, function)
    if "\x00" in os.fspath(value):
        raise UsageError(error("U075", f"tlmpc.{function}: the path holds a NUL character"))


class _NotPlain(Exception):
    """A value of a mission dict that is no YAML value, and its JSON path."""

    def __init__(self, path: str, what: str) -> None:
        super().__init__(path, what)
        self.path = path
        self.what = what


#: How deep a mission dict may nest (a mission nests a handful of levels; a dict that holds
#: itself would never end).
_MAX_PLAIN_DEPTH = 64


def _plain(value: Any, keys: tuple[str | int, ...] = (), depth: int = 0) -> Any:
    """``value`` (at ``keys`` in the mission dict) as the plain values YAML writes: any mapping
    a dict, a tuple or list (or a numpy array) a list, a subclass of ``str``, ``int`` or
    ``float`` (an enum member, numpy's ``float64``) its plain value; :class:`_NotPlain`, with
    the value's JSON path, for anything else."""
    import numbers

    from tlmpc.io.json_places import json_path

    if depth > _MAX_PLAIN_DEPTH:
        raise _NotPlain(
            json_path(*keys), f"nested more than {_MAX_PLAIN_DEPTH} levels (or holds itself)"
        )
    if value is None or type(value) in (bool, int, float, str):
        return value
    if isinstance(value, bool):
        return bool(value)
    if isinstance(value, str):
        return str.__str__(value)
    if isinstance(value, numbers.Integral):
        return int(value)
    if isinstance(value, numbers.Real):
        return float(value)
    if isinstance(value, Mapping):
        plain: dict[Any, Any] = {}
        for key, item in value.items():
            name = _plain(key, keys, depth + 1)
            if isinstance(name, list | dict):
                raise _NotPlain(json_path(*keys), f"a key that is a {type(key).__name__}")
            plain[name] = _plain(item, (*keys, str(name)), depth + 1)
        return plain
    if isinstance(value, list | tuple):
        return [_plain(item, (*keys, i), depth + 1) for i, item in enumerate(value)]
    tolist = getattr(value, "tolist", None)  # a numpy array or scalar
    if callable(tolist) and type(value).__module__.split(".")[0] == "numpy":
        return _plain(tolist(), keys, depth + 1)
    raise _NotPlain(json_path(*keys), f"a value of type {type(value).__name__}")


def _mission_text(mission: MissionSource, function: str) -> tuple[str | None, Path]:
    """(YAML text or None when ``mission`` is a file, the path diagnostics will name)."""
    _expect(mission, (*_PATH, Mapping), "the mission must be a path, YAML text or a dict", function)
    if isinstance(mission, Mapping):
        import yaml

        try:
            document = _plain(mission)
        except _NotPlain as refused:
            raise UsageError(
                error(
                    "U075",
                    f"tlmpc.{function}: the mission dict holds a value YAML cannot write at "
                    f"{refused.path if len(refused.path) <= 80 else refused.path[:79] + '…'}: "
                    f"{refused.what}",
                    hint="use dicts (any mapping), lists (or tuples, numpy arrays), strings and "
                    "numbers",
                )
            ) from None
        return yaml.safe_dump(document, sort_keys=False), Path("<mission>")
    if isinstance(mission, os.PathLike):
        return None, Path(mission)
    if "\x00" in mission:
        raise UsageError(
            error("U075", f"tlmpc.{function}: the mission text or path holds a NUL character")
        )
    if _is_mission_text(mission):
        return mission, Path("<mission>")
    return None, Path(mission)


def _is_mission_text(mission: str) -> bool:
    """Whether the string ``mission`` is YAML text rather than a path: it spans lines, starts
    with ``{`` (flow style or JSON, however long or broken: its diagnostics are the YAML
    reader's), or is one line that YAML reads as a mapping (``name: x``) and names no existing
    file.  Anything else is a path, so a missing or unreadable file is U001, whatever its
    name holds (``C:/missions/a.yaml``)."""
    if "\n" in mission or "\r" in mission or mission.lstrip().startswith("{"):
        return True
    import yaml

    try:
        mapping = isinstance(yaml.safe_load(mission), Mapping)
    except (yaml.YAMLError, ValueError, RecursionError):
        return False
    if not mapping:
        return False
    try:
        return not Path(mission).is_file()
    except (OSError, ValueError):  # a name longer than the system allows is no file
        return True


@dataclass(frozen=True, repr=False)
class Compiled:
    """A compiled mission: its artifacts (parsed JSON documents, HOA text) and summary.

    ``artifacts`` maps file names (``"witness.json"``) to documents exactly as ``tlmpc
    compile`` writes them; :meth:`write` writes them into a directory.
    """

    artifacts: Mapping[str, Any]
    source: str = "<mission>"
    warnings: tuple[Diagnostic, ...] = ()
    _figure: dict[str, str] = field(default_factory=dict, repr=False, compare=False)

    def __repr__(self) -> str:
        """One line: the source, the mesh, the plan and the verdict — not every artifact."""
        summary = self.summary
        parts = [f"source={self.source!r}"]
        for stage in summary.get("stages", []):
            if stage.get("name") == "abstraction" and "triangles" in stage.get("sizes", {}):
                parts.append(f"triangles={stage['sizes']['triangles']}")
        plan = summary.get("plan")
        if plan:
            parts.append(f"plan=({plan.get('prefix_length')} + {plan.get('cycle_length')} steps)")
        verdict = summary.get("verdict")
        if verdict:
            parts.append(f"satisfied={verdict.get('satisfied')}")
            parts.append(f"robustness={verdict.get('robustness', float('nan')):.4g}")
        parts.append(f"artifacts={len(self.artifacts)}")
        if self.warnings:
            parts.append(f"warnings={len(self.warnings)}")
        return f"Compiled({', '.join(parts)})"

    @property
    def summary(self) -> Mapping[str, Any]:
        """``summary.json``: sizes and seconds per stage, plan shape and cost, verdict."""
        return dict(self.artifacts.get("summary.json", {}))

    @property
    def formula(self) -> str:
        """The whole task as one LTL formula."""
        return str(self.artifacts["mission.json"]["formula"])

    @property
    def plan(self) -> Mapping[str, Any] | None:
        """``witness.json`` (prefix and cycle of triangles), or None before the plan stage."""
        witness: Mapping[str, Any] | None = self.artifacts.get("witness.json")
        return witness

    @property
    def trajectory(self) -> list[list[float]]:
        """The simulated ``[t, x, y]`` samples (empty before the simulate stage)."""
        trace = self.artifacts.get("trace.json")
        return [list(map(float, row)) for row in trace["points"]] if trace else []

    def write(self, out: str | os.PathLike[str], *, force: bool = False) -> Path:
        """Write every artifact (and the figure, when drawn) into ``out`` atomically."""
        from tlmpc.io.outdir import (
            check_destination,
            commit,
            refuse_deleting_foreign,
            staging_directory,
            write_artifacts,
        )

        _expect_path(out, "out must be a path", "Compiled.write")
        destination = Path(out)
        check_destination(destination, force=force)
        refuse_deleting_foreign(destination, force=force)
        with staging_directory(destination) as staging:
            write_artifacts(staging, dict(self.artifacts))
            commit(staging, destination, force=force)
        return destination

    def svg(self) -> str:
        """The plan figure as SVG text (drawn on first use)."""
        if "svg" not in self._figure:
            drawn = self.artifacts.get("plan.svg")
            if not isinstance(drawn, bytes):
                from tlmpc.render.plot import render_svg

                drawn = render_svg(self.artifacts)
            self._figure["svg"] = drawn.decode("utf-8")
        return self._figure["svg"]

    def _repr_svg_(self) -> str | None:
        if "trace.json" not in self.artifacts:
            return None
        return self.svg()

    def _repr_html_(self) -> str:
        summary = self.summary
        rows = [("formula", self.formula if "mission.json" in self.artifacts else "")]
        plan = summary.get("plan")
        if plan:
            rows.append(("plan", f"prefix {plan['prefix_length']}, cycle {plan['cycle_length']}"))
            rows.append(("cost", f"{plan['cost']:.4g} ({plan['metric']})"))
        verdict = summary.get("verdict")
        if verdict:
            rows.append(("verdict", "satisfied" if verdict["satisfied"] else "violated"))
        table = "".join(
            f"<tr><th style='text-align:left'>{html.escape(k)}</th>"
            f"<td style='text-align:left'>{html.escape(str(v))}</td></tr>"
            for k, v in rows
        )
        figure = self._repr_svg_() or ""
        return f"<div><table>{table}</table>{figure}</div>"


def compile(
    mission: MissionSource,
    *,
    until: str | None = None,
) -> Compiled:
    """Compile ``mission`` through every stage (or up to the stage ``until``).

    ``mission`` is a path to a YAML file, YAML text, or a dict with the same keys as the
    YAML format.  Raises :class:`~tlmpc.base.errors.TlmpcError` (with diagnostics) when the mission
    is invalid, has no plan, or a stage fails.  Nothing is written: call
    :meth:`Compiled.write`.
    """
    from tlmpc.pipeline.stages import compile_mission

    text, source = _mission_text(mission, "compile")
    if until is not None:
        _expect(until, (str,), "until must be a stage name", "compile")
        from tlmpc.pipeline.stages import stage_names

        if until not in stage_names():
            raise UsageError(
                error(
                    "U072",
                    f"unknown stage {until!r}",
                    hint="one of: " + ", ".join(stage_names()),
                )
            )
    result = compile_mission(source, text=text, until=until)
    from tlmpc.io.arrays import plain

    # plain lists for the caller (the pipeline keeps large ones as arrays until written)
    artifacts = {name: plain(document) for name, document in result.artifacts.items()}
    artifacts["summary.json"] = result.summary()
    return Compiled(artifacts=artifacts, source=str(source), warnings=result.warnings)


def read_output(directory: str | os.PathLike[str]) -> Compiled:
    """Read the artifacts of an output directory written by ``tlmpc compile``.

    Each JSON artifact is checked against its schema; raises
    :class:`~tlmpc.base.errors.UsageError` when the directory holds no tlmpc output.
    """
    from tlmpc.io.artifacts import ARTIFACT_SCHEMAS, MAX_ARTIFACT_BYTES, cross_check, read_artifact
    from tlmpc.io.inputs import read_text

    _expect_path(directory, "directory must be a path", "read_output")
    root = Path(directory)
    artifacts: dict[str, Any] = {}
    for name, (_, schema) in ARTIFACT_SCHEMAS.items():
        if (root / name).is_file():
            artifacts[name] = read_artifact(root / name, schema)
    if (root / "automaton.hoa").is_file():
        # bounded and decoded as every artifact is (U001 at its first byte that is not UTF-8)
        artifacts["automaton.hoa"] = read_text(
            root / "automaton.hoa",
            limit=MAX_ARTIFACT_BYTES,
            code="U001",
            too_large_code="U040",
            what="artifact",
        )
    if "mission.json" not in artifacts:
        raise UsageError(
            error(
                "U020",
                f"{root} holds no tlmpc output (no mission.json)",
                file=str(root),
                hint="pass the directory given to `tlmpc compile -o`",
            )
        )
    cross_check(root, {k: v for k, v in artifacts.items() if isinstance(v, dict)})
    return Compiled(artifacts=artifacts, source=str(root))


def verify_trace(
    trace: Compiled | str | os.PathLike[str] | Mapping[str, Any],
    *,
    mission: str | os.PathLike[str] | None = None,
    boundary: str | None = None,
) -> Verdict:
    """Verify a trajectory against its task under continuous-time semantics.

    ``trace`` is a :class:`Compiled` result, a ``trace.json`` document (dict), or a path to a
    ``trace.json`` or a robot log — CSV, ROS 1 ``.bag``, ROS 2 bag directory, ``.mcap`` — read
    as ``tlmpc verify`` reads it (then ``mission`` names the mission file whose task and regions
    apply).  ``boundary`` overrides the labelling convention (``"right"`` or ``"closed"``).
    The verifier shares no code with the planner.
    """
    from tlmpc.verify import from_document, read_trace
    from tlmpc.verify import verify_trace as check_trace

    _expect(
        trace,
        (Compiled, Mapping, *_PATH),
        "trace must be a Compiled result, a trace.json dict or a path",
        "verify_trace",
    )
    if mission is not None:
        _expect_path(mission, "mission must be a path", "verify_trace")
    if boundary is not None:
        _expect(boundary, (str,), "boundary must be 'right' or 'closed'", "verify_trace")
    if isinstance(trace, Compiled):
        document = trace.artifacts.get("trace.json")
        if document is None:
            raise UsageError(error("U073", "this compilation stopped before the simulate stage"))
        return check_trace(from_document(document, convention=boundary))
    if isinstance(trace, Mapping):
        return check_trace(from_document(trace, convention=boundary))
    path = Path(trace)
    return check_trace(read_trace(path, Path(mission) if mission is not None else None, boundary))


def translate(formula: str) -> Automaton:
    """Translate a Next-free LTL formula into a transition-based generalized Büchi automaton.

    Raises :class:`~tlmpc.base.errors.InvalidInputError` with located diagnostics for bad syntax.
    """
    from tlmpc.automata import translate as translate_formula
    from tlmpc.ltl import parse_ltl

    _expect(formula, (str,), "the formula must be a string", "translate")
    return translate_formula(parse_ltl(formula))


def check(mission: MissionSource) -> list[Diagnostic]:
    """What ``tlmpc check`` reports for ``mission``: every problem (schema, geometry, task,
    a contradictory task, a reactive part outside GR(1)) best first, then its notes and
    warnings; empty when valid and nothing to note.  A path to a map_server map YAML is
    checked as a map.  Raises :class:`~tlmpc.base.errors.UsageError` when the file cannot be
    read."""
    from tlmpc.commands.check import check_source

    text, source = _mission_text(mission, "check")
    _, problems, notices, status, _ = check_source(source, text)
    if status == "unreadable":
        raise UsageError(problems)
    return [*problems, *notices]


def executor(output: Compiled | str | os.PathLike[str]) -> Executor:
    """The runtime executor of a compiled mission (an output folder or a :class:`Compiled`).

    ``executor(out).command(pose, t)`` returns the velocity to apply (``(vx, vy)``, or
    ``(v, omega)`` for a unicycle), tracking the plan step and recovering when the robot is
    pushed off its plan; ``.progress`` reports the task's progress.  A reactive mission's
    output is refused (R025): its executor is :func:`reactive_executor`.  See
    docs/python-api.md.
    """
    from tlmpc.runtime import Executor

    _expect(output, (Compiled, *_PATH), "output must be a Compiled result or a path", "executor")
    if _is_reactive(output):
        raise UsageError(
            error(
                "R025",
                "the output is a reactive mission's (it has a strategy, not a plan)",
                hint="use tlmpc.reactive_executor(output): its command(point, t, sensors) "
                "also reads the sensors",
            )
        )
    return Executor.from_output(output)


def reactive_executor(output: Compiled | str | os.PathLike[str]) -> ReactiveExecutor:
    """The runtime executor of a compiled reactive mission (an output folder or a
    :class:`Compiled`).

    ``reactive_executor(out).command(point, t, sensors)`` returns the velocity ``(vx, vy)``
    to apply, stepping the mission's strategy at every event (a sensor change, an arrival);
    ``.events`` lists them.  See docs/python-api.md and docs/semantics.md.
    """
    from tlmpc.runtime.reactive import ReactiveExecutor

    _expect(
        output,
        (Compiled, *_PATH),
        "output must be a Compiled result or a path",
        "reactive_executor",
    )
    return ReactiveExecutor.from_output(output)


def _is_reactive(output: Compiled | str | os.PathLike[str]) -> bool:
    if isinstance(output, Compiled):
        return "strategy.json" in output.artifacts
    return (Path(output) / "strategy.json").is_file()
