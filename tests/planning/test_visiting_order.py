"""The order in which a patrol visits its goals (``tlmpc.pipeline.shortest.order_candidates``).

A degeneralization awaits the acceptance sets in one order, so a minimum-cost lasso of its
product visits them in that order once a lap.  The plan stage plans the task again awaiting
the sets in every other order (up to rotation and direction) and keeps the shortest path.

Oracle: a visibility-graph tour oracle on shapely geometry over every visiting order
(tests/oracles/shortest_paths.py: no tlmpc geometry); the orders themselves and the
reordered automata: tests/automata/test_acceptance_orders.py.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from typing import Any

import pytest
import shapely
import yaml
from shortest_paths import VisibilityOracle

from tlmpc.mission.cspace import workspace_free_space
from tlmpc.pipeline import shortest
from tlmpc.pipeline.stages import ABSTRACTION, AUTOMATON, MISSION, WITNESS, compile_mission
from tlmpc.planning.mission import plan_mission

GOALS = {"sw": [0.5, 0.5, 2.0, 2.0], "se": [10.0, 0.5, 11.5, 2.0], "ne": [10.0, 8.0, 11.5, 9.5]}


def _patrol(listing: tuple[str, ...], nw: list[float]) -> str:
    """A 12 x 10 room with a pillar, a goal near each corner, patrolled in ``listing``."""
    document = {
        "version": 1,
        "name": "square",
        "workspace": {"boundary": {"rect": [0, 0, 12, 10]}, "holes": [{"rect": [5, 4, 7, 6]}]},
        "regions": {name: {"rect": rect} for name, rect in {**GOALS, "nw": nw}.items()},
        "robot": {"start": [6.0, 1.0], "max_speed": 1.0},
        "task": [f"patrol {', '.join(listing[:-1])} and {listing[-1]}"],
    }
    return yaml.safe_dump(document)


def _cyclic_order(witness: Any, names: tuple[str, ...]) -> tuple[str, ...]:
    """The goals in the order the plan's cycle first enters them."""
    word = witness.word[len(witness.prefix) :]
    order: list[str] = []
    for letters in word:
        for name in sorted(set(letters) & set(names)):
            if name not in order:
                order.append(name)
    return tuple(order)


def _tour_oracle(mission: Any) -> Callable[[tuple[str, ...]], float]:
    """The closed tour from the start through the named regions in a given order, on the
    visibility-graph oracle (shapely geometry of the mission's free space)."""
    names = [r.name for r in mission.regions]
    oracle = _visibility_oracle(mission)

    def tour(order: tuple[str, ...]) -> float:
        return oracle.tour_length([names.index(n) for n in order])

    return tour


def _visibility_oracle(mission: Any) -> VisibilityOracle:
    free = workspace_free_space(mission)
    start = (float(mission.robot.start[0]), float(mission.robot.start[1]))
    return VisibilityOracle(free, [shapely.Polygon(r.polygon) for r in mission.regions], start)


def test_the_tour_oracles_two_readings_agree() -> None:
    """The tour as a min-plus product over the touching nodes' distances is the tour as a
    Dijkstra in the layered graph from every touching node of the first target."""
    mission = compile_mission("five.yaml", text=_five(tuple(FIVE)), until="mission")
    oracle = _visibility_oracle(mission.compilation.get(MISSION))
    for order in [(0, 1, 2, 3, 4), (0, 3, 1, 4, 2), (4, 2, 0, 1, 3), (2, 0), (1, 4, 3), (3,)]:
        product, layered = oracle.tour_length(order), oracle.layered_tour_length(order)
        assert math.isclose(product, layered, rel_tol=1e-9), (order, product, layered)


@pytest.mark.parametrize(
    ("listing", "nw"),
    [
        (("sw", "ne", "se", "nw"), [0.5, 8.0, 2.0, 9.5]),
        (("sw", "se", "nw", "ne"), [0.5, 8.0, 2.0, 9.5]),
        (("ne", "sw", "nw", "se"), [3.0, 7.5, 4.5, 9.0]),
    ],
)
def test_a_patrol_visits_its_goals_in_the_best_order(
    listing: tuple[str, ...], nw: list[float]
) -> None:
    """Whatever order the task lists the goals in, the plan's cycle visits them in the order
    of the shortest closed tour (brute force over every order with the tour oracle)."""
    result = compile_mission("square.yaml", text=_patrol(listing, nw), until="plan")
    witness = result.compilation.get(WITNESS)
    names = tuple(sorted(listing))
    tour = _tour_oracle(result.compilation.get(MISSION))
    best = min(tour(("sw", *rest)) for rest in itertools.permutations(("ne", "nw", "se")))
    planned = _cyclic_order(witness, names)
    assert sorted(planned) == list(names)
    assert math.isclose(tour(planned), best, rel_tol=1e-9), (planned, tour(planned), best)
    assert len(witness.stats["order_lengths"]) == 3


FIVE = {
    "dock": [0.5, 0.5, 2.0, 2.0],
    "lab": [12.0, 0.5, 13.5, 2.0],
    "bay": [12.0, 8.0, 13.5, 9.5],
    "desk": [6.5, 8.2, 8.0, 9.7],
    "shop": [0.5, 7.5, 2.0, 9.0],
}


def _five(listing: tuple[str, ...]) -> str:
    """A 14 x 10 room with two pillars and five goals round its walls, patrolled in
    ``listing``."""
    document = {
        "version": 1,
        "name": "five",
        "workspace": {
            "boundary": {"rect": [0, 0, 14, 10]},
            "holes": [{"rect": [4, 3, 6, 6]}, {"rect": [9, 3.5, 10, 6.5]}],
        },
        "regions": {name: {"rect": rect} for name, rect in FIVE.items()},
        "robot": {"start": [7.0, 1.0], "max_speed": 1.0},
        "task": [f"patrol {', '.join(listing[:-1])} and {listing[-1]}"],
    }
    return yaml.safe_dump(document)


@pytest.mark.parametrize(
    "listing", [("dock", "bay", "shop", "lab", "desk"), ("desk", "dock", "bay", "shop", "lab")]
)
def test_past_the_budget_the_tour_order_of_the_sets_is_planned(
    listing: tuple[str, ...], monkeypatch: pytest.MonkeyPatch
) -> None:
    """When the plans of every order would pass the budget, the one order of the shortest
    tour between the sets' triangles is planned: the cycle then visits the five goals in the
    best order of the tour oracle (brute force over the 12 orders)."""
    text = _five(listing)
    built = compile_mission("five.yaml", text=text, until="automaton").compilation
    first = plan_mission(built.get(MISSION), built.get(ABSTRACTION), built.get(AUTOMATON))
    nodes = int(first.witness.stats["product_nodes"])
    # room for the first plan and one more, not for the eleven other orders
    monkeypatch.setattr(shortest, "NODE_BUDGET", 3 * nodes)
    result = compile_mission("five.yaml", text=text, until="plan")
    witness = result.compilation.get(WITNESS)
    names = tuple(sorted(listing))
    tour = _tour_oracle(result.compilation.get(MISSION))
    others = [n for n in names if n != "dock"]
    best = min(tour(("dock", *rest)) for rest in itertools.permutations(others))
    planned = _cyclic_order(witness, names)
    assert sorted(planned) == list(names)
    assert math.isclose(tour(planned), best, rel_tol=1e-9), (planned, tour(planned), best)
    assert len(witness.stats["order_lengths"]) == 2  # the first plan's order and the tour's
