"""Planning a mission: the one entry that compile and the runtime executor both call.

Only this module knows how the pieces of planning fit together for a mission:

* the **margin**: the mesh is built from the mission's planning layout (configuration space,
  goal cores, grown avoided regions; :mod:`tlmpc.abstraction.layout`), and when no plan keeps
  the margin the mission is planned again without it, with the warning R008;
* the **boundary convention**: the automaton is always :func:`automaton_for` the mission and
  the mesh, so under ``closed`` every attempt, the fallback included, reads the crossing and
  start letters and the rewritten task (:mod:`tlmpc.planning.boundary`);
* **completeness**: U-turn refinement and vertex passages (:func:`plan_complete`);
* the product-size budget (:func:`check_product_size`, charged by :func:`plan_complete`).

A re-plan of a run under way (``resume``) keeps the mesh and automaton the run was compiled
with (the executor's triangles and automaton states refer to them) and so never drops the
margin nor changes the goal depth; it may still refine the mesh for a U-turn, and then returns
the refined one. Under a disturbance its ladder is the compile's on that mesh: the triangles,
their realisable steps, then the convex cells of the mesh (a run compiled on the cells' own
mesh has that mesh).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import TypedDict

from tlmpc.abstraction.lines import Lines
from tlmpc.abstraction.model import Abstraction
from tlmpc.automata.model import Automaton
from tlmpc.base.errors import Diagnostic, NoPlanError
from tlmpc.ltl.ast import Formula
from tlmpc.mission.model import Mission, Options, TaskPart
from tlmpc.planning.model import Witness
from tlmpc.planning.robust import witness_realisable
from tlmpc.planning.timing import MoveTimes


@dataclass(frozen=True, slots=True, kw_only=True)
class Planned:
    """A planned mission: the mesh the witness refers to (refined where the plan turns
    around, or rebuilt without the margin), the automaton it was planned with, the witness,
    and notes (A030 when the goal depth was dropped, A040 when it yielded to the disturbance,
    R008 when the margin was dropped)."""

    abstraction: Abstraction
    automaton: Automaton
    witness: Witness
    notes: tuple[Diagnostic, ...] = ()
    #: the untimed task the plan was made for (the skeleton, or the holding skeleton)
    formula: Formula | None = None
    #: the mesh the plan was asked on, before any refinement for a U-turn (the convex cells'
    #: rung plans on it: a fan's triangles split the cells a U-turn needs none of)
    unrefined: Abstraction | None = None

    def route(self) -> tuple[int, tuple[int, ...], tuple[int, ...], tuple[tuple[int, int], ...]]:
        """What makes two plans the same route (the re-plan loops' fixed point): the mesh's
        size, the triangles visited and the vertex passages."""
        w = self.witness
        return (self.abstraction.num_triangles, w.prefix, w.cycle, w.passages)


def abstraction_for(
    mission: Mission, margin: float, *, deep: bool = True, scale: float = 1.0
) -> Abstraction:
    """The triangulated workspace of ``mission`` planned with ``margin`` (and its body), and
    with ``deep`` the goal depth (times ``scale``)."""
    from tlmpc.abstraction import build_abstraction
    from tlmpc.abstraction.layout import planning_layout

    return build_abstraction(mission, planning_layout(mission, margin, deep=deep, scale=scale))


def automaton_for(
    mission: Mission, abstraction: Abstraction, *, formula: Formula | None = None
) -> Automaton:
    """The task's automaton over the letters the planner reads on ``abstraction``
    (``formula``: another untimed task of the mission's, planned instead).

    Under the closed convention: the rewritten task over the mesh's letters plus the
    crossing and start letters; under the right-continuous one the task over the mesh's.
    """
    from tlmpc.automata import translate
    from tlmpc.ltl.bounds import untimed_skeleton
    from tlmpc.planning.boundary import task_formula, task_letters

    convention = mission.options.boundary
    # A bounded task is planned on its untimed skeleton; its bounds are checked on the
    # compiled trajectory (tlmpc.pipeline.deadlines).
    task = untimed_skeleton(mission.formula) if formula is None else formula
    return translate(
        task_formula(task, convention),
        letters=task_letters(abstraction, convention, mission.robot.start),
    )


def plan_mission(
    mission: Mission,
    abstraction: Abstraction,
    automaton: Automaton,
    *,
    parts: Callable[[], Sequence[TaskPart]] | None = None,
    resume: frozenset[int] | None = None,
    start_point: tuple[float, float] | None = None,
) -> Planned:
    """A plan for ``mission`` on ``abstraction`` (built with the requested margin) and
    ``automaton`` (:func:`automaton_for` it).

    Raises :class:`NoPlanError` only when no trajectory of the robot satisfies the task: then
    with the explanation of the plan without margin and the body's passage diagnostics.
    ``parts`` gives the task's parts for that explanation (default: the mission's).
    ``resume`` re-plans a run under way from ``abstraction.start`` at ``start_point``, the
    (degeneralized) automaton being in one of these states; it never drops the margin.
    """
    from tlmpc.ltl.bounds import holding_skeleton, untimed_skeleton
    from tlmpc.mission.body import requested_margin

    skeleton = untimed_skeleton(mission.formula)
    times = move_times(mission)

    def attempt(
        mesh: Abstraction, task: Automaton, formula: Formula = skeleton, explain: bool = True
    ) -> Planned:
        # plan_complete charges every mesh against the budget (P040) before building its
        # product, and answers an unreachable goal exactly even beyond it
        first = complete(mesh, task, formula, explain, None)
        ratio = mission.robot.disturbance / mission.robot.max_speed
        if witness_realisable(first.abstraction, first.witness, ratio):
            return first
        # A step no controller realises (a needle, or a corner too sharp for the
        # disturbance): plan again on the steps that are realisable, where the mesh has
        # enough of them; otherwise the control stage states the plan's true bound.
        from tlmpc.planning.complete import RefinementError

        try:
            return complete(mesh, task, formula, explain, ratio)
        except (NoPlanError, RefinementError):
            # U-turn fans may have no realisable route either. The control stage refuses
            # this plan (C032) and states the largest disturbance any plan on its mesh rejects
            # (a run under way states nothing: it goes on to the cells of its mesh, or stops).
            if resume is not None:
                return first
            return _with_supported(first, mission, formula, start_point)

    def complete(
        mesh: Abstraction, task: Automaton, formula: Formula, explain: bool, reject: float | None
    ) -> Planned:
        from tlmpc.planning.complete import plan_complete

        planned_mesh, witness = plan_complete(
            mesh,
            task,
            formula=formula,
            options=mission.options,
            start_point=start_point if start_point is not None else mission.robot.start,
            parts=parts if parts is not None else (lambda: _task_parts(mission)),
            file=mission.source,
            resume=resume,
            explain=explain and resume is None and reject is None,
            reject=reject,
            times=times,
        )
        return Planned(
            abstraction=planned_mesh,
            automaton=task,
            witness=witness,
            formula=formula,
            unrefined=mesh,
        )

    from tlmpc.abstraction.layout import deepens_goals

    margin = requested_margin(mission)

    def on_cells_rung(planned: Planned) -> Planned:
        """``planned``'s task on the convex cells of its mesh, then of the cells' own mesh;
        else ``planned`` with the bound on cells (the control stage refuses it, C032)."""
        on_cells = _on_cells(mission, planned, start_point, resume)
        if on_cells is not None:
            return on_cells
        on_lines, lines_bound = _on_lines(mission, margin, planned, start_point)
        if on_lines is not None:
            return on_lines
        refused = _with_cells_supported(planned, mission, start_point)
        return _with_cells_bound(refused, lines_bound, mission)

    def realisable_depth(
        planned: Planned, formula: Formula = skeleton, explain: bool = True
    ) -> Planned:
        """The goal depth yields to the disturbance: when the plan to the goal cores has a
        step no controller realises, plan again to shallower cores (half, then a quarter of
        the goal depth), then entering the goals only as deep as the margin asks (the cores'
        corners may be all that is too sharp); the first plan whose steps all realise it."""
        ratio = mission.robot.disturbance / mission.robot.max_speed
        if ratio <= 0.0 or witness_realisable(planned.abstraction, planned.witness, ratio):
            return planned
        if resume is not None:
            # A run under way keeps the mesh it was compiled with (its triangles and automaton
            # states refer to it): of the ladder's rungs, the convex cells of that mesh are
            # left, from the robot's cell and the tracked states. None: the control stage
            # refuses the triangles' plan and the run stops.
            return _on_cells(mission, planned, start_point, resume) or planned
        if not deepens_goals(mission):
            return on_cells_rung(planned)
        tried = [planned]
        for scale in (*SHALLOWER, 0.0):
            mesh = abstraction_for(mission, margin, deep=scale > 0.0, scale=scale)
            try:
                again = attempt(
                    mesh, automaton_for(mission, mesh, formula=formula), formula, explain
                )
            except NoPlanError:
                continue
            if witness_realisable(again.abstraction, again.witness, ratio):
                note = _shallow_for_disturbance(mission, planned.witness, scale)
                return replace(again, notes=(note,))
            tried.append(again)
        # None realises the disturbance on triangles: the last rung, convex cells, on each
        # mesh in turn (the goal depth first).
        for tried_plan in tried:
            on_cells = _on_cells(mission, tried_plan, start_point)
            if on_cells is not None:
                return on_cells
        on_lines, lines_bound = _on_lines(mission, margin, planned, start_point)
        if on_lines is not None:
            return on_lines
        # None realises it on cells either: the plan on the mesh whose plans reject the most
        # goes on to be refused, stating that mesh's bound (C032: the mission compiles below it)
        # and the cells' (the largest over the meshes tried).
        tried = [_with_cells_supported(plan, mission, start_point) for plan in tried]
        bounds = [_supported_of(plan.witness) for plan in tried]
        best = max(range(len(tried)), key=lambda k: (bounds[k] is not None, bounds[k] or 0.0, -k))
        cells_bounds = [plan.witness.stats.get(SUPPORTED_CELLS) for plan in tried]
        known = [float(b) / mission.robot.max_speed for b in cells_bounds if b is not None]
        if lines_bound is not None:
            known.append(lines_bound)
        return _with_cells_bound(tried[best], max(known) if known else None, mission)

    holding = holding_skeleton(mission.formula)
    durations = resume is None and holding != skeleton

    def held(mesh: Abstraction) -> Planned | None:
        """The plan of the task's durations held for good on ``mesh`` (None: it has none);
        tried on every mesh before the skeleton's, since the skeleton's plan may leave a goal
        at once and miss the duration."""
        if not durations:
            return None
        try:
            return attempt(mesh, automaton_for(mission, mesh, formula=holding), holding, False)
        except NoPlanError:
            return None

    # Durations ("stay in X for at least T s") are met by a plan that stays for good, when
    # there is one; else the skeleton's plan, whose bounds are then checked.
    staying = held(abstraction)
    if staying is not None:
        try:
            return realisable_depth(staying, holding, False)
        except NoPlanError:
            pass

    try:
        return realisable_depth(attempt(abstraction, automaton))
    except NoPlanError as failure:
        if resume is not None:
            raise
        first = failure.with_traceback(None)  # kept: no cycle through this frame's traceback
    if deepens_goals(mission):
        # the goal depth is an objective: plan again reaching the goals only as deep as the
        # margin asks (overlapping goals' cores may not meet where the regions do)
        shallow = abstraction_for(mission, margin, deep=False)
        try:
            planned = held(shallow) or attempt(shallow, automaton_for(mission, shallow))
        except NoPlanError as again:
            first = again.with_traceback(None)
        else:
            ratio = mission.robot.disturbance / mission.robot.max_speed
            if ratio > 0.0 and not witness_realisable(planned.abstraction, planned.witness, ratio):
                # the shallow plan must carry the disturbance too: the cells' rung, as for
                # any plan without goal cores
                planned = on_cells_rung(planned)
            notes = (_shallow_note(mission, first), *planned.notes)
            return replace(planned, notes=notes)
    if margin <= 0.0:
        raise _with_body_notes(first, mission) from None
    plain = abstraction_for(mission, 0.0, deep=False)
    try:
        planned = held(plain) or attempt(plain, automaton_for(mission, plain))
    except NoPlanError as again:
        raise _with_body_notes(again, mission) from None
    planned = _with_cells_supported(planned, mission, start_point)
    from tlmpc.mission.body import MARGIN_PATH

    reason = first.diagnostics[0].message if first.diagnostics else "no plan"
    note = Diagnostic(
        code="R008",
        severity="warning",
        message=f"no plan keeps the margin {margin:g} ({reason}); planned without it",
        hint="the R006/R007 warnings, if any, say where the path comes closer; lower "
        "options.margin to plan with a smaller one",
        file=mission.source,
        path=MARGIN_PATH,
    )
    return replace(planned, notes=(note,))


def move_times(mission: Mission, measured: MoveTimes | None = None) -> MoveTimes | None:
    """What the ``time`` metric weighs moves with for ``mission`` (None under the other
    metrics): ``measured`` when given, else the estimates at the robot's top speed."""
    if mission.options.cost != "time":
        return None
    return measured if measured is not None else MoveTimes(speed=mission.robot.max_speed)


class PlanArguments(TypedDict):
    """The keyword arguments of :func:`~tlmpc.planning.plan.plan` and
    :func:`~tlmpc.planning.complete.plan_complete` that plan a plan's task again."""

    formula: Formula
    options: Options
    start_point: tuple[float, float]
    times: MoveTimes | None


def again(
    mission: Mission,
    planned: Planned,
    times: MoveTimes | None,
    start_point: tuple[float, float] | None = None,
) -> PlanArguments:
    """What plans ``planned``'s task again for ``mission``: its task (the mission's untimed
    skeleton when it has none of its own), the mission's options, ``start_point`` (the
    robot's start when None) and the moves weighing ``times`` (the one place that spells
    them out for a re-plan, the cells' rung and the touch candidate)."""
    formula = planned.formula
    if formula is None:
        from tlmpc.ltl.bounds import untimed_skeleton

        formula = untimed_skeleton(mission.formula)
    return PlanArguments(
        formula=formula,
        options=mission.options,
        start_point=mission.robot.start if start_point is None else start_point,
        times=times,
    )


def replan(mission: Mission, planned: Planned, times: MoveTimes) -> Planned:
    """``planned`` planned again with the moves weighing ``times``: on its own mesh, with its
    own automaton and task (no fallback: the plan it replaces exists there), U-turn
    refinement and vertex passages as the first plan needed them."""
    from tlmpc.planning.complete import plan_complete

    arguments = again(mission, planned, times)
    ratio = mission.robot.disturbance / mission.robot.max_speed

    def attempt(reject: float | None, cells: bool = False) -> tuple[Abstraction, Witness]:
        return plan_complete(
            planned.abstraction,
            planned.automaton,
            **arguments,
            explain=False,
            reject=reject,
            on_cells=cells,
        )

    if on_cells(planned.witness):
        # planned on cells: so again (the plan it replaces exists there)
        mesh, witness = attempt(ratio, cells=True)
        from tlmpc.planning.cells import partition, witness_on_cells
        from tlmpc.planning.robust import TOLERANCE

        if witness_on_cells(
            partition(mesh), witness.prefix, witness.cycle, witness.is_stay, ratio, TOLERANCE
        ):
            witness = replace(witness, stats={**witness.stats, ON_CELLS: True})
            return replace(planned, abstraction=mesh, witness=witness)
        return planned
    mesh, witness = attempt(None)
    if not witness_realisable(mesh, witness, ratio):
        mesh, witness = attempt(ratio)
    return replace(planned, abstraction=mesh, witness=witness)


def _shallow_note(mission: Mission, failure: NoPlanError) -> Diagnostic:
    reason = failure.diagnostics[0].message if failure.diagnostics else "no plan"
    return Diagnostic(
        code="A030",
        severity="note",
        message=f"no plan reaches the goal depth ({reason}); planned to enter the goals only "
        "as deep as the margin asks",
        hint="goals that overlap only near their edges have deep parts that do not meet; "
        "set options.goal_depth to a smaller depth (0: the margin's) to plan with it",
        file=mission.source,
    )


#: The witness statistic that carries the largest disturbance any plan on its mesh rejects
#: (in the units of robot.disturbance), set only on a plan with a step that does not reject the
#: mission's: the control stage states it when it refuses the plan (C032).
SUPPORTED = "supported_disturbance"


def _with_supported(
    planned: Planned, mission: Mission, formula: Formula, start_point: tuple[float, float] | None
) -> Planned:
    """``planned`` with the largest disturbance any plan on its mesh rejects in its
    witness's statistics (:mod:`tlmpc.planning.bottleneck`), when that can be computed."""
    from tlmpc.planning.bottleneck import supported_ratio

    ratio = supported_ratio(
        planned.abstraction,
        planned.automaton,
        formula=formula,
        options=mission.options,
        start_point=start_point if start_point is not None else mission.robot.start,
    )
    if ratio is None:
        return planned
    stats = {**planned.witness.stats, SUPPORTED: ratio * mission.robot.max_speed}
    return replace(planned, witness=replace(planned.witness, stats=stats))


def _with_cells_supported(
    planned: Planned, mission: Mission, start_point: tuple[float, float] | None
) -> Planned:
    """``planned``, a plan about to be refused with its mesh's bound (SUPPORTED), with the
    largest disturbance plans on the convex cells of its mesh reject (SUPPORTED_CELLS, within
    the cells' budget). Computed only here, for a refusal: a plan the cells' rung then
    carries never needs it."""
    stats = planned.witness.stats
    if SUPPORTED not in stats or SUPPORTED_CELLS in stats:
        return planned
    from tlmpc.ltl.bounds import untimed_skeleton
    from tlmpc.planning.bottleneck import supported_ratio
    from tlmpc.planning.cells import MAX_TRIANGLES

    if planned.abstraction.num_triangles > MAX_TRIANGLES:
        return planned
    on_cells = supported_ratio(
        planned.abstraction,
        planned.automaton,
        formula=planned.formula
        if planned.formula is not None
        else untimed_skeleton(mission.formula),
        options=mission.options,
        start_point=start_point if start_point is not None else mission.robot.start,
        cells=True,
    )
    if on_cells is None:
        return planned
    value = on_cells * mission.robot.max_speed
    return replace(
        planned, witness=replace(planned.witness, stats={**stats, SUPPORTED_CELLS: value})
    )


#: The witness statistic of the bound on cells (:mod:`tlmpc.planning.cells`): at most this
#: much disturbance any plan on the mesh's convex cells rejects, set with SUPPORTED.
SUPPORTED_CELLS = "supported_disturbance_cells"
#: The witness statistic that marks a plan made on convex cells: its steps are cell steps.
ON_CELLS = "cells"


def _on_cells(
    mission: Mission,
    planned: Planned,
    start_point: tuple[float, float] | None,
    resume: frozenset[int] | None = None,
) -> Planned | None:
    """The last rung of the plan stage: ``planned``'s task planned again on the convex
    cells of its mesh (:mod:`tlmpc.planning.cells`), when every cell step of that plan
    rejects the mission's disturbance; None otherwise. ``resume`` re-plans a run under way
    from the mesh's start triangle (its cell entered from nowhere: any interface may be
    left), the automaton being in one of these states."""
    from tlmpc.planning.cells import MAX_TRIANGLES, partition, witness_on_cells
    from tlmpc.planning.complete import RefinementError, plan_complete
    from tlmpc.planning.plan import plan
    from tlmpc.planning.robust import TOLERANCE

    ratio = mission.robot.disturbance / mission.robot.max_speed
    mesh = planned.unrefined if planned.unrefined is not None else planned.abstraction
    if mesh.num_triangles > MAX_TRIANGLES:
        return None  # beyond the rung's budget
    arguments = again(mission, planned, move_times(mission), start_point)
    formula = arguments["formula"]
    cells = partition(mesh)
    # A U-turn inside one cell is no turn for the cell's field: the triangles' U-turns are
    # allowed first; a plan that turns back across an interface is refused below, and the
    # planner without U-turns (refined where they are needed) tried then.

    def turning() -> tuple[Abstraction, Witness]:
        witness = plan(
            mesh,
            planned.automaton,
            **arguments,
            bounces=True,
            resume=resume,
            reject=ratio,
            on_cells=True,
        )
        return mesh, witness

    def refined() -> tuple[Abstraction, Witness]:
        return plan_complete(
            mesh,
            planned.automaton,
            **arguments,
            resume=resume,
            explain=False,
            reject=ratio,
            on_cells=True,
        )

    attempts: tuple[Callable[[], tuple[Abstraction, Witness]], ...] = (turning, refined)
    for attempt in attempts:
        try:
            found, witness = attempt()
        except (NoPlanError, RefinementError):
            continue
        on = cells if found is mesh else partition(found)
        if not witness.passages and witness_on_cells(
            on, witness.prefix, witness.cycle, witness.is_stay, ratio, TOLERANCE
        ):
            witness = replace(witness, stats={**witness.stats, ON_CELLS: True})
            return replace(planned, abstraction=found, witness=witness, formula=formula)
    return None


def _with_cells_bound(planned: Planned, ratio: float | None, mission: Mission) -> Planned:
    """``planned`` (to be refused) stating ``ratio`` x max_speed as the largest disturbance
    plans on convex cells reject, where that is more than it states already."""
    if ratio is None:
        return planned
    value = ratio * mission.robot.max_speed
    known = planned.witness.stats.get(SUPPORTED_CELLS)
    if known is not None and float(known) >= value:
        return planned
    stats = {**planned.witness.stats, SUPPORTED_CELLS: value}
    return replace(planned, witness=replace(planned.witness, stats=stats))


def _on_lines(
    mission: Mission, margin: float, planned: Planned, start_point: tuple[float, float] | None
) -> tuple[Planned | None, float | None]:
    """The cells' rung on the convex cells' own meshes (:mod:`tlmpc.abstraction.lines`):
    first the arrangement of every side extended across the free space (faces that meet side
    to side), with the goal depth, then the margin's; then the reflex cuts (near-linear in
    the sides), then the bisector cuts, in the same order. The plan on the first that
    carries the disturbance, or (None, the largest disturbance ratio any plan on those
    meshes' cells rejects, None when none was built: over the size budgets)."""
    from tlmpc.abstraction import build_abstraction
    from tlmpc.abstraction.layout import deepens_goals, planning_layout
    from tlmpc.abstraction.lines import OverBudget
    from tlmpc.abstraction.triangulate import lines_fit
    from tlmpc.ltl.bounds import untimed_skeleton
    from tlmpc.planning.bottleneck import supported_ratio
    from tlmpc.planning.cells import MAX_TRIANGLES

    formula = planned.formula
    bound: float | None = None
    depths = (True, False) if deepens_goals(mission) else (False,)
    kinds: tuple[Lines, ...] = ("arrangement", "reflex", "bisector")
    for kind in kinds:
        for deep in depths:
            layout = planning_layout(mission, margin, deep=deep)
            if kind == "arrangement" and not lines_fit(mission, layout):
                continue
            try:
                mesh = build_abstraction(mission, layout, lines=kind)
            except OverBudget:
                continue
            if mesh.num_triangles > MAX_TRIANGLES:
                continue
            task = automaton_for(mission, mesh, formula=formula)
            candidate = Planned(
                abstraction=mesh, automaton=task, witness=planned.witness, formula=formula
            )
            found = _on_cells(mission, candidate, start_point)
            if found is not None:
                return found, None
            supported = supported_ratio(
                mesh,
                task,
                formula=formula if formula is not None else untimed_skeleton(mission.formula),
                options=mission.options,
                start_point=start_point if start_point is not None else mission.robot.start,
                cells=True,
            )
            if supported is not None and (bound is None or supported > bound):
                bound = supported
    return None, bound


def on_cells(witness: Witness) -> bool:
    """True for a plan made on convex cells (its controllers are cell fields)."""
    return bool(witness.stats.get(ON_CELLS, False))


def _supported_of(witness: Witness) -> float | None:
    value = witness.stats.get(SUPPORTED)
    return None if value is None else float(value)


#: The fractions of the goal depth tried, in turn, when the goal cores' corners are too sharp
#: for the disturbance (before the margin's depth).
SHALLOWER = (0.5, 0.25)


def _shallow_for_disturbance(mission: Mission, deep: Witness, scale: float) -> Diagnostic:
    """A040: the goal depth was given up, or reduced to ``scale`` of it, for the disturbance."""
    disturbance = mission.robot.disturbance
    requested = mission.options.goal_depth
    bound = _supported_of(deep)
    reach = f"; any plan to the goal cores rejects at most {bound:.6g}" if bound is not None else ""
    return Diagnostic(
        code="A040",
        severity="warning",
        message=f"the goals' cores (options.goal_depth) add corners too sharp for "
        f"robot.disturbance {disturbance:g}{reach}; planned "
        + (
            f"with cores {scale:g} x the goal depth deep (at least the margin)"
            if scale > 0.0
            else "to enter the goals only as deep as the margin asks"
        )
        + ", where every step rejects it",
        hint="a goal core's corners are held on both facets: a corner of angle a rejects at "
        "most max_speed * sin(a / 2); set options.goal_depth to a smaller depth (0: the "
        "margin's) to plan with it without this warning"
        + ("" if bound is None else ", or lower robot.disturbance below the bound to keep it"),
        file=mission.source,
        path="$.options.goal_depth" if requested is not None else "$.robot.disturbance",
    )


def _task_parts(mission: Mission) -> Sequence[TaskPart]:
    """The task's parts as the planner reads them (bounded ones by their skeletons)."""
    import dataclasses

    from tlmpc.ltl.bounds import untimed_skeleton
    from tlmpc.mission.parts import task_parts

    return [
        dataclasses.replace(part, formula=untimed_skeleton(part.formula))
        for part in task_parts(mission)
    ]


def _with_body_notes(failure: NoPlanError, mission: Mission) -> NoPlanError:
    """The no-plan error with the body's diagnostics (a passage too narrow says why)."""
    from tlmpc.mission.cspace import body_diagnostics

    extra = [d for d in body_diagnostics(mission) if d.code in ("R002", "R003", "R004")]
    if not extra:
        return failure
    return NoPlanError([*failure.diagnostics, *extra])
