"""``affine_laws`` solves many triangles' fields in one call: each is ``affine_law``'s, bit for
bit (degenerate and far-off triangles included), and each interpolates its vertex velocities."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
from hypothesis import given, settings
from hypothesis import strategies as st

from tlmpc.control.geometry import affine_law, affine_laws

FloatArray = npt.NDArray[np.float64]

_coordinate = st.floats(-1e6, 1e6, allow_nan=False, allow_subnormal=False)
_velocity = st.floats(-10.0, 10.0, allow_nan=False, allow_subnormal=False)


@st.composite
def _triangles(draw: st.DrawFn) -> tuple[FloatArray, FloatArray]:
    corners = np.array(draw(st.lists(st.tuples(_coordinate, _coordinate), min_size=3, max_size=3)))
    if draw(st.booleans()):  # a small triangle far from the origin
        corners = corners * 1e-6 + draw(_coordinate)
    if draw(st.integers(0, 9)) == 0:  # point-like: every corner the same
        corners = np.repeat(corners[:1], 3, axis=0)
    velocities = np.array(draw(st.lists(st.tuples(_velocity, _velocity), min_size=3, max_size=3)))
    return corners, velocities


@settings(max_examples=60, deadline=None)
@given(st.lists(_triangles(), min_size=0, max_size=12))
def test_affine_laws_are_affine_law_bit_for_bit(
    triangles: list[tuple[FloatArray, FloatArray]],
) -> None:
    with np.errstate(all="ignore"):
        try:
            one_by_one = [affine_law(c, w) for c, w in triangles]
        except np.linalg.LinAlgError:  # a singular system: the batch refuses it too
            return
        together = affine_laws([c for c, _ in triangles], [w for _, w in triangles])
    assert len(together) == len(one_by_one)
    for (gain, offset), (gain_1, offset_1) in zip(together, one_by_one, strict=True):
        assert gain.tobytes() == gain_1.tobytes()
        assert offset.tobytes() == offset_1.tobytes()


def test_affine_laws_interpolate_the_vertex_velocities() -> None:
    corners = [
        np.array([[0.0, 0.0], [2.0, 0.0], [0.0, 1.0]]),
        np.array([[5.0, 5.0], [6.0, 5.5], [5.0, 7.0]]),
    ]
    velocities = [
        np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, -1.0]]),
        np.array([[0.5, 0.5], [1.0, 0.0], [0.0, 2.0]]),
    ]
    for (gain, offset), c, w in zip(
        affine_laws(corners, velocities), corners, velocities, strict=True
    ):
        assert np.allclose(c @ gain.T + offset, w, atol=1e-12)
