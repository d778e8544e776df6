"""Hypothesis strategy: small maps with corridors, dead ends, bays, spirals, pockets, slivers
and blocking regions, with Next-free tasks that are sometimes possible and sometimes not.

The free space is a buffered skeleton (a random grid walk, a square spiral or a comb of bays),
so corridors can be 0.2 wide and walks that cross themselves enclose pockets (holes).
"""

from __future__ import annotations

import json
from dataclasses import dataclass

from hypothesis import strategies as st
from shapely.geometry import LineString, MultiLineString, Polygon, box

Coords = list[tuple[float, float]]

#: Task templates in Spot syntax over the placeholders A, B, C (distinct regions).
TEMPLATES = (
    "F A",
    "F A & F B",
    "F(A & F B)",
    "F(A & F(B & F A))",
    "G F A & G F B",
    "G !C & G F A & G F B",
    "F A & G(!C | A)",
    "!B U A",
    "G !A",
    "G(A | B)",
    "G !C & F A",
    "F G A",
    "G F A & F G B",
    "F(A & F B) & G !C",
    "G(A -> F B) & G F A",
    "G !A & F A",
    "F A & G !B & G F C",
    "G(!A | F B)",
)

RETURNS = ("F(A & F B)", "F(B & F A)", "G F A & G F B", "F(A & F(B & F A))", "G !C & G F A & G F B")


@dataclass(frozen=True)
class FaceMap:
    """A generated mission: geometry, regions, start and an LTL task."""

    kind: str
    boundary: Coords
    holes: list[Coords]
    regions: dict[str, Coords]
    start: tuple[float, float]
    ltl: str

    def yaml(self) -> str:
        """The mission file (JSON is YAML)."""
        return json.dumps(
            {
                "version": 1,
                "name": f"face-{self.kind}",
                "workspace": {"boundary": self.boundary, "holes": self.holes},
                "regions": dict(self.regions),
                "robot": {"start": list(self.start), "max_speed": 1.0},
                "ltl": self.ltl,
            }
        )


def _coords(ring: object) -> Coords:
    points = [(round(x, 6), round(y, 6)) for x, y in list(ring.coords)[:-1]]  # type: ignore[attr-defined]
    return points


def _skeleton(draw: st.DrawFn, kind: str) -> LineString | MultiLineString:
    if kind == "spiral":
        s = draw(st.sampled_from([1.0, 1.5]))
        pts = [(0, 0), (4, 0), (4, 4), (0, 4), (0, 1), (3, 1), (3, 3), (1, 3), (1, 2), (2, 2)]
        return LineString([(x * s, y * s) for x, y in pts])
    if kind == "comb":
        length = draw(st.integers(3, 6))
        xs = draw(st.lists(st.integers(0, length), min_size=1, max_size=3, unique=True))
        teeth = [LineString([(x, 0), (x, draw(st.integers(1, 4)))]) for x in xs]
        return MultiLineString([LineString([(0, 0), (length, 0)]), *teeth])
    points = [(0, 0)]
    for _ in range(draw(st.integers(1, 6))):
        axis = draw(st.integers(0, 1))
        step = draw(st.sampled_from([-3, -2, -1, 1, 2, 3]))
        x, y = points[-1]
        nxt = (x + step, y) if axis == 0 else (x, y + step)
        if nxt != points[-1]:
            points.append(nxt)
    if len(points) < 2:
        points.append((2, 0))
    return LineString(points)


@st.composite
def face_maps(draw: st.DrawFn) -> FaceMap:
    """A map and a task; regions always lie inside the boundary (they may cover holes)."""
    kind = draw(st.sampled_from(["walk", "spiral", "comb"]))
    width = draw(st.sampled_from([0.2, 0.4, 1.0] if kind != "spiral" else [0.2, 0.4]))
    skeleton = _skeleton(draw, kind)
    free = skeleton.buffer(width / 2, cap_style="square", join_style="mitre")
    if draw(st.booleans()):
        free = free.union(box(-1.0, -1.0, 1.0, 1.0))
    if free.geom_type != "Polygon":
        free = max(free.geoms, key=lambda g: g.area)
    outer = Polygon(free.exterior)
    names = ["a", "b", "c"][: draw(st.integers(2, 3))]
    regions: dict[str, Coords] = {}
    ends = [(p.x, p.y) for p in skeleton.boundary.geoms]  # dead ends of corridors and bays
    for name in names:
        if draw(st.booleans()) and ends:
            cx, cy = draw(st.sampled_from(ends))
        else:
            centre = skeleton.interpolate(draw(st.integers(0, 20)) / 20 * skeleton.length)
            cx, cy = round(centre.x, 2), round(centre.y, 2)
        shape = draw(st.sampled_from(["small", "sliver", "block", "room"]))
        half = {"small": (0.3, 0.3), "sliver": (0.025, 0.6), "block": (0.6, 0.6), "room": (1, 1)}
        hx, hy = (w * width if shape != "room" else w for w in half[shape])
        if draw(st.booleans()):
            hx, hy = hy, hx
        rect = box(cx - hx, cy - hy, cx + hx, cy + hy)
        if not outer.covers(rect):
            # Clipped to the map: a region filling the end of a corridor or a bay.
            clipped = rect.intersection(outer)
            if clipped.geom_type == "Polygon" and not clipped.interiors and clipped.area > 0:
                rect = clipped.simplify(0)
            else:
                rect = box(cx - 0.025, cy - 0.025, cx + 0.025, cy + 0.025)
        regions[name] = _coords(rect.exterior)
    if draw(st.booleans()) and ends:
        sx, sy = draw(st.sampled_from(ends))
    else:
        point = skeleton.interpolate(draw(st.integers(0, 20)) / 20 * skeleton.length)
        sx, sy = point.x, point.y
    start = (round(sx + 0.0123 * width, 6), round(sy + 0.0071 * width, 6))
    # Half the tasks go somewhere and come back: the U-turns that need refinement.
    template = draw(st.sampled_from(RETURNS if draw(st.booleans()) else TEMPLATES))
    placeholders = {"A": names[0], "B": names[1], "C": names[-1]}
    if len(names) == 2 and "C" in template:
        placeholders["C"] = draw(st.sampled_from(names))
    ltl = "".join(placeholders.get(ch, ch) for ch in template)
    return FaceMap(
        kind=kind,
        boundary=_coords(free.exterior),
        holes=[_coords(ring) for ring in free.interiors],
        regions=regions,
        start=start,
        ltl=ltl,
    )
