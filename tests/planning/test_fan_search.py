"""The cell moves' fan search (tlmpc.planning.cells._fan_widths), every vertex and direction at
once, against its definition: per direction t and move, the smallest over the move's vertices
of the corner push of normals + [(cos t, sin t)], evaluated one at a time by the oracle of the
arc holding the normals and xi (tests/oracles/brute_push.py, by sorting) and by the one
implementation the final widths and the control stage use (best_direction). Random moves of
one to three vertices, each with one or two unit normals (a convex cell's vertex lies on two
sides), and random direction angles, several moves in one call; and the refusal of a vertex
with three normals."""

from __future__ import annotations

import math

import numpy as np
import pytest
from brute_push import arc_push
from hypothesis import given, settings
from hypothesis import strategies as st

from tlmpc.planning.cells import _fan_widths
from tlmpc.planning.robust import best_direction

angles = st.floats(-math.pi, math.pi, allow_nan=False)
vertex = st.lists(angles, min_size=1, max_size=2).map(
    lambda turns: [(math.cos(a), math.sin(a)) for a in turns]
)
move = st.lists(vertex, min_size=1, max_size=3)


@settings(max_examples=200, deadline=None)
@given(st.lists(move, min_size=1, max_size=4), st.lists(angles, min_size=1, max_size=12))
def test_every_direction_and_move_is_the_definition(
    moves: list[list[list[tuple[float, float]]]], turns: list[float]
) -> None:
    columns = np.array([[t + 0.37 * k for k in range(len(moves))] for t in turns])
    found = _fan_widths(moves, columns)
    assert found.shape == (len(turns), len(moves))
    for d in range(len(turns)):
        for m, groups in enumerate(moves):
            t = float(columns[d, m])
            xi = (math.cos(t), math.sin(t))
            expected = min(1.0, *(arc_push([*normals, xi]) for normals in groups))
            assert found[d, m] == pytest.approx(expected, abs=1e-12)
            pushed = min(1.0, *(max(best_direction([*n, xi])[0], 0.0) for n in groups))
            assert found[d, m] == pytest.approx(pushed, abs=1e-12)


def test_a_move_without_rows_pushes_fully() -> None:
    assert _fan_widths([[]], np.zeros((3, 1))).tolist() == [[1.0], [1.0], [1.0]]


def test_a_vertex_on_three_sides_is_no_convex_cells() -> None:
    with pytest.raises(ValueError, match="at most two"):
        _fan_widths([[[(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0)]]], np.zeros((1, 1)))


def test_moves_of_one_shape_share_a_search_and_nothing_else() -> None:
    """Every move of Example 1's mission mesh and cells' own mesh, searched with all the others
    at once (one search per distinct shape), equals its own search, alone."""
    from pathlib import Path

    from tlmpc.abstraction import build_abstraction
    from tlmpc.abstraction.layout import planning_layout
    from tlmpc.mission.body import requested_margin
    from tlmpc.mission.load import load_mission
    from tlmpc.planning.cells import _partition, _pending, _searched_moves

    mission = load_mission(Path(__file__).resolve().parents[2] / "specs" / "example1.yaml")
    layout = planning_layout(mission, requested_margin(mission))
    checked = 0
    for lines in (None, "arrangement", "reflex"):
        cells = _partition(build_abstraction(mission, layout, lines=lines))
        for (cell, target), together in cells._moves.items():
            rows = _pending(cells, cell, target)
            if rows is None:
                continue
            (alone,) = _searched_moves(cells, [rows])
            assert (alone.xi, alone.width) == (together.xi, together.width)
            checked += 1
    assert checked > 300


def test_a_partition_is_kept_per_mesh_object() -> None:
    """Within one compilation's memo the same mesh object gives the same partition; another
    mesh, even of equal content, its own (kept by identity, never by a possibly reused id
    alone); outside a compilation each ask partitions anew."""
    from pathlib import Path

    from tlmpc.base.memo import memo_scope
    from tlmpc.mission.body import requested_margin
    from tlmpc.mission.load import load_mission
    from tlmpc.planning.cells import PARTITIONS, partition
    from tlmpc.planning.mission import abstraction_for

    mission = load_mission(Path(__file__).resolve().parents[2] / "specs" / "example1.yaml")
    mesh = abstraction_for(mission, requested_margin(mission))
    other = abstraction_for(mission, requested_margin(mission))
    assert partition(mesh) is not partition(mesh)
    with memo_scope():
        first = partition(mesh)
        assert partition(mesh) is first
        assert partition(other) is not first
        assert partition(other).abstraction is other
        for _ in range(PARTITIONS.keep):
            partition(abstraction_for(mission, requested_margin(mission)))
        again = partition(mesh)  # pushed out by newer meshes: partitioned afresh, the same
        assert again is not first
        assert [c.triangles for c in again.cells] == [c.triangles for c in first.cells]
