"""A needed region the robot cannot reach is refused exactly, whatever the planner's budget.

No sequence of edge moves or vertex passages reaches a region in another piece of free space;
that is decided by a search over the triangles before the search through vertex passages,
whose product is refused beyond a budget (P060). So an unreachable region is P010/P011 (with
the P005 fact) even when the passages' budget is zero, and the explanation never blames a
part that has a plan through a point contact, nor says that a region beyond one "cannot be
reached".

Oracle: shapely. The free space (the boundary minus the holes, less the closed avoided
regions) is cut into pieces; pieces that touch at a point are joined (under the closed
convention only where that point is not on an avoided region); a goal is reachable when a
piece joined to the start's holds part of it.
"""

from __future__ import annotations

import io
import random
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from shapely.geometry import Point, box
from shapely.geometry.base import BaseGeometry
from shapely.ops import unary_union

from tlmpc.abstraction import build_abstraction
from tlmpc.base.errors import NoPlanError
from tlmpc.cli import main
from tlmpc.ltl.parser import parse_ltl
from tlmpc.mission import load_mission_text
from tlmpc.planning import budget, plan
from tlmpc.planning.boundary import start_cells
from tlmpc.planning.explain import invariant_mask, invariants
from tlmpc.planning.mission import automaton_for
from tlmpc.planning.reach import cannot_accept_on_reach

# -- the oracle --------------------------------------------------------------------------


def _polygons(geometry: BaseGeometry) -> list[BaseGeometry]:
    parts = getattr(geometry, "geoms", [geometry])
    return [p for p in parts if p.geom_type == "Polygon" and p.area > 1e-12]


def _rect(shape: Any) -> BaseGeometry:
    return box(*shape["rect"])


def reachable_area(mission: dict[str, Any], avoided: list[str]) -> BaseGeometry:
    """The closed free space a point robot reaches from its start without entering the
    ``avoided`` regions (pieces joined through points, see the module doc)."""
    workspace = mission["workspace"]
    pieces = [
        _rect(workspace["boundary"]).difference(
            unary_union([_rect(h) for h in workspace.get("holes", [])])
        )
    ]
    pieces += [_rect(c["boundary"]) for c in workspace.get("components", [])]
    forbidden = unary_union([_rect(mission["regions"][name]) for name in avoided])
    closed = mission.get("options", {}).get("boundary") == "closed"
    free = [p for piece in pieces for p in _polygons(piece.difference(forbidden))]
    group = list(range(len(free)))

    def root(i: int) -> int:
        while group[i] != i:
            i = group[i]
        return i

    for i in range(len(free)):
        for j in range(i + 1, len(free)):
            touch = free[i].intersection(free[j])
            if touch.is_empty:
                continue
            if closed and touch.area == 0 and forbidden.intersects(touch):
                continue  # a corner of an avoided region holds the only way through
            group[root(i)] = root(j)
    start = Point(mission["robot"]["start"])
    home = [root(i) for i, p in enumerate(free) if p.distance(start) < 1e-9]
    return unary_union([p for i, p in enumerate(free) if root(i) in home])


def goal_reachable(mission: dict[str, Any], goal: str, avoided: list[str]) -> bool:
    """Whether the robot can be in ``goal`` (for a moment of positive length under the
    right-continuous convention, at a point under the closed one)."""
    inside = reachable_area(mission, avoided).intersection(_rect(mission["regions"][goal]))
    if mission.get("options", {}).get("boundary") == "closed":
        return not inside.is_empty
    return bool(inside.area > 1e-9)


# -- running tlmpc ---------------------------------------------------------------------


def compile_text(tmp_path: Path, mission: dict[str, Any]) -> tuple[int, str]:
    path = tmp_path / "m.yaml"
    path.write_text(yaml.safe_dump(mission, sort_keys=False))
    out, err = io.StringIO(), io.StringIO()
    code = main(
        ["compile", str(path), "-o", str(tmp_path / "out"), "-q", "--force", "--until", "plan"],
        out=out,
        err=err,
    )
    return code, err.getvalue()


def rect(x0: float, y0: float, x1: float, y1: float) -> dict[str, list[float]]:
    return {"rect": [x0, y0, x1, y1]}


def corner_components(task: list[str]) -> dict[str, Any]:
    """The main room touches a second piece at the point (4, 4) (region b there); a third
    piece (region c) touches neither."""
    return {
        "version": 1,
        "workspace": {
            "boundary": rect(0, 0, 4, 4),
            "components": [{"boundary": rect(4, 4, 8, 8)}, {"boundary": rect(10, 0, 12, 2)}],
        },
        "regions": {
            "a": rect(1, 1, 2, 2),
            "b": rect(6, 6, 7, 7),
            "c": rect(10.5, 0.5, 11.5, 1.5),
        },
        "robot": {"start": [0.5, 0.5]},
        "task": task,
    }


@pytest.mark.parametrize("order", [["visit c", "visit b"], ["visit b", "visit c"]])
def test_the_part_blamed_is_the_one_without_a_plan(tmp_path: Path, order: list[str]) -> None:
    mission = corner_components(order)
    assert goal_reachable(mission, "b", [])
    assert not goal_reachable(mission, "c", [])
    code, text = compile_text(tmp_path, mission)
    assert code == 1, text
    headline = text.splitlines()[0]
    assert "error[P010]" in headline
    assert "`visit c`" in headline
    assert "region 'c' cannot be reached" in text
    assert "'b'" not in text
    # and the part not blamed has a plan, through the point (4, 4)
    code, text = compile_text(tmp_path, corner_components(["visit b"]))
    assert code == 0, text


def test_an_unreachable_region_is_p010_with_no_budget_for_passages(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(budget, "MAX_PASSAGE_EDGES", 0)
    mission = corner_components(["visit a then b", "visit c"])
    assert not goal_reachable(mission, "c", [])
    code, text = compile_text(tmp_path, mission)
    assert code == 1, text
    assert "error[P010]" in text
    assert "`visit c`" in text
    assert "P060" not in text


def test_an_unreachable_region_is_p010_with_no_budget_for_the_product(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Not P040: the product is never needed to know that c cannot be reached."""
    monkeypatch.setattr(budget, "MAX_PRODUCT_NODES", 1)
    monkeypatch.setattr(budget, "MAX_GUIDED_NODES", 1)
    mission = corner_components(["visit a then b", "visit c"])
    code, text = compile_text(tmp_path, mission)
    assert code == 1, text
    assert "error[P010]" in text
    assert "`visit c`" in text
    assert "region 'c' cannot be reached" in text
    assert "P040" not in text
    # the budget still refuses where reachability leaves the question open
    code, text = compile_text(tmp_path, corner_components(["visit b"]))
    assert code == 2, text
    assert "error[P040]" in text


def diagonal_wall(closed: bool) -> dict[str, Any]:
    """Avoided regions x and y meet at the corner (1, 1), the only way to the goal g."""
    mission: dict[str, Any] = {
        "version": 1,
        "workspace": {"boundary": rect(0, 0, 2, 2)},
        "regions": {"x": rect(1, 0, 2, 1), "y": rect(0, 1, 1, 2), "g": rect(1.5, 1.5, 2, 2)},
        "robot": {"start": [0.3, 0.3]},
        "task": ["avoid x", "visit g", "avoid y"],
    }
    if closed:
        mission["options"] = {"boundary": "closed"}
    return mission


@pytest.mark.parametrize("closed", [False, True])
def test_a_corner_of_avoided_regions_is_a_way_only_under_the_right_convention(
    closed: bool,
) -> None:
    data = diagonal_wall(closed)
    expected = goal_reachable(data, "g", ["x", "y"])
    assert expected is not closed
    mission = load_mission_text(yaml.safe_dump(data), "m.yaml")
    abstraction = build_abstraction(mission)
    automaton = automaton_for(mission, abstraction)
    formula = mission.formula
    refused = cannot_accept_on_reach(
        abstraction,
        automaton,
        allowed=invariant_mask(abstraction, formula),
        required=invariants(formula),
        starts=start_cells(abstraction, mission.robot.start),
        start_point=mission.robot.start,
        convention=mission.options.boundary,
    )
    assert refused is not expected


def test_a_run_under_way_is_refused_from_the_states_it_is_in() -> None:
    """Resumed in the accepting sink of ``F c`` the task holds wherever the robot goes;
    resumed before it, c must be reached, and it cannot be."""
    data = corner_components(["visit c"])
    mission = load_mission_text(yaml.safe_dump(data), "m.yaml")
    abstraction = build_abstraction(mission)
    automaton = automaton_for(mission, abstraction, formula=parse_ltl("F c"))
    formula = parse_ltl("F c")
    accepting = {e.src for e in automaton.edges if e.marks and e.src == e.dst}
    waiting = set(range(automaton.num_states)) - accepting
    assert accepting
    assert waiting

    def refused(states: set[int]) -> bool:
        return cannot_accept_on_reach(
            abstraction,
            automaton,
            allowed=np.ones(abstraction.num_triangles, dtype=bool),
            required=invariants(formula),
            starts=start_cells(abstraction, mission.robot.start),
            start_point=mission.robot.start,
            convention="right",
            resume=frozenset(states),
        )

    assert refused(waiting)
    assert not refused(accepting)


# -- random maps -----------------------------------------------------------------------


def random_mission(seed: int) -> dict[str, Any]:
    """A grid room cut by a wall of unit holes: closed, with a one-cell gap (which the
    avoided region c may fill), or a staircase whose two runs touch at one corner (the free
    space pinched there); three regions in free cells, a task visiting two of them and maybe
    avoiding the third."""
    rng = random.Random(seed)
    width, height = rng.randint(5, 7), rng.randint(4, 6)
    wall = rng.randint(1, width - 3)
    kind = rng.choice(["closed", "gap", "gap", "staircase", "staircase"])
    step = rng.randint(1, height - 1)
    holes: set[tuple[int, int]] = set()
    for y in range(height):
        if kind == "staircase":
            holes.add((wall, y) if y < step else (wall + 1, y))
        elif kind == "closed" or y != step:
            holes.add((wall, y))
    free = [(x, y) for x in range(width) for y in range(height) if (x, y) not in holes]
    left = [(x, y) for x, y in free if x < wall]
    start = rng.choice(left)
    others = [cell for cell in free if cell != start]
    rng.shuffle(others)
    names = ["a", "b", "c"]
    regions = {
        n: rect(x + 0.2, y + 0.2, x + 0.8, y + 0.8)
        for n, (x, y) in zip(names, others[:3], strict=True)
    }
    if kind == "gap" and rng.random() < 0.6 and (wall, step) != start:
        regions["c"] = rect(wall, step, wall + 1, step + 1)  # fills the gap
        regions["a"], regions["b"] = [
            rect(x + 0.2, y + 0.2, x + 0.8, y + 0.8)
            for x, y in [c for c in others if c != (wall, step)][:2]
        ]
    task = ["visit a", "visit b"] + (["avoid c"] if rng.random() < 0.6 else [])
    rng.shuffle(task)
    mission: dict[str, Any] = {
        "version": 1,
        "workspace": {
            "boundary": rect(0, 0, width, height),
            "holes": [rect(x, y, x + 1, y + 1) for x, y in sorted(holes)],
        },
        "regions": regions,
        "robot": {"start": [start[0] + 0.5, start[1] + 0.5]},
        "task": task,
    }
    if rng.random() < 0.3:
        mission["options"] = {"boundary": "closed"}
    return mission


@pytest.mark.parametrize("seed", range(16))
def test_random_maps_refuse_unreachable_goals_exactly(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, seed: int
) -> None:
    """With no budget for vertex passages: an unreachable goal is P010/P011 naming it; a
    reachable one is planned, or refused by the budget only (the passages it needs)."""
    monkeypatch.setattr(budget, "MAX_PASSAGE_EDGES", 0)
    mission = random_mission(seed)

    def feasible(parts: list[str]) -> bool:
        avoided = [p.split()[1] for p in parts if p.startswith("avoid ")]
        goals = [p.split()[1] for p in parts if p.startswith("visit ")]
        return all(goal_reachable(mission, g, avoided) for g in goals)

    code, text = compile_text(tmp_path, mission)
    codes = re.findall(r"error\[(\w+)\]", text)
    if feasible(mission["task"]):
        assert code == 0 or codes == ["P060"], text
        return
    assert code == 1, text
    blamed = re.findall(r"`([^`]*)`", text.splitlines()[0])
    if codes[0] == "P010":
        assert not feasible(blamed[:1]), text
    else:
        assert codes[0] == "P011", text
        assert not feasible(blamed), text
        assert all(feasible([part]) for part in blamed), text


def wall_with_corner_gap(closed: bool) -> dict[str, Any]:
    """A wall at x = 4..5 whose opening (y = 2..6) ends in the avoided region c; the holes'
    corners (5, 2) and (5, 6) touch c's, and the free space beyond through them."""
    mission: dict[str, Any] = {
        "version": 1,
        "workspace": {
            "boundary": rect(0, 0, 12, 8),
            "holes": [rect(4, 0, 5, 2), rect(4, 6, 5, 8)],
        },
        "regions": {"b": rect(9, 5, 11, 7), "c": rect(5, 2, 7, 6)},
        "robot": {"start": [0.5, 7.5]},
        "task": ["visit b", "avoid c"],
    }
    if closed:
        mission["options"] = {"boundary": "closed"}
    return mission


@pytest.mark.parametrize("closed", [False, True])
def test_a_region_beyond_a_corner_is_never_said_to_be_out_of_reach(closed: bool) -> None:
    """The search along edges alone finds no plan; its explanation states the region facts,
    and b is out of reach only where the corners are no way through (under *closed* they
    lie on c)."""
    data = wall_with_corner_gap(closed)
    reachable = goal_reachable(data, "b", ["c"])
    assert reachable is not closed
    mission = load_mission_text(yaml.safe_dump(data), "m.yaml")
    abstraction = build_abstraction(mission)
    with pytest.raises(NoPlanError) as caught:
        plan(
            abstraction,
            automaton_for(mission, abstraction),
            formula=mission.formula,
            options=mission.options,
            start_point=mission.robot.start,
        )
    said = " ".join(d.message for d in caught.value.diagnostics)
    assert ("region 'b' can only be reached through" in said) is not reachable, said
