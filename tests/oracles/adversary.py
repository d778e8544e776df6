"""An adversarial closed loop for one compiled step, independent of tlmpc.

The step's stored field u = K x + g is integrated by scipy's RK45 with a disturbance of norm
exactly d chosen by an adversary at every instant, from starting points on the triangle's
corners (a hair inside), its edge midpoints and its centroid. The adversaries push straight
out of the facet the step must not cross that is nearest to the state, straight against the
exit, along each facet (both ways), and the worst of these at each instant for the nearest
guarded facet. The checker computes its own facets from the vertices and reports the facets
each run crosses (none for a stay that holds) and when it leaves.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from scipy.integrate import solve_ivp

Push = Callable[[float, np.ndarray], np.ndarray]


def facets(vertices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Outward unit normals and offsets of facets 0..2 (facet i opposite vertex i) of a
    counter-clockwise triangle."""
    normals, offsets = np.empty((3, 2)), np.empty(3)
    for i in range(3):
        a, b = vertices[(i + 1) % 3], vertices[(i + 2) % 3]
        n = np.array([b[1] - a[1], a[0] - b[0]])
        normals[i] = n / np.linalg.norm(n)
        offsets[i] = normals[i] @ a
    return normals, offsets


def adversaries(
    d: float, normals: np.ndarray, offsets: np.ndarray, exit_edge: int | None
) -> list[Push]:
    """Pushes of norm ``d``: out of the nearest guarded facet, against the exit, and along
    each facet both ways (where a corner's two facets meet at a sharp angle, a push along
    one is the most dangerous for the other)."""
    guarded = [j for j in range(3) if j != exit_edge]

    def out_of_nearest(t: float, x: np.ndarray) -> np.ndarray:
        nearest = min(guarded, key=lambda j: offsets[j] - normals[j] @ x)
        return np.asarray(d * normals[nearest])

    pushes: list[Push] = [out_of_nearest]
    if exit_edge is not None:
        back = -d * normals[exit_edge]
        pushes.append(lambda t, x: back)
    for j in range(3):
        along = d * np.array([-normals[j][1], normals[j][0]])
        pushes += [_steady(along), _steady(-along), _steady(d * normals[j])]
    return pushes


def _steady(push: np.ndarray) -> Push:
    def steady(t: float, x: np.ndarray) -> np.ndarray:
        return push

    return steady


def starts(vertices: np.ndarray) -> list[np.ndarray]:
    """Corners and edge midpoints a thousandth of the way to the centroid, and the centroid
    (nearer, a sliver's start would lie on its facet to rounding)."""
    centre = vertices.mean(axis=0)
    points = [v + 1e-3 * (centre - v) for v in vertices]
    for i in range(3):
        middle = (vertices[(i + 1) % 3] + vertices[(i + 2) % 3]) / 2
        points.append(middle + 1e-3 * (centre - middle))
    points.append(centre)
    return points


def run(
    step: dict[str, Any], d: float, x0: np.ndarray, push: Push, horizon: float
) -> tuple[list[int], float | None]:
    """(the facets crossed, the time the first was crossed) for one adversarial run.

    Integrated in barycentric coordinates: lambda_i = (c_i - n_i x) / h_i, facet i is
    lambda_i = 0, and lambda_i' = -n_i (sum_j lambda_j w_j + push) / h_i with w_j the field
    at corner j. Each coordinate is of order one whatever the triangle's shape or place, so
    the solver's relative tolerance is a tolerance on the distance to each facet over its
    height (in map coordinates a sliver 1e-8 wide at 5 from the origin is below it).
    """
    vertices = np.asarray(step["vertices"], dtype=float)
    gain, offset = np.asarray(step["K"], dtype=float), np.asarray(step["g"], dtype=float)
    normals, offsets = facets(vertices)
    heights = offsets - np.einsum("ij,ij->i", normals, vertices)
    origin = vertices[0]
    corner_field = np.array([gain @ (v - origin) for v in vertices]) + (gain @ origin + offset)
    rates = -(normals @ corner_field.T) / heights[:, None]  # d lambda_i / d lambda_j
    lam0 = (offsets - normals @ x0) / heights

    def flow(t: float, lam: np.ndarray) -> np.ndarray:
        x = lam @ vertices
        return np.asarray(rates @ lam - (normals @ push(t, x)) / heights)

    def crossing_of(facet: int) -> Callable[[float, np.ndarray], float]:
        def crossing(t: float, lam: np.ndarray) -> float:
            return float(lam[facet])

        crossing.terminal = True  # type: ignore[attr-defined]
        crossing.direction = -1  # type: ignore[attr-defined]
        return crossing

    events = [crossing_of(facet) for facet in range(3)]
    # LSODA switches to a stiff method where a sliver's rates (max_speed / its width) are huge
    result = solve_ivp(
        flow, (0.0, horizon), lam0, method="LSODA", events=events, rtol=1e-10, atol=1e-13
    )
    crossed = [facet for facet in range(3) if len(result.t_events[facet])]
    when = min((float(result.t_events[f][0]) for f in crossed), default=None)
    return crossed, when


def check_step(step: dict[str, Any], d: float, max_speed: float) -> None:
    """Every adversarial run from every start leaves through the planned facet only, within
    ``exit_time_bound``; a stay is never left."""
    vertices = np.asarray(step["vertices"], dtype=float)
    normals, offsets = facets(vertices)
    exit_edge = step["exit_edge"]
    size = float(np.ptp(vertices, axis=0).max())
    bound = step.get("exit_time_bound")
    horizon = 40.0 * size / max_speed if bound is None else 1.5 * float(bound)
    for push in adversaries(d, normals, offsets, exit_edge):
        for x0 in starts(vertices):
            crossed, when = run(step, d, x0, push, horizon)
            if exit_edge is None:
                assert crossed == [], (step["step"], crossed)
            else:
                assert crossed == [exit_edge], (step["step"], crossed, x0)
                assert when is not None
                assert bound is not None
                assert when <= float(bound) * (1 + 1e-6), (step["step"], when)
