"""Exact pure-Python geometry for small, plain missions, so that checking them needs no shapely.

Each test here either proves its answer — with floating-point orientation tests guarded by a
forward error bound, so a sign it reports is the sign of the exact determinant — or returns
``None`` ("cannot tell"), and the caller asks shapely.  Whatever these functions answer,
shapely answers the same on the same coordinates (a test compares them on random shapes).
"""

from __future__ import annotations

from collections.abc import Sequence

from tlmpc.mission.model import Polygon

#: Above this many vertices a shape goes to shapely (the simple-polygon test is quadratic).
MAX_VERTICES = 64

#: Relative error bound of the float orientation determinant (Shewchuk's ccwerrboundA).
_ORIENT_ERROR = (3.0 + 16.0 * 2.0**-53) * 2.0**-53


def _orientation(
    a: tuple[float, float], b: tuple[float, float], c: tuple[float, float]
) -> int | None:
    """The exact sign of the turn a → b → c (1 left, -1 right, 0 collinear), or None."""
    left = (b[0] - a[0]) * (c[1] - a[1])
    right = (b[1] - a[1]) * (c[0] - a[0])
    det = left - right
    bound = _ORIENT_ERROR * (abs(left) + abs(right))
    if det > bound:
        return 1
    if det < -bound:
        return -1
    if left == 0.0 and right == 0.0 and _exact_differences(a, b, c):
        return 0
    return None


def _exact_differences(
    a: tuple[float, float], b: tuple[float, float], c: tuple[float, float]
) -> bool:
    """Whether the coordinate differences above were computed without rounding."""
    return all(
        (q - p) + p == q and q - (q - p) == p
        for p, q in ((a[0], b[0]), (a[1], b[1]), (a[0], c[0]), (a[1], c[1]))
    )


def _apart(
    a: tuple[float, float], b: tuple[float, float], c: tuple[float, float], d: tuple[float, float]
) -> bool:
    """True only when the closed segments ab and cd certainly do not meet."""
    if (
        max(a[0], b[0]) < min(c[0], d[0])
        or max(c[0], d[0]) < min(a[0], b[0])
        or max(a[1], b[1]) < min(c[1], d[1])
        or max(c[1], d[1]) < min(a[1], b[1])
    ):
        return True
    for p, q, r, s in ((a, b, c, d), (c, d, a, b)):
        first, second = _orientation(p, q, r), _orientation(p, q, s)
        if first is not None and first == second and first != 0:
            return True  # r and s strictly on one side of the line pq
    return False


def certainly_simple(points: Polygon) -> bool | None:
    """True when the closed ring is certainly a simple polygon (shapely: valid); else None.

    Simple: no two non-neighbouring edges meet, and neighbouring edges meet only at their
    shared vertex (they do not fold back over each other).
    """
    n = len(points)
    if n < 3 or n > MAX_VERTICES:
        return None
    edges = [(points[i], points[(i + 1) % n]) for i in range(n)]
    for i in range(n):
        turn = _orientation(points[i - 1], points[i], points[(i + 1) % n])
        if turn is None:
            return None
        if turn == 0:
            # collinear neighbours are fine when they continue forward, not when they fold back
            a, b, c = points[i - 1], points[i], points[(i + 1) % n]
            if (b[0] - a[0]) * (c[0] - b[0]) + (b[1] - a[1]) * (c[1] - b[1]) <= 0.0:
                return None
    for i in range(n):
        for j in range(i + 2, n):
            if i == 0 and j == n - 1:
                continue  # neighbours through the closing edge
            if not _apart(*edges[i], *edges[j]):
                return None
    return True


def shoelace_area(points: Polygon) -> float:
    """The polygon's signed area (counter-clockwise positive)."""
    total = 0.0
    n = len(points)
    for i in range(n):
        x0, y0 = points[i]
        x1, y1 = points[(i + 1) % n]
        total += x0 * y1 - x1 * y0
    return total / 2.0


def axis_rectangle(points: Polygon) -> tuple[float, float, float, float] | None:
    """(xmin, ymin, xmax, ymax) when the ring is exactly an axis-aligned rectangle."""
    if len(points) != 4:
        return None
    xs = sorted({p[0] for p in points})
    ys = sorted({p[1] for p in points})
    if len(xs) != 2 or len(ys) != 2:
        return None
    corners = {(x, y) for x in xs for y in ys}
    if set(points) != corners:
        return None
    # the ring must go around the rectangle, not across it (a bow tie has the same corners)
    for i in range(4):
        a, b = points[i], points[(i + 1) % 4]
        if a[0] != b[0] and a[1] != b[1]:
            return None
    return xs[0], ys[0], xs[1], ys[1]


def inside_rectangle(
    points: Sequence[tuple[float, float]], rect: tuple[float, float, float, float]
) -> bool:
    """Whether every point lies in the closed rectangle (so their convex hull does too)."""
    x0, y0, x1, y1 = rect
    return all(x0 <= x <= x1 and y0 <= y <= y1 for x, y in points)
