"""Parallel automaton edges (same successor, different marks) give one accepting product edge."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tlmpc.abstraction import build_abstraction
from tlmpc.automata.model import Automaton, Edge
from tlmpc.ltl.ast import Const
from tlmpc.mission import load_mission
from tlmpc.planning.product import build_product

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("accepting_first", [True, False])
def test_an_edge_is_accepting_when_any_parallel_edge_is(accepting_first: bool) -> None:
    mission = load_mission(ROOT / "specs" / "example1.yaml")
    abstraction = build_abstraction(mission)
    marked = Edge(src=0, dst=0, guard=Const(True), marks=frozenset({0}))
    plain = Edge(src=0, dst=0, guard=Const(True))
    automaton = Automaton(
        aps=(),
        num_states=1,
        initial=0,
        edges=(marked, plain) if accepting_first else (plain, marked),
        num_acc=1,
    )
    product = build_product(
        abstraction,
        automaton,
        allowed=np.ones(abstraction.num_triangles, dtype=bool),
        start_point=mission.robot.start,
        metric="length",
    )
    # One automaton state: every product edge is a move of the map, each exactly once.
    moves = int((abstraction.neighbors >= 0).sum())
    assert product.graph.nnz >= moves
    assert int(product.accepting.sum()) == product.graph.nnz
    assert product.stutter_accepting.any()
