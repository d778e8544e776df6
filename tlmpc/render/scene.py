"""What a figure of a compiled mission shows, computed once for every renderer.

A :class:`Scene` is plain data in world coordinates: the map, its holes, the regions with
their names, the mesh's edges, the discrete plan, the simulated trajectory (or a recorded
log) with its arc-length colouring, the start and any violations.  The SVG writer
(:mod:`tlmpc.render.svg`) and the matplotlib renderer (:mod:`tlmpc.render.plot`) only draw it, so
both pictures always agree.  Building a scene imports numpy (for the mesh), never a
plotting library.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import numpy as np
    import numpy.typing as npt

    FloatArray = npt.NDArray[np.float64]

Point = tuple[float, float]
Polygon = tuple[Point, ...]

#: Region colours, cycled; readable on top of each other when translucent.
REGION_COLOURS = (
    "#4e79a7",
    "#f28e2b",
    "#59a14f",
    "#e15759",
    "#76b7b2",
    "#edc948",
    "#b07aa1",
    "#ff9da7",
    "#9c755f",
)
#: Beyond this many regions only the ones the task names are labelled.
MAX_REGION_NAMES = 60
#: A denser mesh (inside the view) is a grey blur at any printable size.
MAX_MESH_TRIANGLES = 20_000
#: Beyond this many regions in the view only the task's are drawn (the rest is a blur).
MAX_DRAWN_REGIONS = 20_000

#: Viridis at eleven evenly spaced stops (matplotlib's table), for the arc-length colouring.
_VIRIDIS = (
    (0.267, 0.005, 0.329),
    (0.283, 0.141, 0.458),
    (0.254, 0.265, 0.530),
    (0.207, 0.372, 0.553),
    (0.164, 0.471, 0.558),
    (0.128, 0.567, 0.551),
    (0.135, 0.659, 0.518),
    (0.267, 0.749, 0.441),
    (0.478, 0.821, 0.318),
    (0.741, 0.873, 0.150),
    (0.993, 0.906, 0.144),
)


def viridis(fraction: float) -> str:
    """The ``#rrggbb`` colour of ``fraction`` in [0, 1] on the viridis scale."""
    f = min(1.0, max(0.0, fraction)) * (len(_VIRIDIS) - 1)
    low = min(int(f), len(_VIRIDIS) - 2)
    w = f - low
    rgb = [a + (b - a) * w for a, b in zip(_VIRIDIS[low], _VIRIDIS[low + 1], strict=True)]
    return "#" + "".join(f"{round(255 * c):02x}" for c in rgb)


@dataclass(frozen=True, slots=True)
class Region:
    """A region of the mission, its colour and where its name goes."""

    name: str
    polygon: Polygon
    colour: str
    named_by_task: bool
    labelled: bool
    label_at: Point  # where the name goes (when labelled)


@dataclass(frozen=True, slots=True)
class Violation:
    """A place where a trajectory breaks the task or leaves the free space."""

    position: Point
    time: float | None
    message: str


@dataclass(frozen=True, slots=True)
class Path:
    """A trajectory: its points and the arc-length fraction reached at each."""

    points: tuple[Point, ...]
    fractions: tuple[float, ...]
    length: float


@dataclass(frozen=True, slots=True)
class PlayMark:
    """A place of an unrealizable mission's counterstrategy play: the steps the robot is
    there, and what it senses at each (``counterstrategy.json``)."""

    position: Point
    text: str


@dataclass(frozen=True, slots=True)
class Scene:
    """Everything one figure shows, in world coordinates."""

    title: str
    view: tuple[float, float, float, float]  # x0, y0, x1, y1
    boundary: Polygon
    holes: tuple[Polygon, ...]
    regions: tuple[Region, ...]
    emphasise_task_regions: bool
    mesh_edges: FloatArray = field(compare=False)  # rows x0, y0, x1, y1
    mesh_omitted: int  # triangles in the view not drawn (mesh too dense), 0 when drawn
    regions_omitted: int  # regions in the view not drawn (too many), 0 when all are
    plan_prefix: tuple[Point, ...]
    plan_cycle: tuple[Point, ...]
    plan_stays: bool
    trajectory: Path | None
    log: Path | None
    start: Point | None
    violations: tuple[Violation, ...]
    #: further pieces of free space (workspace components): outer boundaries, and their holes
    components: tuple[Polygon, ...] = ()
    component_holes: tuple[Polygon, ...] = ()
    #: the points of every polygon in ``regions``, in order, as rows ``x, y`` (when the scene
    #: converted them in one array anyway: the SVG writer then need not convert them again)
    region_points: FloatArray | None = field(default=None, compare=False)
    #: an unrealizable reactive mission: the places of the environment's winning play, in
    #: the order visited (closing back to where it repeats from, if it does)
    play: tuple[PlayMark, ...] = ()
    play_route: tuple[Point, ...] = ()


def _polygon(points: Sequence[Sequence[float]]) -> Polygon:
    return tuple([(float(p[0]), float(p[1])) for p in points])


def _inside(polygon: Polygon, point: Point) -> bool:
    """Whether ``point`` is inside ``polygon`` (even-odd rule)."""
    x, y = point
    hit = False
    for (ax, ay), (bx, by) in zip(polygon, polygon[-1:] + polygon[:-1], strict=True):
        if (ay > y) != (by > y) and x < (bx - ax) * (y - ay) / (by - ay) + ax:
            hit = not hit
    return hit


def label_point(polygon: Polygon) -> Point:
    """Where a region's name goes: its area centroid when that lies inside it, else the
    point inside farthest from its edges (an L-shaped or ring-like region's centroid is
    outside it)."""
    centre = _centroid(polygon)
    if len(polygon) < 3 or _inside(polygon, centre):
        return centre
    import shapely
    from shapely.ops import polylabel

    shape = shapely.Polygon(polygon)
    if not shape.is_valid or shape.area <= 0:
        return centre
    x0, y0, x1, y1 = shape.bounds
    pole = polylabel(shape, tolerance=max(x1 - x0, y1 - y0) / 100)
    return float(pole.x), float(pole.y)


def _centroid(polygon: Polygon) -> Point:
    """The area centroid (the vertex mean for degenerate polygons)."""
    area = cx = cy = 0.0
    for (x0, y0), (x1, y1) in zip(polygon, polygon[1:] + polygon[:1], strict=True):
        cross = x0 * y1 - x1 * y0
        area += cross
        cx += (x0 + x1) * cross
        cy += (y0 + y1) * cross
    if abs(area) < 1e-300:
        n = len(polygon)
        return sum(p[0] for p in polygon) / n, sum(p[1] for p in polygon) / n
    return cx / (3.0 * area), cy / (3.0 * area)


def task_propositions(formula: str | None) -> frozenset[str]:
    """The propositions a task formula (text) names."""
    if not formula:
        return frozenset()
    from tlmpc.ltl.parser import parse_ltl

    return parse_ltl(formula).props()


def _task_propositions(mission: Mapping[str, Any]) -> frozenset[str]:
    return task_propositions(mission.get("formula"))


def label_priority(name: str, polygon: Polygon, named_by_task: bool) -> tuple[int, float, str]:
    """The order names are placed in (every renderer): the task's regions first, then the
    larger ones (by bounding box), then by name."""
    xs = [p[0] for p in polygon]
    ys = [p[1] for p in polygon]
    area = (max(xs) - min(xs)) * (max(ys) - min(ys)) if polygon else 0.0
    return (0 if named_by_task else 1, -area, name)


def named_regions(
    regions: Mapping[str, Sequence[Sequence[float]]], formula: str | None
) -> list[tuple[str, Point, bool]]:
    """The regions whose names are drawn, in placement order, with each name's point and
    whether the task names it: every region, or beyond :data:`MAX_REGION_NAMES` only the
    task's."""
    named = task_propositions(formula)
    many = len(regions) > MAX_REGION_NAMES
    chosen = []
    for name, points in regions.items():
        if many and name not in named:
            continue
        polygon = _polygon(points)
        chosen.append((label_priority(name, polygon, name in named), name, polygon))
    chosen.sort()
    return [(name, label_point(polygon), key[0] == 0) for key, name, polygon in chosen]


def _inside_view(box: tuple[float, float, float, float], view: Sequence[float]) -> bool:
    return not (box[2] < view[0] or box[0] > view[2] or box[3] < view[1] or box[1] > view[3])


def _bbox(points: Sequence[Point]) -> tuple[float, float, float, float]:
    xs = [p[0] for p in points]
    ys = [p[1] for p in points]
    return min(xs), min(ys), max(xs), max(ys)


def _mesh(
    abstraction: Mapping[str, Any],
    view: tuple[float, float, float, float],
    *,
    view_is_whole_map: bool,
) -> tuple[FloatArray, int]:
    """The mesh's unique edges inside ``view`` as rows ``x0, y0, x1, y1`` (and 0), or no
    edges and the number of triangles in the view when there are too many to draw."""
    import numpy as np

    empty = np.zeros((0, 4))
    listed = abstraction["triangles"]
    if len(listed) > MAX_MESH_TRIANGLES and view_is_whole_map:
        return empty, len(listed)  # not even converted: a million triangles cost a second
    triangles = np.asarray(listed, dtype=np.int64).reshape(-1, 3)
    if len(triangles) == 0:
        return empty, 0
    vertices = np.asarray(abstraction["vertices"], dtype=np.float64).reshape(-1, 2)
    corners = vertices[triangles]  # (n, 3, 2)
    low = corners.min(axis=1)
    high = corners.max(axis=1)
    x0, y0, x1, y1 = view
    inside = (high[:, 0] >= x0) & (low[:, 0] <= x1) & (high[:, 1] >= y0) & (low[:, 1] <= y1)
    count = int(inside.sum())
    if count > MAX_MESH_TRIANGLES:
        return empty, count
    visible = triangles[inside]
    pairs = np.concatenate([visible[:, [0, 1]], visible[:, [1, 2]], visible[:, [2, 0]]])
    low_end = pairs.min(axis=1)
    keys = np.unique(low_end * len(vertices) + pairs.max(axis=1))  # each edge once, sorted
    first, second = np.divmod(keys, len(vertices))
    return np.concatenate([vertices[first], vertices[second]], axis=1), 0


#: From this many regions on, their points are converted and boxed in one numpy pass.
_BATCH_FROM = 64


def _region_polygons(
    listed: Sequence[Sequence[Sequence[float]]], view: Sequence[float]
) -> tuple[list[Polygon], list[bool], FloatArray | None]:
    """:func:`_polygon` of each region, whether its bounding box meets ``view``, and all
    their points as rows ``x, y`` when they were gathered in one array (else None).

    With many regions (maps with thousands of rooms) the boxes come from one array and
    ``minimum/maximum.reduceat``: the same floats and the same comparisons as :func:`_bbox`
    and :func:`_inside_view` one by one (the extremes of finite floats do not depend on the
    order).  A non-finite coordinate or an empty ring takes the one-by-one path.
    """
    polygons = [_polygon(points) for points in listed]
    lengths = [len(polygon) for polygon in polygons]
    if len(polygons) < _BATCH_FROM or min(lengths) == 0:
        return polygons, [_inside_view(_bbox(polygon), view) for polygon in polygons], None
    import numpy as np

    chain = itertools.chain.from_iterable
    flat = np.fromiter(chain(chain(polygons)), dtype=np.float64, count=2 * sum(lengths))
    flat = flat.reshape(-1, 2)
    if not np.isfinite(flat).all():
        return polygons, [_inside_view(_bbox(polygon), view) for polygon in polygons], None
    starts = np.cumsum([0, *lengths[:-1]])
    low = np.minimum.reduceat(flat, starts, axis=0)
    high = np.maximum.reduceat(flat, starts, axis=0)
    x0, y0, x1, y1 = view
    outside = (high[:, 0] < x0) | (low[:, 0] > x1) | (high[:, 1] < y0) | (low[:, 1] > y1)
    return polygons, (~outside).tolist(), flat


def _centroids(abstraction: Mapping[str, Any], triangles: Sequence[int]) -> tuple[Point, ...]:
    vertices = abstraction["vertices"]
    tris = abstraction["triangles"]
    result = []
    for t in triangles:
        corners = [vertices[i] for i in tris[t]]
        result.append(
            (sum(c[0] for c in corners) / 3.0, sum(c[1] for c in corners) / 3.0),
        )
    return tuple(result)


def arc_length_path(samples: Sequence[Sequence[float]]) -> Path | None:
    """A :class:`Path` of ``[t, x, y]`` samples, coloured by the distance travelled.

    Colouring by arc length rather than time gives no colour range to a final stay (or any
    pause): the scale shows how far along its route the robot is.
    """
    if not samples:
        return None
    points = tuple([(float(s[1]), float(s[2])) for s in samples])
    steps = [math.hypot(bx - ax, by - ay) for (ax, ay), (bx, by) in itertools.pairwise(points)]
    cumulative = list(itertools.accumulate(steps, initial=0.0))  # summed first to last
    total = cumulative[-1]
    fractions = tuple([c / total for c in cumulative] if total > 0 else [0.0] * len(cumulative))
    return Path(points=points, fractions=fractions, length=total)


def _violations(verdict: Mapping[str, Any] | None) -> tuple[Violation, ...]:
    if verdict is None:
        return ()
    found = []
    for key in ("counterexample", "workspace_violation"):
        example = verdict.get(key)
        if isinstance(example, Mapping) and example.get("position") is not None:
            x, y = example["position"]
            time = example.get("time")
            found.append(
                Violation(
                    position=(float(x), float(y)),
                    time=None if time is None else float(time),
                    message=str(example.get("message") or example.get("conjunct") or key),
                )
            )
    return tuple(found)


def play_marks(document: Mapping[str, Any]) -> tuple[tuple[PlayMark, ...], tuple[Point, ...]]:
    """The marks and the route of a ``counterstrategy.json`` play: one mark per place, its
    text the steps spent there with the sensors on at each (``2 alarm``), in step order."""
    texts: dict[Point, list[str]] = {}
    route: list[Point] = []
    steps = list(document.get("play", []))
    for entry in steps:
        x, y = entry["position"]
        here = (float(x), float(y))
        on = [name for name, value in sorted(entry["sensors"].items()) if value]
        texts.setdefault(here, []).append(" ".join([str(entry["step"]), *on]))
        if not route or route[-1] != here:
            route.append(here)
    again = document.get("again_from")
    if again is not None and steps:
        x, y = steps[min(int(again), len(steps) - 1)]["position"]
        if route[-1] != (float(x), float(y)):
            route.append((float(x), float(y)))
    marks = tuple(PlayMark(position=p, text=", ".join(t)) for p, t in texts.items())
    return marks, tuple(route)


def build_scene(
    artifacts: Mapping[str, Any],
    *,
    zoom: tuple[float, float, float, float] | None = None,
    log: Sequence[Sequence[float]] | None = None,
    verdict: Mapping[str, Any] | None = None,
) -> Scene:
    """The scene of a compile output's ``artifacts`` (file name -> JSON document).

    ``zoom`` restricts the view to ``(x0, y0, x1, y1)``; ``log`` adds recorded ``[t, x, y]``
    samples drawn over the map, and ``verdict`` (a ``tlmpc.verdict/1`` document) marks its
    violations.
    """
    mission = artifacts["mission.json"]
    workspace = mission["workspace"]
    boundary = _polygon(workspace["boundary"])
    holes = tuple(_polygon(h) for h in workspace.get("holes", []))
    components = tuple(_polygon(c["boundary"]) for c in workspace.get("components", []))
    component_holes = tuple(
        _polygon(h) for c in workspace.get("components", []) for h in c.get("holes", [])
    )
    if zoom is not None:
        view = zoom
    else:
        bx0, by0, bx1, by1 = _bbox(tuple(p for ring in (boundary, *components) for p in ring))
        margin = 0.01 * max(bx1 - bx0, by1 - by0)
        view = (bx0 - margin, by0 - margin, bx1 + margin, by1 + margin)

    named = _task_propositions(mission)
    many = len(mission["regions"]) > MAX_REGION_NAMES
    ordered = sorted(mission["regions"].items())
    polygons, in_view, flat = _region_polygons([points for _, points in ordered], view)
    regions = []
    for index, ((name, _), polygon) in enumerate(zip(ordered, polygons, strict=True)):
        if not in_view[index]:
            continue  # not drawn; its colour still counts (colours follow the sorted names)
        labelled = not many or name in named
        regions.append(
            Region(
                name=name,
                polygon=polygon,
                colour=REGION_COLOURS[index % len(REGION_COLOURS)],
                named_by_task=name in named,
                labelled=labelled,
                label_at=label_point(polygon) if labelled else polygon[0],
            )
        )
    visible_regions = tuple(regions)
    # Every region drawn: the converted points are the drawn ones, in order.
    region_points = flat if len(visible_regions) == len(ordered) else None
    regions_omitted = 0
    if len(visible_regions) > MAX_DRAWN_REGIONS:
        regions_omitted = sum(1 for r in visible_regions if not r.named_by_task)
        visible_regions = tuple(r for r in visible_regions if r.named_by_task)
        region_points = None

    abstraction = artifacts.get("abstraction.json")
    if abstraction is not None:
        mesh_edges, omitted = _mesh(abstraction, view, view_is_whole_map=zoom is None)
    else:
        import numpy as np

        mesh_edges, omitted = np.zeros((0, 4)), 0

    prefix: tuple[Point, ...] = ()
    cycle: tuple[Point, ...] = ()
    stays = False
    witness = artifacts.get("witness.json")
    if witness is not None and abstraction is not None:
        prefix_ids = list(witness["prefix"])
        cycle_ids = list(witness["cycle"])
        prefix = _centroids(abstraction, [*prefix_ids, *cycle_ids[:1]]) if prefix_ids else ()
        stays = len(cycle_ids) <= 1
        cycle = _centroids(abstraction, [*cycle_ids, *cycle_ids[:1]]) if cycle_ids else ()

    trace = artifacts.get("trace.json")
    trajectory = arc_length_path(trace["points"]) if trace is not None else None
    start_value = mission.get("robot", {}).get("start")
    start = (float(start_value[0]), float(start_value[1])) if start_value else None
    counter = artifacts.get("counterstrategy.json")
    marks, route = play_marks(counter) if counter is not None else ((), ())
    title = str(mission.get("name") or "tlmpc plan")
    if counter is not None:
        title += ": unrealizable, how the environment wins"
    return Scene(
        title=title,
        view=view,
        boundary=boundary,
        holes=holes,
        regions=visible_regions,
        emphasise_task_regions=many,
        mesh_edges=mesh_edges,
        mesh_omitted=omitted,
        regions_omitted=regions_omitted,
        plan_prefix=prefix,
        plan_cycle=cycle,
        plan_stays=stays,
        trajectory=trajectory,
        log=arc_length_path(log) if log is not None else None,
        start=start,
        violations=_violations(verdict),
        components=components,
        component_holes=component_holes,
        region_points=region_points,
        play=marks,
        play_route=route,
    )
