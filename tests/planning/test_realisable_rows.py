"""The realisable moves and stays of some triangles are the rows of the whole mesh's tables.

The planner checks a witness against the tables of its path's triangles only; the oracle is the
tables of every triangle, computed the plain way and read at the same rows.
"""

from __future__ import annotations

from functools import cache
from pathlib import Path

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from tlmpc.abstraction import build_abstraction
from tlmpc.abstraction.model import Abstraction
from tlmpc.mission import load_mission
from tlmpc.planning.robust import corner_angles, realisable

ROOT = Path(__file__).resolve().parents[2]


@cache
def _mesh() -> Abstraction:
    return build_abstraction(load_mission(ROOT / "specs" / "example7.yaml"))


@given(st.data(), st.sampled_from([0.0, 0.05, 0.3, 0.7]))
def test_rows_of_some_triangles_equal_the_whole_tables(data: st.DataObject, ratio: float) -> None:
    mesh = _mesh()
    chosen = np.array(
        sorted(data.draw(st.sets(st.integers(0, mesh.num_triangles - 1), max_size=40))),
        dtype=np.int64,
    )
    assert corner_angles(mesh, chosen).tobytes() == corner_angles(mesh)[chosen].tobytes()
    moves, stays = realisable(mesh, ratio, chosen)
    all_moves, all_stays = realisable(mesh, ratio)
    assert np.array_equal(moves, all_moves[chosen])
    assert np.array_equal(stays, all_stays[chosen])
