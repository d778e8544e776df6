"""Map coordinates (metres) to WGS 84 longitude and latitude, for GeoJSON (RFC 7946).

A mission's coordinates are metres in a local frame (``map``).  Given where that frame's
origin lies on the Earth (latitude, longitude, height 0 on the WGS 84 ellipsoid) and the
angle from east to its x axis (counter-clockwise, degrees), the map's plane is the
ellipsoid's tangent plane at the origin, and a point goes onto the ellipsoid along its normal:
local east/north -> Earth-centred (ECEF) by the rotation of the tangent plane, then ECEF ->
geodetic latitude and longitude by Bowring's iteration (converged to far below a millimetre).
No flat-Earth approximation, so maps kilometres wide stay exact.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

#: WGS 84: semi-major axis (m) and flattening.
A = 6378137.0
F = 1.0 / 298.257223563
E2 = F * (2.0 - F)  # first eccentricity squared


@dataclass(frozen=True, slots=True)
class Georeference:
    """Where the map frame's origin is and how its x axis is turned from east."""

    latitude: float  # degrees
    longitude: float  # degrees
    yaw: float = 0.0  # degrees, counter-clockwise from east to the map's x axis


def geodetic_to_ecef(latitude: float, longitude: float, height: float = 0.0) -> tuple[float, ...]:
    """Earth-centred, Earth-fixed coordinates (m) of a geodetic point (degrees, m)."""
    phi, lam = math.radians(latitude), math.radians(longitude)
    n = A / math.sqrt(1.0 - E2 * math.sin(phi) ** 2)
    return (
        (n + height) * math.cos(phi) * math.cos(lam),
        (n + height) * math.cos(phi) * math.sin(lam),
        (n * (1.0 - E2) + height) * math.sin(phi),
    )


def ecef_to_geodetic(x: float, y: float, z: float) -> tuple[float, float, float]:
    """Latitude, longitude (degrees) and height (m) of an ECEF point."""
    lam = math.atan2(y, x)
    p = math.hypot(x, y)
    phi = math.atan2(z, p * (1.0 - E2))
    for _ in range(10):
        n = A / math.sqrt(1.0 - E2 * math.sin(phi) ** 2)
        height = p / math.cos(phi) - n
        updated = math.atan2(z, p * (1.0 - E2 * n / (n + height)))
        if abs(updated - phi) < 1e-15:
            phi = updated
            break
        phi = updated
    n = A / math.sqrt(1.0 - E2 * math.sin(phi) ** 2)
    return math.degrees(phi), math.degrees(lam), p / math.cos(phi) - n


def to_lon_lat(reference: Georeference, x: float, y: float) -> tuple[float, float]:
    """``[longitude, latitude]`` (RFC 7946 order, degrees) of the map point ``(x, y)``."""
    turn = math.radians(reference.yaw)
    east = x * math.cos(turn) - y * math.sin(turn)
    north = x * math.sin(turn) + y * math.cos(turn)
    phi, lam = math.radians(reference.latitude), math.radians(reference.longitude)
    x0, y0, z0 = geodetic_to_ecef(reference.latitude, reference.longitude)
    # the local tangent plane's east and north unit vectors in ECEF
    ex, ey, ez = -math.sin(lam), math.cos(lam), 0.0
    nx = -math.sin(phi) * math.cos(lam)
    ny = -math.sin(phi) * math.sin(lam)
    nz = math.cos(phi)
    latitude, longitude, _ = ecef_to_geodetic(
        x0 + east * ex + north * nx, y0 + east * ey + north * ny, z0 + east * ez + north * nz
    )
    return longitude, latitude


#: How far a written segment may lie from the map's straight edge it stands for, in metres on
#: the ellipsoid.  GeoJSON draws a segment straight in longitude and latitude (RFC 7946
#: §3.1.1), where a map's straight edge is curved: 3.4 m off over 10 km at latitude 60.
EDGE_TOLERANCE = 1e-3
#: Halvings of one map edge at most: a segment through a pole never straightens.
_MAX_HALVINGS = 24
#: Points the subdivision may add to one export (a map Earth-sized, not a robot's).
MAX_ADDED_POINTS = 1_000_000


@dataclass
class Subdivision:
    """Polylines of the map in longitude and latitude, points added along each edge until
    every written segment lies within :data:`EDGE_TOLERANCE` of the map's own edge.

    A longitude is unwrapped to within 180 degrees of the origin's, so a geometry stays
    connected where the map crosses the antimeridian (it is cut there afterwards).  The
    points added to all polylines of one export are counted against
    :data:`MAX_ADDED_POINTS` (M087 beyond)."""

    reference: Georeference
    added: int = field(default=0, init=False)

    def lon_lat(self, x: float, y: float) -> tuple[float, float]:
        """The map point's longitude (unwrapped) and latitude."""
        longitude, latitude = to_lon_lat(self.reference, x, y)
        origin = self.reference.longitude
        return origin + math.remainder(longitude - origin, 360.0), latitude

    def path(
        self, points: Sequence[Sequence[float]]
    ) -> tuple[list[tuple[float, float]], list[float]]:
        """The polyline through ``points`` (map x, y) in longitude and latitude, with the
        points added, and where each written point lies along the input: its index, plus the
        fraction of the edge after it for an added point."""
        mapped = [self.lon_lat(float(p[0]), float(p[1])) for p in points]
        if not mapped:
            return [], []
        out, at = [mapped[0]], [0.0]
        for index in range(1, len(points)):
            start, end = points[index - 1], points[index]
            self._fill(start, end, mapped[index - 1], mapped[index], 0.0, 1.0, index - 1, out, at)
            out.append(mapped[index])
            at.append(float(index))
        return out, at

    def _fill(
        self,
        start: Sequence[float],
        end: Sequence[float],
        first: tuple[float, float],
        last: tuple[float, float],
        low: float,
        high: float,
        index: int,
        out: list[tuple[float, float]],
        at: list[float],
        depth: int = 0,
    ) -> None:
        """Append the points strictly between ``first`` and ``last`` (the edge's fractions
        ``low`` and ``high``) that keep each written segment within the tolerance."""
        middle = (low + high) / 2.0
        x = start[0] + middle * (end[0] - start[0])
        y = start[1] + middle * (end[1] - start[1])
        point = self.lon_lat(x, y)
        chord = ((first[0] + last[0]) / 2.0, (first[1] + last[1]) / 2.0)
        if depth >= _MAX_HALVINGS or _apart(point, chord) <= EDGE_TOLERANCE:
            return
        self.added += 1
        if self.added > MAX_ADDED_POINTS:
            from tlmpc.base.errors import UsageError, error

            raise UsageError(
                error(
                    "M087",
                    f"placing this map on the Earth within {EDGE_TOLERANCE * 1000:g} mm "
                    f"takes more than {MAX_ADDED_POINTS:,} added points",
                    hint="its edges are too long for longitude and latitude: export without "
                    "--georeference (map metres), or georeference a smaller map",
                    file="--georeference",
                )
            )
        self._fill(start, end, first, point, low, middle, index, out, at, depth + 1)
        out.append(point)
        at.append(index + middle)
        self._fill(start, end, point, last, middle, high, index, out, at, depth + 1)


def _apart(a: tuple[float, float], b: tuple[float, float]) -> float:
    """The straight distance (m) between two points of the ellipsoid (longitude, latitude)."""
    pa = geodetic_to_ecef(a[1], a[0])
    pb = geodetic_to_ecef(b[1], b[0])
    return math.dist(pa, pb)


def encircles_pole(ring: Sequence[tuple[float, float]]) -> bool:
    """Whether a closed ring (longitude, latitude) goes once around a pole: its longitude,
    followed step by step, turns by a whole circle."""
    turn = sum(math.remainder(b[0] - a[0], 360.0) for a, b in itertools.pairwise(ring))
    return abs(turn) > 180.0


def parse_georeference(text: str) -> Georeference:
    """``LAT,LON[,YAW]`` (degrees) -> a :class:`Georeference` (argparse type)."""
    import argparse

    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected LAT,LON[,YAW] in degrees, got {text!r}"
        ) from None
    if len(values) not in (2, 3) or not all(math.isfinite(v) for v in values):
        raise argparse.ArgumentTypeError(f"expected LAT,LON[,YAW] in degrees, got {text!r}")
    if not -90.0 < values[0] < 90.0 or not -180.0 <= values[1] <= 180.0:
        raise argparse.ArgumentTypeError(
            f"latitude must be in (-90, 90) and longitude in [-180, 180], got {text!r}"
        )
    return Georeference(*values)
