"""Vertex passages and U-turn refinement are charged against the planner's budget before
the work is done.

A vertex with ``g`` triangles around it gives about ``g**2`` vertex passages; a mesh with a
sliver (thousands of needle triangles around one corner) once made the plan stage list 20
million of them and run out of memory.  The passages' product edges are estimated from the
corners' counts alone and refused beyond the budget (P060), and every mesh refinement plans on
is charged like the input mesh (P040).

Oracles: the edges :func:`add_vertex_passages` actually builds (counted as it hands them to
the graph) for the estimate, and the counts of what each planning call was given.
"""

from __future__ import annotations

import io
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from tlmpc.abstraction import build_abstraction
from tlmpc.abstraction.model import Abstraction
from tlmpc.automata import translate
from tlmpc.automata.degeneralize import degeneralize
from tlmpc.automata.guards import holds
from tlmpc.automata.model import Automaton, Edge
from tlmpc.base.errors import UsageError
from tlmpc.cli import main
from tlmpc.ltl.ast import Const
from tlmpc.ltl.parser import parse_ltl
from tlmpc.mission import load_mission
from tlmpc.mission.model import Options
from tlmpc.planning import budget, passages
from tlmpc.planning.boundary import start_cells
from tlmpc.planning.budget import estimate_product
from tlmpc.planning.complete import plan_complete
from tlmpc.planning.mission import automaton_for
from tlmpc.planning.model import Witness
from tlmpc.planning.passages import add_vertex_passages, estimate_passage_edges
from tlmpc.planning.plan import plan
from tlmpc.planning.product import build_product

#: Two hole corners exactly 1.0 apart and a body a hair narrower than the gap: without the
#: goal depth the mesh around the goal's corner is a fan of thousands of needles.
DIAGONAL_GAP = {
    "version": 1,
    "workspace": {
        "boundary": {"rect": [0, 0, 10, 6]},
        "holes": [{"rect": [2, 0, 4, 2.5]}, {"rect": [4.6, 3.3, 6, 6]}],
    },
    "regions": {"a": {"rect": [8, 0.5, 9.5, 2]}},
    "robot": {"start": [1, 4.5], "max_speed": 1.0, "radius": 0.4999},
    "options": {"margin": 0},
    "task": ["visit a"],
}

A = [[2, 2], [5, 2], [5, 5], [2, 5]]
B = [[5, 5], [8, 5], [8, 8], [5, 8]]


def corner_mission(ltl: str, start: tuple[float, float], boundary: str) -> dict[str, Any]:
    """Regions a and b touching only at the corner (5, 5)."""
    return {
        "version": 1,
        "workspace": {"boundary": [[0, 0], [10, 0], [10, 10], [0, 10]]},
        "regions": {"a": A, "b": B},
        "robot": {"start": list(start), "max_speed": 1.0},
        "ltl": ltl,
        "options": {"boundary": boundary},
    }


def fan(count: int, *, labelled: int) -> Abstraction:
    """A disc cut into ``count`` needle triangles around its centre, each with an outer
    triangle on its rim edge (the way in and out of a passage); the first ``labelled`` needles
    and their outer triangles lie in region ``a``, so the centre is a contact vertex with
    ``count`` triangles around it."""
    angles = 2.0 * math.pi * np.arange(count) / count
    rim = np.column_stack([np.cos(angles), np.sin(angles)])
    middle = angles + math.pi / count
    outside = 2.0 * np.column_stack([np.cos(middle), np.sin(middle)])
    vertices = np.vstack([[0.0, 0.0], rim, outside])
    ring = np.arange(count)
    rim_at, next_rim, outer_at = 1 + ring, 1 + (ring + 1) % count, 1 + count + ring
    needles = np.column_stack([np.zeros(count, dtype=np.int64), rim_at, next_rim])
    outers = np.column_stack([rim_at, outer_at, next_rim])
    # across the edge opposite each corner: a needle's outer triangle, the next needle, the
    # previous one; an outer triangle's needle (opposite its outside corner), else nothing
    needle_neighbors = np.column_stack([count + ring, (ring + 1) % count, (ring - 1) % count])
    none = np.full(count, -1)
    outer_neighbors = np.column_stack([none, ring, none])
    letter_of = np.tile((ring >= labelled).astype(np.int64), 2)  # 0: ('a',), 1: ()
    region = ((0.0, 0.0), *((float(x), float(y)) for x, y in rim[: labelled + 1]))
    return Abstraction(
        vertices=vertices,
        triangles=np.vstack([needles, outers]).astype(np.int64),
        neighbors=np.vstack([needle_neighbors, outer_neighbors]).astype(np.int64),
        letter_of=letter_of,
        letters=(("a",), ()),
        start=count - 1,
        component=np.zeros(2 * count, dtype=np.int64),
        regions={"a": region},
    )


def centroid(abstraction: Abstraction, triangle: int) -> tuple[float, float]:
    x, y = abstraction.corners(triangle).mean(axis=0).tolist()
    return float(x), float(y)


class PairsListed:
    """Wraps the listing of passage pairs: records how many each call lists, and fails
    (instead of exhausting the machine) when a call would list more than ``most``."""

    def __init__(self, monkeypatch: pytest.MonkeyPatch, most: int) -> None:
        self.counts: list[int] = []
        original = passages._ArrivalCorners.pairs

        def pairs(corners: Any, *, bounces: bool) -> Any:
            listed = int((corners.group_size.astype(np.int64) ** 2).sum())
            assert listed <= most, f"{listed:,} passage pairs listed, beyond the budget"
            self.counts.append(listed)
            return original(corners, bounces=bounces)

        monkeypatch.setattr(passages._ArrivalCorners, "pairs", pairs)


class Built:
    """Counts the passage moves :func:`add_vertex_passages` makes and the product edges it
    hands to the graph."""

    def __init__(self, monkeypatch: pytest.MonkeyPatch) -> None:
        self.moves = 0
        self.edges = 0
        with_edges, add = passages._with_edges, passages._PassageMoves.add

        def counted_edges(product: Any, edges: Any, stutter: Any, size: int) -> Any:
            self.edges += sum(len(batch) for batch in edges.sources)
            return with_edges(product, edges, stutter, size)

        def counted_moves(moves: Any, source: Any, *rest: Any) -> None:
            self.moves += len(source)
            add(moves, source, *rest)

        monkeypatch.setattr(passages, "_with_edges", counted_edges)
        monkeypatch.setattr(passages._PassageMoves, "add", counted_moves)


def test_the_diagonal_gap_ends_within_a_small_budget(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The mission that ran for minutes into 10 GB: a plan or a documented refusal, with no
    more passage pairs listed than a budget of a hundred thousand edges allows."""
    small = 100_000
    monkeypatch.setattr(budget, "MAX_PASSAGE_EDGES", small)
    listed = PairsListed(monkeypatch, most=small)
    path = tmp_path / "diag_gap.yaml"
    path.write_text(yaml.safe_dump(DIAGONAL_GAP))
    out, err = io.StringIO(), io.StringIO()
    code = main(["compile", str(path), "-o", str(tmp_path / "out"), "-q"], out=out, err=err)
    text = err.getvalue()
    assert code in (0, 1, 2), text
    if code == 1:
        assert "error[P010]" in text
    if code == 2:
        assert "error[P060]" in text or "error[P040]" in text, text
    assert all(count <= small for count in listed.counts)


def _fan_task(count: int, labelled: int) -> tuple[Abstraction, Automaton, tuple[float, float], int]:
    """A fan of ``count`` needles round one vertex, ``labelled`` of them in ``a``: the mesh,
    the automaton of ``F a``, the start (in the fan's start triangle) and the passage
    estimate."""
    needles = fan(count, labelled=labelled)
    automaton = translate(parse_ltl("F a"), letters=needles.letters)
    start = centroid(needles, needles.start)
    estimate = estimate_passage_edges(
        needles,
        automaton,
        allowed=np.ones(needles.num_triangles, dtype=bool),
        starts=start_cells(needles, start),
        convention=Options().boundary,
    )
    return needles, automaton, start, estimate


def _plan_fan(needles: Abstraction, automaton: Automaton, start: tuple[float, float]) -> Witness:
    return plan(
        needles,
        automaton,
        formula=parse_ltl("F a"),
        options=Options(),
        start_point=start,
        passages=True,
    )


def test_a_fan_beyond_the_budget_is_p060_before_any_pair_is_listed(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    needles, automaton, start, estimate = _fan_task(1000, labelled=500)
    assert estimate >= 1000 * 999  # every ordered pair of the fan's needles
    monkeypatch.setattr(budget, "MAX_PASSAGE_EDGES", estimate - 1)
    listed = PairsListed(monkeypatch, most=0)
    with pytest.raises(UsageError) as refused:
        _plan_fan(needles, automaton, start)
    (diagnostic,) = refused.value.diagnostics
    assert diagnostic.code == "P060"
    assert "1,000 lie around (0, 0)" in diagnostic.message
    assert listed.counts == []


def test_a_fan_within_the_budget_plans_through_its_centre(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """At the budget exactly, the passages are built and the plan found (the estimate is the
    whole charge: nothing else refuses)."""
    needles, automaton, start, estimate = _fan_task(60, labelled=30)
    monkeypatch.setattr(budget, "MAX_PASSAGE_EDGES", estimate)
    witness = _plan_fan(needles, automaton, start)
    assert witness.prefix


def working_automaton(ltl: str, abstraction: Abstraction, mission: Any) -> Automaton:
    automaton = automaton_for(mission, abstraction, formula=parse_ltl(ltl))
    return degeneralize(automaton) if automaton.num_acc >= 2 else automaton


CASES = [
    ("G(a | b) & F b", (3.0, 3.0), "right"),
    ("G(a | b) & F b", (3.0, 3.0), "closed"),
    ("F(a & b)", (1.0, 1.0), "closed"),
    ("G F a & G F b & G F !a", (4.9, 4.8), "right"),
    ("G F a & G F b & G F !a", (4.9, 4.8), "closed"),
    ("F b", (5.1, 4.9), "closed"),
]


@pytest.mark.parametrize("bounces", [False, True])
@pytest.mark.parametrize(("ltl", "start", "boundary"), CASES)
def test_the_estimate_bounds_the_passage_edges_built(
    ltl: str,
    start: tuple[float, float],
    boundary: str,
    bounces: bool,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    path = tmp_path / "corner.yaml"
    path.write_text(yaml.safe_dump(corner_mission(ltl, start, boundary)))
    mission = load_mission(path)
    abstraction = build_abstraction(mission)
    automaton = working_automaton(ltl, abstraction, mission)
    _assert_bounded(abstraction, automaton, start, boundary, bounces, monkeypatch)


@pytest.mark.parametrize("bounces", [False, True])
@pytest.mark.parametrize("boundary", ["right", "closed"])
def test_the_estimate_bounds_the_passage_edges_of_a_fan(
    boundary: str, bounces: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    needles = fan(40, labelled=13)
    automaton = translate(parse_ltl("G F a & G F !a"), letters=needles.letters)
    working = degeneralize(automaton) if automaton.num_acc >= 2 else automaton
    start = centroid(needles, needles.start)
    _assert_bounded(needles, working, start, boundary, bounces, monkeypatch)


def stepping(count: int) -> Automaton:
    """States on a ring, each letter staying or stepping on: ``2 * count`` edges, but after
    two letters three successors per state (more than the edges over a word of two letters;
    no task's automaton is this nondeterministic, so it is built by hand)."""
    edges = tuple(
        Edge(src=q, dst=target, guard=Const(value=True))
        for q in range(count)
        for target in (q, (q + 1) % count)
    )
    return Automaton(aps=("a",), num_states=count, initial=0, edges=edges, num_acc=0)


@pytest.mark.parametrize("bounces", [False, True])
@pytest.mark.parametrize("boundary", ["right", "closed"])
def test_the_estimate_bounds_the_passage_edges_of_a_nondeterministic_automaton(
    boundary: str, bounces: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    needles = fan(12, labelled=5)
    start = centroid(needles, needles.start)
    _assert_bounded(needles, stepping(5), start, boundary, bounces, monkeypatch)


def _assert_bounded(
    abstraction: Abstraction,
    automaton: Automaton,
    start: tuple[float, float],
    boundary: str,
    bounces: bool,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    allowed = np.ones(abstraction.num_triangles, dtype=bool)
    starts = start_cells(abstraction, start)
    product = build_product(
        abstraction,
        automaton,
        allowed=allowed,
        start_point=start,
        metric="length",
        starts=starts,
        convention=boundary,
        bounces=bounces,
    )
    built = Built(monkeypatch)
    add_vertex_passages(
        product,
        abstraction,
        automaton,
        allowed=allowed,
        starts=starts,
        start_point=start,
        metric="length",
        convention=boundary,
        bounces=bounces,
    )
    estimate = estimate_passage_edges(
        abstraction,
        automaton,
        allowed=allowed,
        starts=starts,
        convention=boundary,
        bounces=bounces,
    )
    assert built.edges > 0
    assert built.edges <= estimate
    # The moves are counted exactly (a start on an edge through a vertex passes fewer).
    counted = passages._ArrivalCorners.around_contacts(abstraction, allowed).move_count(
        abstraction, allowed=allowed, starts=starts, bounces=bounces
    )
    if any(cell.blocked for cell in starts):
        assert built.moves <= counted
    else:
        assert built.moves == counted


def successors(automaton: Automaton, state: int, letter: frozenset[str]) -> set[int]:
    return {edge.dst for edge in automaton.edges if edge.src == state and holds(edge.guard, letter)}


@pytest.mark.parametrize(
    "ltl",
    ["G F a & G F b & G F !a", "F(a & b)", "G(a | b) & F b", "(a U b) & G F (a & !b) & G F !a", ""],
)
def test_the_successor_bounds_hold_for_every_word(ltl: str) -> None:
    """Brute force over every valuation of the task's propositions: after one letter, and
    after two, the states reached summed over the starting states stay within the bounds
    (``""``: the hand-built :func:`stepping` automaton)."""
    automaton = translate(parse_ltl(ltl)) if ltl else stepping(5)
    working = degeneralize(automaton) if automaton.num_acc >= 2 else automaton
    aps = sorted(working.aps)
    letters = [
        frozenset(name for bit, name in enumerate(aps) if mask >> bit & 1)
        for mask in range(1 << len(aps))
    ]
    one_letter, two_letters = passages._successor_bounds(working)
    states = range(working.num_states)
    most_one = max(sum(len(successors(working, q, x)) for q in states) for x in letters)
    most_two = max(
        sum(
            len({r for p in successors(working, q, x) for r in successors(working, p, y)})
            for q in states
        )
        for x in letters
        for y in letters
    )
    assert most_one <= one_letter
    assert most_two <= two_letters


DEAD_END = {
    "version": 1,
    "workspace": {"boundary": [[0, 0], [10, 0], [10, 4], [6, 4], [6, 10], [5, 10], [5, 4], [0, 4]]},
    "regions": {
        "tip": [[5, 9], [6, 9], [6, 10], [5, 10]],
        "base": [[0, 0], [2, 0], [2, 2], [0, 2]],
    },
    "robot": {"start": [9, 1], "max_speed": 1.0},
    "ltl": "F(tip & F base)",
}


def test_a_refined_mesh_beyond_the_budget_is_p040_before_its_product(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The dead end needs a U-turn: its refined mesh has more triangles than the input.  With
    the budget at the input's product, the refined one is refused, never planned on."""
    path = tmp_path / "dead_end.yaml"
    path.write_text(yaml.safe_dump(DEAD_END))
    mission = load_mission(path)
    abstraction = build_abstraction(mission)
    automaton = automaton_for(mission, abstraction)
    planned = plan_complete(
        abstraction,
        automaton,
        formula=mission.formula,
        options=mission.options,
        start_point=mission.robot.start,
    )[0]
    assert planned.num_triangles > abstraction.num_triangles  # refined: the case at hand
    fits = estimate_product(abstraction, automaton).nodes
    monkeypatch.setattr(budget, "MAX_PRODUCT_NODES", fits)
    monkeypatch.setattr(budget, "MAX_GUIDED_NODES", fits)
    sizes: list[int] = []
    complete = sys.modules["tlmpc.planning.complete"]
    original = complete.plan

    def counted(mesh: Abstraction, *args: Any, **kwargs: Any) -> Any:
        sizes.append(mesh.num_triangles)
        return original(mesh, *args, **kwargs)

    monkeypatch.setattr(complete, "plan", counted)
    with pytest.raises(UsageError) as refused:
        plan_complete(
            abstraction,
            automaton,
            formula=mission.formula,
            options=mission.options,
            start_point=mission.robot.start,
        )
    assert [d.code for d in refused.value.diagnostics] == ["P040"]
    assert sizes  # the input mesh was planned on, with and without bounces
    assert set(sizes) == {abstraction.num_triangles}


def test_a_budget_refusal_names_the_mission_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The planner knows the mesh, not the file: the refusal still names the mission."""
    from tlmpc.cli import main
    from tlmpc.planning import budget

    monkeypatch.setattr(budget, "MAX_GUIDED_NODES", 1)
    monkeypatch.setattr(budget, "MAX_PRODUCT_NODES", 1)
    path = tmp_path / "mission.yaml"
    path.write_text(
        "version: 1\n"
        "workspace: {boundary: {rect: [0, 0, 10, 10]}}\n"
        "regions: {goal: {rect: [8, 8, 9, 9]}}\n"
        "robot: {start: [1, 1]}\n"
        "task: [visit goal]\n"
    )
    err = io.StringIO()
    assert main(["compile", str(path), "-o", str(tmp_path / "out"), "-q"], err=err) == 2
    assert err.getvalue().startswith(f"{path}: error[P040]"), err.getvalue()
