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
import sys
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Generic, TypeVar

from tlmpc.base.errors import (
    EXIT_INCONCLUSIVE,
    Diagnostic,
    InvalidInputError,
    TlmpcError,
    UsageError,
    error,
)
from tlmpc.base.memo import current_memo, memo_scope
from tlmpc.base.pages import plain_pages
from tlmpc.base.progress import heartbeat
from tlmpc.base.version import __version__

if TYPE_CHECKING:
    from tlmpc.abstraction.model import Abstraction
    from tlmpc.automata.model import Automaton
    from tlmpc.control.model import Controllers
    from tlmpc.mission.model import Mission
    from tlmpc.planning.model import Witness
    from tlmpc.verify.clearance import Clearance
    from tlmpc.verify.model import Verdict


T = TypeVar("T")


@dataclass(frozen=True, slots=True, eq=False)
class Product(Generic[T]):
    """A typed slot of a compilation: the IR one stage provides and later stages require.

    ``artifact`` is the file the IR is written to and ``read`` rebuilds the IR from that
    file's document, so a stage can run alone from its input artifacts.
    """

    name: str
    artifact: str
    schema: str
    read: Callable[[Mapping[str, Any]], T]

    def __repr__(self) -> str:
        return f"Product({self.name})"


def _read_mission(document: Mapping[str, Any]) -> Mission:
    from tlmpc.mission.io import mission_from_json

    return mission_from_json(document)


def _read_abstraction(document: Mapping[str, Any]) -> Abstraction:
    from tlmpc.abstraction.io import abstraction_from_json

    return abstraction_from_json(document)


def _read_automaton(document: Mapping[str, Any]) -> Automaton:
    from tlmpc.automata.io import automaton_from_json

    return automaton_from_json(document)


def _read_witness(document: Mapping[str, Any]) -> Witness:
    from tlmpc.planning.io import witness_from_json

    return witness_from_json(document)


def _read_controllers(document: Mapping[str, Any]) -> Controllers:
    from tlmpc.control.io import controllers_from_json

    return controllers_from_json(document)


def _read_trace(document: Mapping[str, Any]) -> Mapping[str, Any]:
    # The verifier reads the self-contained document itself (it shares no IR with the planner).
    return document


MISSION: Product[Mission] = Product("mission", "mission.json", "mission-artifact", _read_mission)
ABSTRACTION: Product[Abstraction] = Product(
    "abstraction", "abstraction.json", "abstraction", _read_abstraction
)
AUTOMATON: Product[Automaton] = Product("automaton", "automaton.json", "automaton", _read_automaton)
WITNESS: Product[Witness] = Product("witness", "witness.json", "witness", _read_witness)
CONTROLLERS: Product[Controllers] = Product(
    "controllers", "controllers.json", "controllers", _read_controllers
)
TRACE: Product[Mapping[str, Any]] = Product("trace", "trace.json", "trace", _read_trace)


class MissingProductError(TlmpcError):
    """A stage was asked to run without the artifacts it needs (exit 2)."""

    exit_code = 2


@dataclass(frozen=True, slots=True, kw_only=True)
class Compilation:
    """What the stages have produced so far: typed products and the artifacts written.

    ``text`` is the mission's YAML when it does not come from the file ``source``.
    """

    source: Path
    text: str | None = None
    products: Mapping[Product[Any], Any] = field(default_factory=dict)
    documents: Mapping[str, Any] = field(default_factory=dict)  # artifacts written so far
    figures: tuple[str, ...] = ("svg",)  # which plan pictures the plot stage draws

    def get(self, product: Product[T]) -> T:
        """The IR of ``product``; a stage only asks for what its ``requires`` declares."""
        try:
            value: T = self.products[product]
        except KeyError:
            raise MissingProductError(
                error(
                    "U070",
                    f"the {product.name} is not available ({product.artifact} is missing)",
                    hint="run the earlier stages first (tlmpc compile --until ...)",
                )
            ) from None
        return value

    def find(self, product: Product[T]) -> T | None:
        """The IR of ``product``, or None when no stage has provided it."""
        value: T | None = self.products.get(product)
        return value


@dataclass(frozen=True, slots=True, kw_only=True)
class StageResult:
    """What one stage returns: its products, its artifacts and sizes to report."""

    products: Mapping[Product[Any], Any] = field(default_factory=dict)
    artifacts: Mapping[str, Any] = field(default_factory=dict)  # file name -> JSON doc | text
    sizes: Mapping[str, Any] = field(default_factory=dict)
    warnings: tuple[Diagnostic, ...] = ()
    summary: Mapping[str, Any] = field(default_factory=dict)  # keys added to summary.json


def provide(product: Product[T], value: T) -> dict[Product[Any], Any]:
    """``{product: value}``, with the value's type checked against the product's."""
    return {product: value}


#: A mission's world: ``static`` (one plan, computed once) or ``reactive`` (sensors: a game).
World = str
WORLDS: frozenset[World] = frozenset({"static", "reactive"})


@dataclass(frozen=True, slots=True, kw_only=True)
class Stage:
    """A named lowering step: reads ``requires``, returns ``provides`` (checked when run).

    ``worlds`` are the kinds of mission the stage lowers; the walker skips it for the others.
    """

    name: str
    run: Callable[[Compilation], StageResult]
    requires: tuple[Product[Any], ...] = ()
    provides: tuple[Product[Any], ...] = ()
    aliases: tuple[str, ...] = ()
    worlds: frozenset[World] = WORLDS


def world_of(mission: Mission) -> World:
    """``reactive`` for a mission with sensors, actions or assumptions, else ``static``."""
    return "reactive" if mission.reactive is not None else "static"


def _load(c: Compilation) -> StageResult:
    from tlmpc.mission import load_mission, load_mission_text
    from tlmpc.mission.holes import workspace_notes

    if c.text is not None:
        loaded = load_mission_text(c.text, str(c.source))
    else:
        loaded = load_mission(c.source)
    mission, notes = workspace_notes(loaded, c.text)  # holes merged; narrow passages
    notes += _body_notes(mission, c.text)
    return StageResult(
        products=provide(MISSION, mission),
        artifacts={"mission.json": mission.to_json()},
        sizes={"regions": len(mission.regions), "formula": str(mission.formula)},
        warnings=tuple(notes),
    )


def _body_notes(mission: Mission, text: str | None) -> list[Diagnostic]:
    """R001 (raised) and the R002-R004 warnings of a robot with a body."""
    from tlmpc.base.errors import InvalidInputError
    from tlmpc.mission.cspace import body_diagnostics

    found = body_diagnostics(mission, text)
    errors = [d for d in found if d.severity == "error"]
    if errors:
        raise InvalidInputError(errors)
    return found


def _abstraction(c: Compilation) -> StageResult:
    from tlmpc.abstraction import abstraction_diagnostics, build_abstraction
    from tlmpc.abstraction.build import mesh_size_diagnostic
    from tlmpc.abstraction.io import abstraction_document
    from tlmpc.abstraction.layout import planning_layout
    from tlmpc.mission.body import requested_margin

    mission = c.get(MISSION)
    # A body or a margin: the configuration space, goal cores and grown avoided regions are
    # triangulated (the body's own diagnostics came with the load stage).
    layout = planning_layout(mission, requested_margin(mission))
    abstraction = build_abstraction(mission, layout)
    return StageResult(
        products=provide(ABSTRACTION, abstraction),
        artifacts={"abstraction.json": abstraction_document(abstraction)},
        sizes={
            "triangles": abstraction.num_triangles,
            "vertices": int(abstraction.vertices.shape[0]),
            "letters": len(abstraction.letters),
        },
        warnings=tuple(abstraction_diagnostics(abstraction, mission))
        if layout is None or layout.free is None
        else tuple(d for d in [mesh_size_diagnostic(abstraction, mission)] if d is not None),
    )


def _automaton(c: Compilation) -> StageResult:
    from tlmpc.automata import automaton_to_json, to_hoa
    from tlmpc.planning.mission import automaton_for

    mission = c.get(MISSION)
    # A bounded task's automaton is its untimed skeleton's (the bounds are checked on the
    # simulated trajectory).  Under the closed convention the planner reads boundary
    # instants too (their letters and a rewritten task; see tlmpc/planning/boundary.py).
    automaton = automaton_for(mission, c.get(ABSTRACTION))
    return StageResult(
        products=provide(AUTOMATON, automaton),
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
    from tlmpc.abstraction.io import abstraction_document
    from tlmpc.automata import automaton_to_json, to_hoa
    from tlmpc.pipeline.mintime import plan_minimum_time
    from tlmpc.pipeline.shortest import plan_shortest
    from tlmpc.planning import witness_to_json

    built = c.get(ABSTRACTION)
    # The plan may need U-turns (a locally refined mesh) or, when no plan reaches the goal
    # depth or keeps the margin, the mesh and automaton without them: either replaces the
    # built one (and its artifacts) for every later stage.  Under the time metric the plan
    # is re-weighed with its exact simulated step times (tlmpc.pipeline.mintime).
    # Under the length metric the channel is chosen by its shortest path (pipeline.shortest);
    # the time metric's rounds start from that plan.
    planned = plan_minimum_time(c.get(MISSION), built, c.get(AUTOMATON), plan_shortest)
    planned = plan_shortest(c.get(MISSION), planned)
    abstraction, witness = planned.abstraction, planned.witness
    artifacts: dict[str, Any] = {}
    if planned.automaton is not c.get(AUTOMATON):  # without margin, or the durations held
        artifacts["automaton.json"] = automaton_to_json(planned.automaton)
        artifacts["automaton.hoa"] = to_hoa(planned.automaton)
    artifacts["witness.json"] = witness_to_json(witness, abstraction)
    if abstraction is not built:
        artifacts["abstraction.json"] = abstraction_document(abstraction)
    refined = abstraction.stats.get("split_for_u_turns", 0) != built.stats.get(
        "split_for_u_turns", 0
    )
    return StageResult(
        products={
            **provide(AUTOMATON, planned.automaton),
            **provide(ABSTRACTION, abstraction),
            **provide(WITNESS, witness),
        },
        warnings=planned.notes,
        artifacts=artifacts,
        sizes={
            "prefix": len(witness.prefix),
            "cycle": len(witness.cycle),
            "cost": round(witness.cost, 6),
            **(
                {
                    "exact time": round(witness.stats["exact_time"], 3),
                    "rounds": witness.stats["time_rounds"],
                }
                if "exact_time" in witness.stats
                else {}
            ),
            "product nodes": witness.stats.get("product_nodes"),
            "reached": witness.stats.get("product_reached"),
            **({"triangles after U-turn splits": abstraction.num_triangles} if refined else {}),
        },
    )


def _control(c: Compilation) -> StageResult:
    from tlmpc.control import controllers_to_json, synthesize

    mission = c.get(MISSION)
    abstraction = c.get(ABSTRACTION)
    witness = c.get(WITNESS)
    controllers = synthesize(
        abstraction,
        witness,
        mission.robot,
        source=mission.source,
        relevant=mission.formula.props(),
    )
    document = controllers_to_json(controllers)
    return StageResult(
        products=provide(CONTROLLERS, controllers),
        artifacts={"controllers.json": document},
        sizes={"steps": len(document["steps"]), "jumps": len(document.get("jumps", []))},
    )


def _simulate(c: Compilation) -> StageResult:
    from tlmpc.simulate import simulate, trace_to_json

    mission = c.get(MISSION)
    abstraction = c.get(ABSTRACTION)
    controllers = c.get(CONTROLLERS)
    trace = simulate(abstraction, controllers, mission)
    document = trace_to_json(trace, mission)
    points: list[list[float]] = document["points"]  # type: ignore[assignment]
    clearance, margin = _clearance(document, mission)
    from tlmpc.pipeline.deadlines import check_time_bounds, disturbed_bounds
    from tlmpc.verify.clearance import margin_warnings

    # Every time bound checked on the exact trajectory (P050/P051 when one is missed).
    bounds = check_time_bounds(mission, document, abstraction)
    warnings = list(margin_warnings(clearance, margin, mission.source))
    if bounds is not None and mission.robot.disturbance > 0.0:
        warnings.append(disturbed_bounds(mission, controllers))

    return StageResult(
        products=provide(TRACE, document),
        artifacts={"trace.json": document},
        sizes={"samples": len(points), "duration": round(float(points[-1][0]), 3)},
        warnings=tuple(warnings),
        summary={"clearance": clearance.to_json(margin), **(bounds or {})},
    )


def _clearance(document: Mapping[str, Any], mission: Mission) -> tuple[Clearance, float]:
    """The clearance and depth the trace achieved (measured on the trace alone), and the
    margin the mission asked for."""
    from tlmpc.mission.body import requested_margin
    from tlmpc.verify.clearance import measure
    from tlmpc.verify.trace_input import from_document

    return measure(from_document(dict(document))), requested_margin(mission)


#: A trace sampled again for its certificate has at most this many samples (a budget in
#: samples: beyond it the trace stays as simulated, verified but not certified).
MAX_CERTIFIED_SAMPLES = 2_000_000


def _verify(c: Compilation) -> StageResult:
    from tlmpc.verify import verdict_to_json, verify_document

    document = c.get(TRACE)
    verdict = verify_document(dict(document))
    verdict_json = verdict_to_json(verdict)
    if not verdict.satisfied:
        # The compiler's guarantee failed: that is a bug in tlmpc, never the user's fault.
        answer = _verdict_text(verdict)
        raise SelfCheckError(
            error(
                "I001",
                f"the compiled trajectory does not satisfy the task (self-check failed): "
                f"the verifier's answer is {answer}",
                hint="please report this mission; the artifacts were not written",
            ),
            reason=f"does not {'decide' if verdict.outcome == 'inconclusive' else 'satisfy'} "
            f"the task: the verifier's answer is {answer}",
            outcome=verdict.outcome,
        )
    certificate = verdict_json["certificate"]
    bound = certificate["max_speed"]
    if bound is not None and _outruns(document, bound):
        # The controllers promise |u| <= max_speed; a faster trace breaks the guarantee too.
        speeds = f"moves at {certificate['observed_speed']:.6g}, faster than max_speed {bound:.6g}"
        raise SelfCheckError(
            error(
                "I001",
                f"the compiled trajectory {speeds} (self-check failed)",
                hint="please report this mission; the artifacts were not written",
            ),
            reason=speeds,
        )
    # (after the self-checks: a trace faster than max_speed is not certified either, and no
    # denser sampling mends that)
    artifacts: dict[str, Any] = {}
    resampled_sizes: dict[str, Any] = {}
    resampled = _sampled_for_certificate(c, document, verdict_json)
    if resampled is not None:
        document, verdict_json = resampled
        artifacts["trace.json"] = document
        resampled_sizes["samples for the certificate"] = len(document["points"])
    artifacts["verdict.json"] = verdict_json
    return StageResult(
        products=provide(TRACE, document),
        artifacts=artifacts,
        sizes={"robustness": round(float(verdict_json["robustness"]), 6), **resampled_sizes},
    )


def _sampled_for_certificate(
    c: Compilation, document: Mapping[str, Any], verdict: Mapping[str, Any]
) -> tuple[dict[str, Any], dict[str, Any]] | None:
    """The trajectory sampled again, densely enough for the certificate, with its verdict,
    when the trace satisfies its task but is not certified; None when it is certified, when
    the denser trace would pass :data:`MAX_CERTIFIED_SAMPLES` or is not certified either.

    The certificate bounds every motion at ``max_speed`` between the samples (a tube of
    ``max_speed`` x gap / 2 round each): the simulation's samples follow its steps, so a
    long step in a wide triangle leaves gaps of a second or more, wider than a shallow
    visit.  No gap longer than robustness / (2 ``max_speed``) leaves a tube of a quarter of
    the robustness; the samples between are the same exact flow."""
    from tlmpc.simulate import simulate, trace_to_json
    from tlmpc.verify import verdict_to_json, verify_document

    certificate = verdict["certificate"]
    robustness = verdict["robustness"]
    speed = certificate["max_speed"]
    if (
        not verdict["satisfied"]
        or certificate["certified"]
        or speed is None
        or _outruns(document, speed)  # (denser samples would not mend that)
        or not isinstance(robustness, float)
        or not robustness > 0.0
    ):
        return None
    max_gap = robustness / (2.0 * speed)
    points: list[list[float]] = document["points"]
    duration = float(points[-1][0]) - float(points[0][0])
    if len(points) + duration / max_gap > MAX_CERTIFIED_SAMPLES:
        return None
    mission, controllers = c.find(MISSION), c.find(CONTROLLERS)
    if mission is None or controllers is None:  # a trace verified on its own
        return None
    trace = simulate(c.get(ABSTRACTION), controllers, mission, max_gap=max_gap)
    denser = trace_to_json(trace, mission)
    dense_verdict = verdict_to_json(verify_document(dict(denser)))
    if not (dense_verdict["satisfied"] and dense_verdict["certificate"]["certified"]):
        return None
    return denser, dense_verdict


def _verdict_text(verdict: Verdict) -> str:
    """The verifier's answer in its own words (as `tlmpc verify` prints it): its outcome and
    every violation (of the task or of the workspace), or for an inconclusive verdict what
    each conjunct has seen so far."""
    if verdict.violations:
        details = [violation.message for violation in verdict.violations]
    else:
        details = [f"{r.conjunct}: {r.outcome}: {r.progress}" for r in verdict.conjuncts]
    return f"{verdict.outcome}" + (f" ({'; '.join(details)})" if details else "")


def _outruns(trace: Mapping[str, Any], speed: float) -> bool:
    """Whether some chord between consecutive samples is longer than ``speed`` allows over
    its time (the verifier's speed check, :func:`tlmpc.verify.robustness.speed_excess`)."""
    import numpy as np

    from tlmpc.verify.robustness import speed_excess

    samples = np.asarray(trace["points"], dtype=np.float64).reshape(-1, 3)
    return bool(speed_excess(samples[:, 0], samples[:, 1:], speed).any())


def _synthesize(c: Compilation) -> StageResult:
    from tlmpc.abstraction.io import abstraction_document
    from tlmpc.reactive.synthesize import (
        counterstrategy_to_json,
        strategy_to_json,
        synthesize_on_regions,
        unrealizable,
    )
    from tlmpc.reactive.unrealizable import UnrealizableError

    mission = c.get(MISSION)
    built = c.get(ABSTRACTION)
    # unrealizable on the goal cores or grown regions: solved again on the regions as they
    # are, whose mesh (and abstraction.json) then replaces the built one
    synthesis, abstraction, notes = synthesize_on_regions(mission, built)
    artifacts: dict[str, Any] = {}
    if abstraction is not built:
        artifacts["abstraction.json"] = abstraction_document(abstraction)
    if not synthesis.realizable:
        if synthesis.counter is not None:
            artifacts["counterstrategy.json"] = counterstrategy_to_json(synthesis, abstraction)
        # compile writes every artifact so far (the environment's play is drawn on them);
        # `tlmpc stage synthesize` only what this stage made
        shown = {**c.documents, **artifacts}
        raise UnrealizableError(unrealizable(synthesis, mission), shown, produced=artifacts)
    assert synthesis.size is not None
    assert synthesis.symbolic is not None
    game = synthesis.game
    artifacts["strategy.json"] = strategy_to_json(synthesis)
    return StageResult(
        products=provide(ABSTRACTION, abstraction),
        warnings=notes,
        artifacts=artifacts,
        sizes={
            "faces": game.faces.count,
            "variables": len(game.spec.variables),
            "parts": len(game.spec.parts),
            "fixpoint steps": synthesis.solution.cpre_count,
            "strategy nodes": synthesis.size.nodes,
            "strategy transitions": synthesis.size.transitions,
            "strategy diagram nodes": len(synthesis.symbolic.diagram.nodes),
        },
        summary={"reactive": {"realizable": True, "faces": game.faces.count}},
    )


def _plot(c: Compilation) -> StageResult:
    # Drawn from the artifacts themselves (the same code as `tlmpc plot`), so the picture
    # always shows what was written.
    # plan.svg is written directly (cheap); plan.png needs matplotlib, so only on request.
    from tlmpc.render.plot import render_png, render_svg

    pictures: dict[str, bytes] = {}
    if "svg" in c.figures:
        pictures["plan.svg"] = render_svg(c.documents)
    if "png" in c.figures:
        pictures["plan.png"] = render_png(c.documents)
    return StageResult(
        artifacts=pictures,
        sizes={f"{name[5:]} bytes": len(data) for name, data in pictures.items()},
    )


class SelfCheckError(TlmpcError):
    """The verifier rejected a trace the compiler produced (an internal error, exit 3);
    ``reason`` says what is wrong with the trajectory, whoever made it, and ``outcome`` is the
    verifier's (``violated`` also for a trace faster than ``max_speed``)."""

    exit_code = 3

    def __init__(self, diagnostic: Diagnostic, *, reason: str, outcome: str = "violated") -> None:
        super().__init__(diagnostic)
        self.reason = reason
        self.outcome = outcome


class InconclusiveTraceError(InvalidInputError):
    """A trajectory read from a folder on which the verifier's answer is ``inconclusive``
    (exit 4, as `tlmpc verify` gives it)."""

    exit_code = EXIT_INCONCLUSIVE


_STATIC: frozenset[World] = frozenset({"static"})

STAGES: tuple[Stage, ...] = (
    Stage(name="load", run=_load, provides=(MISSION,), aliases=("mission",)),
    Stage(name="abstraction", run=_abstraction, requires=(MISSION,), provides=(ABSTRACTION,)),
    Stage(
        name="synthesize",
        run=_synthesize,
        requires=(MISSION, ABSTRACTION),
        # the mesh of the regions as they are, when the goal cores or grown regions leave
        # the robot no strategy
        provides=(ABSTRACTION,),
        aliases=("strategy", "game"),
        worlds=frozenset({"reactive"}),
    ),
    Stage(
        name="automaton",
        run=_automaton,
        requires=(MISSION, ABSTRACTION),
        provides=(AUTOMATON,),
        worlds=_STATIC,
    ),
    Stage(
        name="plan",
        run=_plan,
        requires=(MISSION, ABSTRACTION, AUTOMATON),
        # the mesh refined where the plan turns around, and the mesh and automaton rebuilt
        # without the margin when no plan keeps it (or the automaton of a task's durations
        # held for good, tlmpc.ltl.bounds.holding_skeleton)
        provides=(WITNESS, ABSTRACTION, AUTOMATON),
        aliases=("witness", "planning"),
        worlds=_STATIC,
    ),
    Stage(
        name="control",
        run=_control,
        requires=(MISSION, ABSTRACTION, WITNESS),
        provides=(CONTROLLERS,),
        aliases=("controllers",),
        worlds=_STATIC,
    ),
    Stage(
        name="simulate",
        run=_simulate,
        requires=(MISSION, ABSTRACTION, CONTROLLERS),
        provides=(TRACE,),
        aliases=("trace",),
        worlds=_STATIC,
    ),
    Stage(
        name="verify",
        run=_verify,
        requires=(TRACE,),
        provides=(TRACE,),  # sampled again when that makes the certificate hold
        aliases=("verdict",),
        worlds=_STATIC,
    ),
    Stage(
        name="plot",
        run=_plot,
        requires=(MISSION, ABSTRACTION, WITNESS, TRACE),
        worlds=_STATIC,
    ),
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
    extras: Mapping[str, Any] = field(default_factory=dict)  # from the stages' ``summary``

    def summary(self) -> dict[str, Any]:
        """The ``summary.json`` document (``tlmpc.summary/1``)."""
        mission = self.compilation.find(MISSION)
        witness = self.compilation.find(WITNESS)
        summary: dict[str, Any] = {
            "format": "tlmpc.summary/1",
            "tool": {"name": "tlmpc", "version": __version__},
            "mission": mission.name if mission else None,
            "source": str(self.compilation.source),
            "formula": str(mission.formula) if mission else None,
            "stages": [
                {"name": r.name, "seconds": round(r.seconds, 6), "sizes": dict(r.sizes)}
                for r in self.reports
            ],
            "total_seconds": round(sum(r.seconds for r in self.reports), 6),
            "artifacts": sorted([*self.artifacts, "summary.json"]),
            "warnings": [w.to_json() for w in self.warnings],
        }
        if witness is not None:
            summary["plan"] = {
                "prefix_length": len(witness.prefix),
                "cycle_length": len(witness.cycle),
                "stay": witness.is_stay,
                "cost": witness.cost,
                "metric": witness.metric,
            }
        summary.update(self.extras)
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


def run_stages(
    stages: Sequence[Stage],
    compilation: Compilation,
    *,
    progress: ProgressFn | None = None,
) -> CompileResult:
    """Run ``stages`` in order on ``compilation``, checking each one's requires and provides.

    The run has one memo (:mod:`tlmpc.base.memo`: what its stages compute once and reuse,
    such as a mesh's convex cells), dropped when it ends; a run inside an open memo (a caller
    running the stages one at a time) shares that one.  The stages' arrays are allocated
    without numpy's huge-page request (:mod:`tlmpc.base.pages`: at a million triangles the
    kernel's compaction on first touch cost about 3 CPU s of the compile)."""
    with plain_pages(), memo_scope(current_memo()):
        return _run_stages(stages, compilation, progress=progress)


def _run_stages(
    stages: Sequence[Stage],
    compilation: Compilation,
    *,
    progress: ProgressFn | None = None,
) -> CompileResult:
    artifacts: dict[str, Any] = dict(compilation.documents)
    written: dict[str, Any] = {}
    products: dict[Product[Any], Any] = dict(compilation.products)
    reports: list[StageReport] = []
    warnings: list[Diagnostic] = []
    extras: dict[str, Any] = {}
    index = 0
    for stage in stages:
        mission = products.get(MISSION)
        if mission is not None and world_of(mission) not in stage.worlds:
            continue
        index += 1
        for product in stage.requires:
            compilation.get(product)  # a clear error instead of a failure deep inside
        started = time.perf_counter()
        try:
            with heartbeat(stage.name, sys.stderr) if progress else contextlib.nullcontext():
                result = stage.run(compilation)
        except TlmpcError as exc:
            exc.diagnostics = _placed(exc.diagnostics, compilation)
            raise
        report = StageReport(
            name=stage.name, seconds=time.perf_counter() - started, sizes=result.sizes
        )
        missing = [p.name for p in stage.provides if p not in result.products]
        undeclared = [p.name for p in result.products if p not in stage.provides]
        if missing or undeclared:  # a programming error: the stage list and the stage disagree
            raise RuntimeError(
                f"stage {stage.name} does not provide what it declares (missing: "
                f"{', '.join(missing) or '-'}; undeclared: {', '.join(undeclared) or '-'})"
            )
        products.update(result.products)
        artifacts.update(result.artifacts)
        written.update(result.artifacts)
        compilation = dataclasses.replace(
            compilation, products=dict(products), documents=dict(artifacts)
        )
        warnings.extend(_placed(result.warnings, compilation))
        extras.update(result.summary)
        reports.append(report)
        if progress is not None:
            world = world_of(products[MISSION]) if MISSION in products else None
            total = sum(1 for s in stages if world is None or world in s.worlds)
            progress(index, total, report)
    return CompileResult(
        compilation=compilation,
        artifacts=written,
        reports=tuple(reports),
        warnings=tuple(warnings),
        extras=extras,
    )


def _placed(
    diagnostics: tuple[Diagnostic, ...], compilation: Compilation
) -> tuple[Diagnostic, ...]:
    """The stage's diagnostics of the mission file with the line and column of the value
    their JSON path names (a later stage knows the value, not where it is written); one that
    names no file is about the mission compiled (a planner's budget, say), and names it."""
    from tlmpc.mission.placement import placed

    source = str(compilation.source)
    mission = compilation.find(MISSION)
    if mission is not None and any(d.code == "P041" and d.file is None for d in diagnostics):
        from tlmpc.mission.load import place_translation_refusal

        # the translation knows the formula, not which entry of the file wrote it
        diagnostics = tuple(
            place_translation_refusal(d, mission, compilation.text)
            if d.code == "P041" and d.file is None
            else d
            for d in diagnostics
        )
    named = tuple(
        d if d.file is not None else dataclasses.replace(d, file=source) for d in diagnostics
    )
    return placed(named, source, compilation.text)


def compile_mission(
    source: Path | str,
    *,
    text: str | None = None,
    until: str | None = None,
    progress: ProgressFn | None = None,
    figures: tuple[str, ...] = ("svg",),
) -> CompileResult:
    """Run the stages of :data:`STAGES` (up to ``until``) on the mission file ``source``.

    With ``text``, the mission is that YAML text and ``source`` only names it in diagnostics.
    ``figures`` names the pictures the plot stage draws (``"svg"``, ``"png"``).  Raises the
    stage's :class:`~tlmpc.base.errors.TlmpcError` when one fails; nothing is written here (the
    CLI writes the returned artifacts atomically).
    """
    compilation = Compilation(source=Path(source), text=text, figures=figures)
    return run_stages(stages_until(until), compilation, progress=progress)


def stage_named(name: str) -> Stage:
    """The stage called ``name`` (or one of its aliases); ValueError when there is none."""
    for stage in STAGES:
        if name == stage.name or name in stage.aliases:
            return stage
    raise ValueError(name)


def compilation_from_artifacts(directory: Path, needed: Sequence[Product[Any]]) -> Compilation:
    """A compilation holding the ``needed`` products, read from the artifacts in ``directory``.

    Every artifact is checked against its schema first; a missing or invalid one is a
    diagnostic naming the file.
    """
    from tlmpc.io.artifacts import cross_check, read_artifact

    products: dict[Product[Any], Any] = {}
    documents: dict[str, Any] = {}
    for product in needed:
        path = directory / product.artifact
        if not path.is_file():
            raise MissingProductError(
                error(
                    "U070",
                    f"{path} is missing: the {product.name} is needed",
                    file=str(path),
                    hint="run the earlier stages first (tlmpc compile --until ...)",
                )
            )
        documents[product.artifact] = read_artifact(path, product.schema)
    if MISSION.artifact in documents:
        _refuse_unusable_shapes(directory / MISSION.artifact, documents[MISSION.artifact])
    # before any is used: the artifacts must agree (indices in range, one mission)
    cross_check(directory, documents)
    for product in needed:
        products[product] = product.read(documents[product.artifact])
    _refuse_unguaranteed(directory, documents, products)
    source = Path(str(documents.get("mission.json", {}).get("source") or directory))
    return Compilation(source=source, products=products, documents=documents)


def _refuse_unusable_shapes(path: Path, document: Mapping[str, Any]) -> None:
    """Refuse (U042, at mission.json) the shapes a mission file could not hold: a polygon that
    is not simple, has no area or too few corners, a region or hole outside the boundary, a
    start outside the workspace.  The load stage refused them in the mission; an edited
    mission.json would otherwise reach the triangulation and GEOS (exit 3)."""
    from tlmpc.mission.geometry import check_layout, check_shape
    from tlmpc.mission.shapes import CheckedShape

    file = str(path)
    found: list[Diagnostic] = []

    def unplaced(keys: tuple[str | int, ...]) -> tuple[int, int]:
        return (0, 0)  # positions in the mission's YAML; the refusal names the JSON path

    def checked(points: Any, keys: tuple[str | int, ...], what: str) -> CheckedShape | None:
        shape, problems = check_shape(points, keys, what, file, unplaced)
        found.extend(problems)
        return shape

    workspace = document["workspace"]
    boundary = checked(workspace["boundary"], ("workspace", "boundary"), "workspace boundary")
    holes = [
        checked(hole, ("workspace", "holes", i), f"hole {i + 1}")
        for i, hole in enumerate(workspace["holes"])
    ]
    components = [
        (
            checked(c["boundary"], ("workspace", "components", k, "boundary"), f"component {k}"),
            [
                checked(hole, ("workspace", "components", k, "holes", i), f"hole {i + 1}")
                for i, hole in enumerate(c["holes"])
            ],
        )
        for k, c in enumerate(workspace.get("components", ()))
    ]
    regions = {
        name: checked(points, ("regions", name), f"region {name!r}")
        for name, points in document["regions"].items()
    }
    if document["robot"].get("footprint"):
        checked(document["robot"]["footprint"], ("robot", "footprint"), "robot footprint")
    if not found:  # every shape usable: their relations
        start = document["robot"]["start"]
        found = check_layout(
            boundary,
            [h for h in holes if h is not None],
            {name: shape for name, shape in regions.items() if shape is not None},
            (float(start[0]), float(start[1])),
            ("robot", "start"),
            file,
            unplaced,
            components=[
                (b, [h for h in hs if h is not None]) for b, hs in components if b is not None
            ],
        )
    refused = [
        error(
            "U042",
            f"mission.json holds a shape no mission can: {problem.message}",
            hint="this output was edited or damaged; compile the mission again",
            file=file,
            path=problem.path,
        )
        for problem in found
        if problem.severity == "error"
    ]
    if refused:
        raise UsageError(refused)


def _refuse_unguaranteed(
    directory: Path, documents: Mapping[str, Any], products: Mapping[Product[Any], Any]
) -> None:
    """Refuse (U042, at the artifact) a witness or controllers read from ``directory`` that
    break what the control stage guarantees: inside a compile a stage that fails on them is a
    bug in tlmpc (exit 3), but an edited artifact is the user's input."""
    from tlmpc.control.recheck import refuse_edited

    controllers_document = documents.get(CONTROLLERS.artifact)
    refuse_edited(
        directory,
        products.get(MISSION),
        products.get(ABSTRACTION),
        products.get(WITNESS),
        products.get(CONTROLLERS),
        None if controllers_document is None else controllers_document["steps"],
    )


def run_stage_from_artifacts(
    name: str, directory: Path, *, progress: ProgressFn | None = None
) -> CompileResult:
    """Run the one stage ``name`` on the input artifacts found in ``directory``."""
    stage = stage_named(name)
    # the mission's kind first (also for a stage that does not read mission.json): a stage of
    # the other kind would ask for artifacts that no compile of this mission writes
    mission = (
        compilation_from_artifacts(directory, (MISSION,)).get(MISSION)
        if (directory / MISSION.artifact).is_file()
        else None
    )
    if mission is not None and world_of(mission) not in stage.worlds:
        raise MissingProductError(
            error(
                "U076",
                f"the {stage.name} stage does not apply to this mission "
                f"(a {world_of(mission)} mission)",
                hint="the synthesize stage lowers reactive missions (with sensors); automaton, "
                "plan, control, simulate, verify and plot lower the others",
                file=str(directory / MISSION.artifact),
            )
        )
    compilation = compilation_from_artifacts(directory, stage.requires)
    try:
        return run_stages([stage], compilation, progress=progress)
    except SelfCheckError as exc:
        # artifacts read from a folder may have been edited by hand: a trace that fails its
        # re-check is the folder's answer (as `tlmpc verify` gives it), not a compiler bug
        answer = InconclusiveTraceError if exc.outcome == "inconclusive" else InvalidInputError
        raise answer(
            error(
                "U077",
                f"the trajectory in {TRACE.artifact} {exc.reason}",
                hint=f"compare with `tlmpc verify {directory / TRACE.artifact}`; compile "
                "the mission again for a trajectory that meets it",
                file=str(directory / TRACE.artifact),
            )
        ) from None
