"""Complete planning: a plan whenever some continuous trajectory satisfies the task.

1. Plan on D without bounces (the usual case: nothing changes, the mesh stays as built).
   If that fails (or its product is beyond the budget, P040), ask whether the task can be
   accepted at all on the letters the robot can reach (:mod:`tlmpc.planning.reach`, a search
   over the triangles): when it cannot, no step below finds a plan, and the explanation
   follows at once, whatever the budgets.
2. If that fails, plan with bounces allowed.  That product is stutter-equivalent to the face
   graph of the region arrangement (see docs/planning.md), so failing here means that no
   trajectory in the plane satisfies the task: the explanation is computed against it.
3. Otherwise every triangle where the bouncing lasso turns around is split into a fan of three
   (:func:`tlmpc.abstraction.refine.split_triangles`), and the no-bounce planner runs again on
   the refined mesh, where the fan lets the robot circle back; the returned abstraction is the
   refined one, and the controllers, simulation and self-check all use it.

Every mesh planned on, the refined ones too, is charged against the planner's budget before
its product is built (:func:`tlmpc.planning.budget.check_product_size`, P040): a round of
refinement may triple a mesh (two triangles more per triangle of the lasso).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Protocol

from tlmpc.abstraction.model import Abstraction
from tlmpc.abstraction.refine import split_triangles
from tlmpc.automata.model import Automaton
from tlmpc.base.errors import Diagnostic, NoPlanError, TlmpcError, UsageError, error
from tlmpc.ltl.ast import Formula
from tlmpc.mission.model import Options, TaskPart
from tlmpc.planning.boundary import start_cells, start_point_label, task_formula, task_letters
from tlmpc.planning.budget import check_product_size
from tlmpc.planning.explain import (
    Undecided,
    explain_infeasible,
    explain_no_plan,
    invariant_mask,
    invariants,
)
from tlmpc.planning.model import Witness
from tlmpc.planning.passages import passage_turns
from tlmpc.planning.plan import plan
from tlmpc.planning.reach import cannot_accept_on_reach
from tlmpc.planning.timing import MoveTimes


class Attempt(Protocol):
    """One planning attempt on a mesh of the task's map (U-turns, vertex passages as asked)."""

    def __call__(
        self, mesh: Abstraction, *, bounces: bool = False, passages: bool = False
    ) -> Witness: ...


#: Rounds of refinement before giving up (one always suffices; see the module docstring).
MAX_ROUNDS = 3


def bounce_triangles(
    witness: Witness,
    abstraction: Abstraction | None = None,
    start_point: tuple[float, float] | None = None,
) -> list[int]:
    """Triangles where the run ``prefix + cycle^omega`` enters and leaves by the same edge.

    With ``abstraction`` and ``start_point``, a first triangle left through an edge that
    holds the start point counts too (the robot enters it from that edge at t = 0).
    """
    run = [*witness.prefix, *witness.cycle]
    if len(witness.cycle) > 1:
        run += [*witness.cycle, witness.cycle[0]]
    found = {run[i] for i in range(1, len(run) - 1) if run[i - 1] == run[i + 1]}
    if abstraction is not None and start_point is not None and len(run) > 1:
        first, second = run[0], run[1]
        for cell in start_cells(abstraction, start_point):
            if cell.triangle == first and any(
                int(abstraction.neighbors[first, i]) == second for i in cell.blocked
            ):
                found.add(first)
    return sorted(found)


def plan_complete(
    abstraction: Abstraction,
    automaton: Automaton,
    *,
    formula: Formula,
    options: Options,
    start_point: tuple[float, float],
    parts: Callable[[], Sequence[TaskPart]] = tuple,
    file: str | None = None,
    resume: frozenset[int] | None = None,
    explain: bool = True,
    reject: float | None = None,
    times: MoveTimes | None = None,
    on_cells: bool = False,
) -> tuple[Abstraction, Witness]:
    """A witness on ``abstraction`` or on a locally refined copy of it (returned with it).

    Raises :class:`NoPlanError` only when no trajectory in the plane satisfies the task;
    ``parts`` gives the task's parts for that explanation (called only then, and only with
    ``explain``: a run re-planning under way needs no explanation).  ``resume`` re-plans a
    run under way (see :func:`tlmpc.planning.plan.plan`); ``times`` weighs the moves under
    the ``time`` metric (:mod:`tlmpc.planning.timing`); ``on_cells`` plans the moves and stays
    of convex cells that reject ``reject`` (:mod:`tlmpc.planning.cells`).
    """

    def attempt(mesh: Abstraction, *, bounces: bool = False, passages: bool = False) -> Witness:
        check_product_size(mesh, automaton)
        return plan(
            mesh,
            automaton,
            formula=formula,
            options=options,
            start_point=start_point,
            bounces=bounces,
            passages=passages,
            resume=resume,
            reject=reject,
            times=times,
            on_cells=on_cells,
        )

    out_of_reach: bool | None = None  # asked once, when needed
    try:
        return abstraction, attempt(abstraction)
    except NoPlanError as first:
        # Its diagnostics alone are kept (and raised anew below): an exception kept in a
        # local of the frame its traceback holds is a reference cycle, and the traceback's
        # frames hold every product searched on the way until the compile's paused collector
        # runs (Example 8 on convex cells peaked 0.6 GB higher).
        no_bounce = first.diagnostics
    except UsageError:
        # A product beyond the budget (P040) is no answer where a cheap one exists.
        if not _out_of_reach(abstraction, automaton, formula, options, start_point, resume):
            raise
        out_of_reach = True
        no_bounce = tuple(_why_not(abstraction, automaton, formula, options, start_point))
    # The searches with U-turns and vertex passages decide what the reachable letters leave
    # open; when the task cannot be accepted on those at all, none of them finds a plan (and
    # the passages' budget, P060, must not stand in for that answer).
    if out_of_reach is None:
        out_of_reach = _out_of_reach(abstraction, automaton, formula, options, start_point, resume)
    if not out_of_reach:
        try:
            return _refined(abstraction, attempt, start_point, passages=False)
        except NoPlanError:
            if reject:
                raise NoPlanError(no_bounce) from None  # no law here reaches a point under a push
        # The one place vertex passages come in: no plan exists along edges alone.
        try:
            return abstraction, attempt(abstraction, passages=True)
        except NoPlanError:
            pass
        try:
            return _refined(abstraction, attempt, start_point, passages=True)
        except NoPlanError:
            pass
    if reject or not explain:
        raise NoPlanError(no_bounce) from None
    raise NoPlanError(
        explain_infeasible(
            abstraction,
            automaton,
            formula=formula,
            options=options,
            start_point=start_point,
            parts=parts(),
            file=file,
            fallback=no_bounce,
            no_plan_reasons=_no_plan_reasons(abstraction, options, start_point),
        )
    ) from None


def _why_not(
    abstraction: Abstraction,
    automaton: Automaton,
    formula: Formula,
    options: Options,
    start_point: tuple[float, float],
) -> list[Diagnostic]:
    """The explanation :func:`tlmpc.planning.plan.plan` gives when it finds no plan, without
    building a product."""
    closed = options.boundary == "closed"
    return explain_no_plan(
        abstraction,
        automaton,
        formula,
        invariant_mask(abstraction, formula),
        starts=start_cells(abstraction, start_point),
        start_label=start_point_label(abstraction, start_point) if closed else None,
    )


def _out_of_reach(
    abstraction: Abstraction,
    automaton: Automaton,
    formula: Formula,
    options: Options,
    start_point: tuple[float, float],
    resume: frozenset[int] | None = None,
) -> bool:
    """Whether the task cannot be accepted on the letters the robot can reach at all
    (:func:`tlmpc.planning.reach.cannot_accept_on_reach`): then no plan exists."""
    return cannot_accept_on_reach(
        abstraction,
        automaton,
        allowed=invariant_mask(abstraction, formula),
        required=invariants(formula),
        starts=start_cells(abstraction, start_point),
        start_point=start_point,
        convention=options.boundary,
        resume=resume,
    )


def _no_plan_reasons(
    abstraction: Abstraction, options: Options, start_point: tuple[float, float]
) -> Callable[[Formula], Sequence[Diagnostic] | Undecided | None]:
    """Why no trajectory satisfies a task formula on this map (U-turns and vertex passages
    allowed), None when one does, or :attr:`Undecided.BEYOND_BUDGET` when the budget leaves
    it open: a blamed set then only grows, it never holds parts that have a plan."""
    from tlmpc.automata.translate import translate

    convention = options.boundary
    letters = task_letters(abstraction, convention, start_point)

    def no_plan_reasons(formula: Formula) -> Sequence[Diagnostic] | Undecided | None:
        automaton = translate(task_formula(formula, convention), letters=letters)

        def attempt(*, passages: bool) -> None:
            check_product_size(abstraction, automaton)
            plan(
                abstraction,
                automaton,
                formula=formula,
                options=options,
                start_point=start_point,
                bounces=True,
                passages=passages,
            )

        if _out_of_reach(abstraction, automaton, formula, options, start_point):
            return _why_not(abstraction, automaton, formula, options, start_point)
        try:
            attempt(passages=False)
            return None
        except NoPlanError as failure:
            reasons = failure.diagnostics
        except UsageError:
            return Undecided.BEYOND_BUDGET  # not known to have a plan, nor to have none
        try:
            attempt(passages=True)
        except NoPlanError:
            return reasons
        except UsageError:
            return Undecided.BEYOND_BUDGET
        return None

    return no_plan_reasons


def _refined(
    abstraction: Abstraction,
    attempt: Attempt,
    start_point: tuple[float, float],
    *,
    passages: bool,
) -> tuple[Abstraction, Witness]:
    """A no-bounce witness on a mesh refined where a bouncing lasso turns around; raises
    :class:`NoPlanError` when no bouncing lasso exists on ``abstraction``."""
    mesh = abstraction
    for _ in range(MAX_ROUNDS):
        try:
            bouncing = attempt(mesh, bounces=True, passages=passages)
        except NoPlanError:
            if mesh is abstraction:
                raise
            break
        turns = bounce_triangles(bouncing, mesh, start_point)
        if passages:
            turns = sorted({*turns, *passage_turns(mesh, bouncing)})
        mesh = split_triangles(mesh, turns, start_point)
        try:
            witness = attempt(mesh, passages=passages)
        except NoPlanError:
            continue
        return mesh, witness
    raise RefinementError(
        error(
            "A020",
            "a plan with U-turns exists but refining the mesh did not realise it",
            hint="this is a bug in tlmpc; please report this mission",
        )
    )


class RefinementError(TlmpcError):
    """Refinement for U-turns failed to give a no-bounce plan (an internal error, exit 3)."""

    exit_code = 3
