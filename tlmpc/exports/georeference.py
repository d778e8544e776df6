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

import math
from dataclasses import dataclass

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
