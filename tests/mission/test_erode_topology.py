"""Eroding a free space whose mitred buffer GEOS gets wrong.

Beside a wall 0.002 thick (turned, with a small obstacle in the room), GEOS returns the
free space's boundary buffered with mitred joins as an invalid polygon (nested shells), and
the overlay on it raised a TopologyException: `tlmpc compile` ended in an internal error
(exit 3).  The exact construction needs no buffer; the oracle is shapely's distance from
the obstacles and its own (rounded) erosion.
"""

from __future__ import annotations

import shapely

import tlmpc
from tlmpc.mission.cspace import erode

BOUNDARY = [
    [1.5825730400753373, -1.7245309792168868],
    [5.720022299420423, 0.04507734647126016],
    [5.213324448831717, 1.2297669843970693],
    [5.215163315169203, 1.2305534769862643],
    [5.721861165757909, 0.0458638390604551],
    [10.776904727508859, 2.207931966756774],
    [8.417426959924663, 7.724530979216887],
    [3.3623833981737126, 5.562462851520568],
    [4.8010749669581765, 2.198716603673014],
    [4.79923610062069, 2.197930111083819],
    [3.360544531836226, 5.561676358931374],
    [-0.776904727508859, 3.7920680332432264],
]
HOLE = [
    [2.3937273771562064, 2.8608848843046424],
    [2.906062648942481, 3.1887759779373974],
    [2.380990863606194, 3.399250727595792],
]
#: the body radius plus the margin plus two steps of the snapping grid (1e-8 here)
REACH = 0.376 + 0.151 + 2e-8


def _free() -> shapely.Polygon:
    return shapely.Polygon(BOUNDARY).difference(shapely.Polygon(HOLE))


def test_the_mitred_buffer_is_invalid_here() -> None:
    # the premise: if GEOS ever fixes this, the test below no longer exercises the fallback
    mitred = shapely.boundary(_free()).buffer(REACH, join_style="mitre", mitre_limit=2.0)
    assert not mitred.is_valid


def test_erosion_beside_a_thin_wall_keeps_the_distance() -> None:
    free = _free()
    eroded = erode(free, REACH)
    outside = shapely.box(-5.0, -5.0, 15.0, 12.0).difference(free)
    assert shapely.distance(outside, eroded) >= REACH * (1.0 - 1e-9)
    rounded = free.buffer(-REACH, quad_segs=64)
    assert abs(eroded.area - rounded.area) <= 1e-3 * rounded.area


def test_the_mission_compiles() -> None:
    def points(ring: list[list[float]]) -> str:
        return "[" + ", ".join(f"[{x!r}, {y!r}]" for x, y in ring) + "]"

    text = (
        "version: 1\n"
        f"workspace: {{boundary: {points(BOUNDARY)}, holes: [{points(HOLE)}]}}\n"
        "regions: {g: {rect: [7.5, 5.2, 8.2, 6.2]}}\n"
        "robot: {start: [2.108759914221323, -0.41185151587616864], radius: 0.376}\n"
        "task: [visit g]\n"
        "options: {margin: 0.151}\n"
    )
    compiled = tlmpc.compile(text, until="abstraction")
    assert compiled.artifacts["abstraction.json"]["triangles"]
