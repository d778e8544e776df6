"""The compiler pipeline: a list of stages that :func:`compile_mission` walks.

Each :class:`Stage` is a pure step ``Compilation -> StageResult``: it reads the IR objects the
earlier stages produced and returns the new ones plus its JSON artifacts.  The list is data
(after sqlglot's optimizer rules), so ``--until STAGE`` is a slice and a test can run any
prefix of it.  Heavy modules are imported inside the stage functions.
"""

from __future__ import annotations

import contextlib
import dataclasses
import gc
import time
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from tlmpc import __version__
from tlmpc.errors import TlmpcError, error

if TYPE_CHECKING:
    from tlmpc.abstraction.model import Abstraction
    from tlmpc.automata.model import Automaton
    from tlmpc.control.model import Controllers
    from tlmpc.errors import Diagnostic
    from tlmpc.mission.model import Mission
    from tlmpc.planning.model import Witness
    from tlmpc.simulate.exact import Trace
    from tlmpc.verify.model import Verdict


@dataclass(frozen=True, slots=True, kw_only=True)
class Compilation:
    """Everything the stages have produced so far (``None`` = not yet)."""

    source: Path
    mission: Mission | None = None
    abstraction: Abstraction | None = None
    automaton: Automaton | None = None
    witness: Witness | None = None
    controllers: Controllers | None = None
    trace: Trace | None = None
    trace_document: Mapping[str, Any] | None = None
    verdict: Verdict | None = None
    documents: Mapping[str, Any] = field(default_factory=dict)  # artifacts written so far
    figures: tuple[str, ...] = ("svg",)  # which plan pictures the plot stage draws


@dataclass(frozen=True, slots=True, kw_only=True)
class StageResult:
    """What one stage returns: the updated compilation, its artifacts and sizes to report."""

    compilation: Compilation
    artifacts: Mapping[str, Any] = field(default_factory=dict)  # file name -> JSON doc | text
    sizes: Mapping[str, Any] = field(default_factory=dict)
    warnings: tuple[Diagnostic, ...] = ()


@dataclass(frozen=True, slots=True, kw_only=True)
class Stage:
    """A named lowering step of the compiler."""

    name: str
    run: Callable[[Compilation], StageResult]
    aliases: tuple[str, ...] = ()


def _require(value: Any, what: str) -> Any:
    if value is None:  # a programming error: stages run in order
        raise RuntimeError(f"stage input missing: {what}")
    return value


def _load(c: Compilation) -> StageResult:
    from tlmpc.mission import load_mission

    mission = load_mission(c.source)
    return StageResult(
        compilation=dataclasses.replace(c, mission=mission),
        artifacts={"mission.json": mission.to_json()},
        sizes={"regions": len(mission.regions), "formula": str(mission.formula)},
    )


def _abstraction(c: Compilation) -> StageResult:
    from tlmpc.abstraction import (
        abstraction_diagnostics,
        abstraction_to_json,
        build_abstraction,
    )

    mission: Mission = _require(c.mission, "mission")
    abstraction = build_abstraction(mission)
    return StageResult(
        compilation=dataclasses.replace(c, abstraction=abstraction),
        artifacts={"abstraction.json": abstraction_to_json(abstraction)},
        sizes={
            "triangles": abstraction.num_triangles,
            "vertices": int(abstraction.vertices.shape[0]),
            "letters": len(abstraction.letters),
        },
        warnings=tuple(abstraction_diagnostics(abstraction, mission)),
    )


def _automaton(c: Compilation) -> StageResult:
    from tlmpc.automata import automaton_to_json, to_hoa, translate

    mission: Mission = _require(c.mission, "mission")
    abstraction: Abstraction = _require(c.abstraction, "abstraction")
    automaton = translate(mission.formula, letters=abstraction.letters)
    return StageResult(
        compilation=dataclasses.replace(c, automaton=automaton),
        artifacts={
            "automaton.json": automaton_to_json(automaton),
            "automaton.hoa": to_hoa(automaton),
        },
        sizes={
            "states": automaton.num_states,
            "edges": len(automaton.edges),
            "acceptance sets": automaton.num_acc,
        },
    )


def _plan(c: Compilation) -> StageResult:
    from tlmpc.planning import plan, witness_to_json

    mission: Mission = _require(c.mission, "mission")
    abstraction: Abstraction = _require(c.abstraction, "abstraction")
    automaton: Automaton = _require(c.automaton, "automaton")
    witness = plan(
        abstraction,
        automaton,
        formula=mission.formula,
        options=mission.options,
        start_point=mission.robot.start,
    )
    return StageResult(
        compilation=dataclasses.replace(c, witness=witness),
        artifacts={"witness.json": witness_to_json(witness, abstraction)},
        sizes={
            "prefix": len(witness.prefix),
            "cycle": len(witness.cycle),
            "cost": round(witness.cost, 6),
            "product nodes": witness.stats.get("product_nodes"),
            "reached": witness.stats.get("product_reached"),
        },
    )


def _control(c: Compilation) -> StageResult:
    from tlmpc.control import controllers_to_json, synthesize

    mission: Mission = _require(c.mission, "mission")
    abstraction: Abstraction = _require(c.abstraction, "abstraction")
    witness: Witness = _require(c.witness, "witness")
    controllers = synthesize(abstraction, witness, mission.robot)
    document = controllers_to_json(controllers)
    return StageResult(
        compilation=dataclasses.replace(c, controllers=controllers),
        artifacts={"controllers.json": document},
        sizes={"steps": len(document["steps"]), "jumps": len(document.get("jumps", []))},
    )


def _simulate(c: Compilation) -> StageResult:
    from tlmpc.simulate import simulate, trace_to_json

    mission: Mission = _require(c.mission, "mission")
    abstraction: Abstraction = _require(c.abstraction, "abstraction")
    controllers: Controllers = _require(c.controllers, "controllers")
    trace = simulate(abstraction, controllers, mission)
    document = trace_to_json(trace, mission)
    points: list[list[float]] = document["points"]  # type: ignore[assignment]
    return StageResult(
        compilation=dataclasses.replace(c, trace=trace, trace_document=document),
        artifacts={"trace.json": document},
        sizes={"samples": len(points), "duration": round(float(points[-1][0]), 3)},
    )


def _verify(c: Compilation) -> StageResult:
    from tlmpc.verify import verdict_to_json, verify_document

    document: Mapping[str, Any] = _require(c.trace_document, "trace")
    verdict = verify_document(dict(document))
    verdict_json = verdict_to_json(verdict)
    if not verdict_json["satisfied"]:
        # The compiler's guarantee failed: that is a bug in tlmpc, never the user's fault.
        raise SelfCheckError(
            error(
                "I001",
                "the compiled trajectory does not satisfy the task (self-check failed): "
                + str(verdict_json.get("counterexample")),
                hint="please report this mission; the artifacts were not written",
            )
        )
    return StageResult(
        compilation=dataclasses.replace(c, verdict=verdict),
        artifacts={"verdict.json": verdict_json},
        sizes={"robustness": round(float(verdict.robustness), 6)},
    )


def _plot(c: Compilation) -> StageResult:
    # Drawn from the artifacts themselves (the same code as `tlmpc plot`), so the picture
    # always shows what was written.
    # plan.svg is written directly (cheap); plan.png needs matplotlib, so only on request.
    from tlmpc.plot import render_png, render_svg

    pictures: dict[str, bytes] = {}
    if "svg" in c.figures:
        pictures["plan.svg"] = render_svg(c.documents)
    if "png" in c.figures:
        pictures["plan.png"] = render_png(c.documents)
    return StageResult(
        compilation=c,
        artifacts=pictures,
        sizes={f"{name[5:]} bytes": len(data) for name, data in pictures.items()},
    )


class SelfCheckError(TlmpcError):
    """The verifier rejected a trace the compiler produced (an internal error, exit 3)."""

    exit_code = 3


STAGES: tuple[Stage, ...] = (
    Stage(name="load", run=_load, aliases=("mission",)),
    Stage(name="abstraction", run=_abstraction),
    Stage(name="automaton", run=_automaton),
    Stage(name="plan", run=_plan, aliases=("witness", "planning")),
    Stage(name="control", run=_control, aliases=("controllers",)),
    Stage(name="simulate", run=_simulate, aliases=("trace",)),
    Stage(name="verify", run=_verify, aliases=("verdict",)),
    Stage(name="plot", run=_plot),
)


def stage_names() -> list[str]:
    """Names (and aliases) accepted by ``--until``."""
    return [n for s in STAGES for n in (s.name, *s.aliases)]


def stages_until(name: str | None) -> tuple[Stage, ...]:
    """The prefix of :data:`STAGES` ending with the stage called ``name`` (all when None)."""
    if name is None:
        return STAGES
    for index, stage in enumerate(STAGES):
        if name == stage.name or name in stage.aliases:
            return STAGES[: index + 1]
    raise ValueError(name)


@dataclass(frozen=True, slots=True, kw_only=True)
class StageReport:
    """Timing and sizes of one stage, for the progress line and ``summary.json``."""

    name: str
    seconds: float
    sizes: Mapping[str, Any]


@dataclass(frozen=True, slots=True, kw_only=True)
class CompileResult:
    """The outcome of :func:`compile_mission`."""

    compilation: Compilation
    artifacts: dict[str, Any]
    reports: tuple[StageReport, ...]
    warnings: tuple[Diagnostic, ...]

    def summary(self) -> dict[str, Any]:
        """The ``summary.json`` document (``tlmpc.summary/1``)."""
        c = self.compilation
        summary: dict[str, Any] = {
            "format": "tlmpc.summary/1",
            "tool": {"name": "tlmpc", "version": __version__},
            "mission": c.mission.name if c.mission else None,
            "source": str(c.source),
            "formula": str(c.mission.formula) if c.mission else None,
            "stages": [
                {"name": r.name, "seconds": round(r.seconds, 6), "sizes": dict(r.sizes)}
                for r in self.reports
            ],
            "total_seconds": round(sum(r.seconds for r in self.reports), 6),
            "artifacts": sorted([*self.artifacts, "summary.json"]),
            "warnings": [w.to_json() for w in self.warnings],
        }
        if c.witness is not None:
            summary["plan"] = {
                "prefix_length": len(c.witness.prefix),
                "cycle_length": len(c.witness.cycle),
                "stay": c.witness.is_stay,
                "cost": c.witness.cost,
                "metric": c.witness.metric,
            }
        verdict_doc = self.artifacts.get("verdict.json")
        if verdict_doc is not None:
            summary["verdict"] = {
                "satisfied": verdict_doc["satisfied"],
                "robustness": verdict_doc.get("robustness"),
                "boundary": verdict_doc.get("boundary"),
            }
        return summary


ProgressFn = Callable[[int, int, StageReport], None]


@contextlib.contextmanager
def collector_paused() -> Iterator[None]:
    """Pause Python's cyclic garbage collector for one compilation.

    A compilation holds many small live objects (YAML nodes with positions, region shapes,
    artifact documents), and every full collection walks all of them: on Example 8 that was
    a third of the load stage.  The stages create almost no reference cycles, reference
    counting frees the rest, and the collector resumes (and catches up) when we are done.
    """
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()


def compile_mission(
    source: Path | str,
    *,
    until: str | None = None,
    progress: ProgressFn | None = None,
    figures: tuple[str, ...] = ("svg",),
) -> CompileResult:
    """Run the stages of :data:`STAGES` (up to ``until``) on the mission file ``source``.

    ``figures`` names the pictures the plot stage draws (``"svg"``, ``"png"``).  Raises the
    stage's :class:`~tlmpc.errors.TlmpcError` when one fails; nothing is written here (the
    CLI writes the returned artifacts atomically).
    """
    stages = stages_until(until)
    compilation = Compilation(source=Path(source), figures=figures)
    artifacts: dict[str, Any] = {}
    reports: list[StageReport] = []
    warnings: list[Diagnostic] = []
    with collector_paused():
        for index, stage in enumerate(stages, start=1):
            started = time.perf_counter()
            result = stage.run(compilation)
            report = StageReport(
                name=stage.name, seconds=time.perf_counter() - started, sizes=result.sizes
            )
            artifacts.update(result.artifacts)
            compilation = dataclasses.replace(result.compilation, documents=dict(artifacts))
            warnings.extend(result.warnings)
            reports.append(report)
            if progress is not None:
                progress(index, len(stages), report)
    return CompileResult(
        compilation=compilation,
        artifacts=artifacts,
        reports=tuple(reports),
        warnings=tuple(warnings),
    )
