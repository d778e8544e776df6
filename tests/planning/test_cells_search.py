"""The searches on convex cells against every lasso of cell visits (tests/oracles/brute_cells.py).

* The widest lasso on cells (``supported_ratio(cells=True)``, the bound `C032` states) is the
  brute-force maximum over lassos that never turn back across an interface and whose loops
  inside one cell are that cell's stay: the true largest disturbance the cells support, not
  an upper bound.
* The planner on cells, under a disturbance, finds a plan exactly when such a lasso is wide
  enough (just below the bound, and not at it), and the plan it finds passes the control
  stage's checks (no step leaves for the cell it came from, every cell step and stay wide
  enough).
* Two hand-made maps where the triangles' product alone goes wrong: a dead-end room (the
  only lasso turns back) and an overlap whose narrow cell the cheapest patrol loops in while
  a wide one exists further on.
"""

from __future__ import annotations

import math

from brute_cells import has_lasso, product_graph, widest_lasso
from hypothesis import event, example, given, settings
from hypothesis import strategies as st
from small_maps import RECTS, TASKS, small_mission

from tlmpc.abstraction import build_abstraction
from tlmpc.abstraction.model import Abstraction
from tlmpc.automata import translate
from tlmpc.automata.degeneralize import degeneralize
from tlmpc.automata.model import Automaton
from tlmpc.base.errors import InvalidInputError, NoPlanError
from tlmpc.mission import load_mission_text
from tlmpc.mission.model import Mission
from tlmpc.planning.bottleneck import supported_ratio
from tlmpc.planning.cells import partition, witness_on_cells
from tlmpc.planning.plan import plan
from tlmpc.planning.robust import TOLERANCE

STARTS = [(5.3, 4.6), (3.1, 2.6), (0.4, 0.7), (5.7, 0.2), (1.2, 3.9)]


def _setting(text: str) -> tuple[Mission, Abstraction, Automaton] | None:
    try:
        mission = load_mission_text(text, "m.yaml")
    except InvalidInputError:
        return None
    mesh = build_abstraction(mission)
    return mission, mesh, translate(mission.formula, letters=mesh.letters)


def _oracle(mission: Mission, mesh: Abstraction, automaton: Automaton) -> float | None:
    model = degeneralize(automaton) if automaton.num_acc >= 2 else automaton
    return widest_lasso(mesh, partition(mesh), model, mission.robot.start)


def _bound(mission: Mission, mesh: Abstraction, automaton: Automaton) -> float | None:
    return supported_ratio(
        mesh,
        automaton,
        formula=mission.formula,
        options=mission.options,
        start_point=mission.robot.start,
        cells=True,
    )


def _plan_on_cells(
    mission: Mission, mesh: Abstraction, automaton: Automaton, ratio: float
) -> tuple[int, ...] | None:
    """The planner on cells (U-turns inside a cell allowed, as the cells' rung asks first):
    the plan's triangles, checked as the control stage checks them, or None."""
    try:
        witness = plan(
            mesh,
            automaton,
            formula=mission.formula,
            options=mission.options,
            start_point=mission.robot.start,
            bounces=True,
            reject=ratio,
            on_cells=True,
        )
    except NoPlanError:
        return None
    cells = partition(mesh)
    assert witness_on_cells(
        cells, witness.prefix, witness.cycle, witness.is_stay, ratio, TOLERANCE
    ), "the search found a plan the control stage refuses"
    return (*witness.prefix, *witness.cycle)


def _exists(mission: Mission, mesh: Abstraction, automaton: Automaton, ratio: float) -> bool:
    """The oracle's answer to the planner's question: a lasso with every step wider than
    ``ratio`` plus the controllers' tolerance."""
    model = degeneralize(automaton) if automaton.num_acc >= 2 else automaton
    cells = partition(mesh)
    graph, roots = product_graph(mesh, cells, model, mission.robot.start)
    return has_lasso(cells, graph, roots, math.nextafter(ratio + TOLERANCE, math.inf))


@settings(max_examples=max(15, settings().max_examples // 3), deadline=None)
@given(
    st.sampled_from(TASKS),
    st.lists(RECTS, min_size=3, max_size=3),
    st.sampled_from(STARTS),
    st.sampled_from([0.2, 0.3, 0.4, 0.5, 0.6]),
    st.booleans(),
)
# Two regions sharing an edge, a patrol between them.
@example("patrol a, b", [(0, 0, 2, 2), (2, 0, 2, 2), (4, 3, 1, 1)], (3.1, 2.6), 0.3, False)
# Overlapping regions: the patrol's automaton cycles while the robot is in the overlap.
@example("patrol a, b", [(0, 0, 3, 3), (1, 1, 3, 3), (4, 3, 1, 1)], (5.3, 4.6), 0.4, False)
# The widest lassos on the triangles' product turn back across an interface of several mesh
# edges (entering by one, leaving by another): on cells the bound is lower (0.383, 0.526).
@example("visit a then b", [(3, 0, 1, 3), (3, 0, 1, 3), (4, 1, 2, 1)], (0.4, 0.7), 0.4, True)
@example("visit a", [(1, 2, 2, 3), (4, 3, 1, 2), (2, 2, 2, 3)], (3.1, 2.6), 0.6, True)
# The cheapest lasso loops inside a cell whose stay is too narrow: a wide one exists.
@example("visit a", [(0, 1, 3, 2), (0, 0, 3, 3), (1, 3, 3, 1)], (0.4, 0.7), 0.6, False)
# Every lasso's accepting edges lie inside cells whose stays are too narrow: the mark counts
# once the robot leaves the cell.
@example("whenever a, visit b", [(1, 1, 2, 2), (4, 0, 1, 2), (0, 2, 1, 3)], (5.7, 0.2), 0.5, True)
def test_the_cells_searches_are_the_brute_force_ones(
    task: str,
    regions: list[tuple[int, int, int, int]],
    start: tuple[float, float],
    ratio: float,
    quality: bool,
) -> None:
    setting = _setting(small_mission(task, regions, start, quality=quality))
    if setting is None:
        event("invalid map")
        return
    mission, mesh, automaton = setting
    expected = _oracle(mission, mesh, automaton)
    found = _bound(mission, mesh, automaton)
    event("no lasso" if expected is None else "lasso")
    assert found == expected  # the same widths, compared as they are
    if expected is not None:
        # the bound is the planner's own threshold on cells: a plan just below, none at it
        assert _plan_on_cells(mission, mesh, automaton, expected - 3 * TOLERANCE) is not None
        assert _plan_on_cells(mission, mesh, automaton, expected - 0.5 * TOLERANCE) is None
    planned = _plan_on_cells(mission, mesh, automaton, ratio)
    exists = _exists(mission, mesh, automaton, ratio)
    event(f"plan on cells: {exists}")
    assert (planned is not None) == exists


def _dead_end() -> str:
    # A corridor of three rooms; ``a`` is the room at the left end: visiting it and going on
    # to ``b`` at the right end turns back across the only interface of a's cell.
    return small_mission(
        "visit a then b",
        [(0, 0, 2, 2), (4, 0, 2, 2), (2, 0, 2, 2)],
        (3.1, 1.1),
        "{rect: [0, 0, 6, 2]}",
    )


def test_a_dead_end_visit_has_no_plan_on_cells() -> None:
    setting = _setting(_dead_end())
    assert setting is not None
    mission, mesh, automaton = setting
    cells = partition(mesh)
    a_cells = {int(cells.cell_of[t]) for t in range(mesh.num_triangles) if "a" in mesh.labels(t)}
    assert len(a_cells) == 1, "the room is one convex cell"
    # every lasso turns back: no bound on cells, no plan on cells at any disturbance
    assert _oracle(mission, mesh, automaton) is None
    assert _bound(mission, mesh, automaton) is None
    assert _plan_on_cells(mission, mesh, automaton, 0.1) is None
