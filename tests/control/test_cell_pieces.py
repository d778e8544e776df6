"""Which piece of a cell field holds a point, against shapely: the one search
(tlmpc.simulate.cells.locate) with its two uses, the simulation's (a piece holding the point,
the one the field enters on a shared facet, none outside) and the executor's (nearest_piece:
the nearest piece, held or not)."""

from __future__ import annotations

import numpy as np
import shapely
from hypothesis import given
from hypothesis import strategies as st

from tlmpc.control.model import KEPT, CellField
from tlmpc.simulate.cells import SLACK, locate, nearest_piece

#: A 4 x 2 rectangle cut into four triangles by its diagonals' crossing point (2, 1).
CORNERS = np.array(
    [
        [[0.0, 0.0], [4.0, 0.0], [2.0, 1.0]],
        [[4.0, 0.0], [4.0, 2.0], [2.0, 1.0]],
        [[4.0, 2.0], [0.0, 2.0], [2.0, 1.0]],
        [[0.0, 2.0], [0.0, 0.0], [2.0, 1.0]],
    ]
)
FIELD = CellField(
    triangles=(10, 11, 12, 13),
    vertices=CORNERS,
    velocities=np.zeros((4, 3, 2)),
    gains=np.zeros((4, 2, 2)),
    offsets=np.zeros((4, 2)),
    neighbours=((1, 3, KEPT), (2, 0, KEPT), (3, 1, KEPT), (0, 2, KEPT)),
    direction=(1.0, 0.0),
    cell=0,
    target_cell=None,
)
PIECES = [shapely.Polygon(corners) for corners in CORNERS]


@given(st.floats(0.0, 4.0), st.floats(0.0, 2.0))
def test_a_point_inside_is_in_the_piece_shapely_says_holds_it(x: float, y: float) -> None:
    piece = nearest_piece(FIELD, np.array([x, y]))
    assert PIECES[piece].buffer(1e-9).covers(shapely.Point(x, y))
    assert locate(FIELD, np.array([x, y]), velocity_hint=False) == piece


@given(st.sampled_from(range(4)), st.floats(0.01, 0.99), st.floats(1e-6, 0.05))
def test_a_point_just_outside_a_side_gets_that_sides_piece(
    piece: int, along: float, out: float
) -> None:
    (ax, ay), (bx, by), _ = CORNERS[piece]  # the outer side of each piece comes first
    length = float(np.hypot(bx - ax, by - ay))
    normal = np.array([by - ay, -(bx - ax)]) / length  # outward: the pieces run CCW
    point = np.array([ax + along * (bx - ax), ay + along * (by - ay)]) + out * normal
    assert not shapely.Polygon([(0, 0), (4, 0), (4, 2), (0, 2)]).covers(shapely.Point(*point))
    assert nearest_piece(FIELD, point) == piece


@given(st.sampled_from(range(4)), st.floats(0.01, 0.99), st.floats(1e-6, 0.05))
def test_a_point_outside_the_cell_is_in_no_piece(piece: int, along: float, out: float) -> None:
    (ax, ay), (bx, by), _ = CORNERS[piece]
    length = float(np.hypot(bx - ax, by - ay))
    normal = np.array([by - ay, -(bx - ax)]) / length
    point = np.array([ax + along * (bx - ax), ay + along * (by - ay)]) + out * normal
    assert locate(FIELD, point) is None
    assert locate(FIELD, point, velocity_hint=False) is None
    # within the slack of the side: still its piece
    inside = point - (out - 0.5 * SLACK) * normal
    assert locate(FIELD, inside, velocity_hint=False) == piece


def _flowing(velocity: tuple[float, float]) -> CellField:
    """FIELD with the constant velocity ``velocity`` on every piece."""
    offsets = np.tile(np.array(velocity), (4, 1))
    return CellField(
        triangles=FIELD.triangles,
        vertices=FIELD.vertices,
        velocities=np.tile(np.array(velocity), (4, 3, 1)),
        gains=FIELD.gains,
        offsets=offsets,
        neighbours=FIELD.neighbours,
        direction=FIELD.direction,
        cell=FIELD.cell,
        target_cell=FIELD.target_cell,
    )


@given(st.floats(0.05, 0.95), st.sampled_from([(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)]))
def test_on_a_shared_facet_the_piece_the_field_enters(
    along: float, velocity: tuple[float, float]
) -> None:
    """On the facet from (4, 0) to the centre (2, 1), between the bottom piece 0 and the right
    piece 1: the piece shapely finds a little way along the flow."""
    point = np.array([4.0 - 2.0 * along, along])
    ahead = shapely.Point(*(point + 1e-3 * np.array(velocity)))
    expected = next(k for k, polygon in enumerate(PIECES) if polygon.covers(ahead))
    assert locate(_flowing(velocity), point) == expected
