"""Read ROS map_server / nav2 occupancy-grid maps (``map.yaml`` + image) into cell values.

The conversion follows nav2's ``map_io`` exactly: a pixel's *shade* is the mean of its colour
channels divided by the channel maximum; ``occ = shade`` when ``negate`` else ``1 - shade``;

* ``trinary`` (default): ``occ > occupied_thresh`` → 100, ``occ < free_thresh`` → 0, else -1;
* ``scale``: a transparent pixel → -1; ``occ > occupied_thresh`` → 100;
  ``occ < free_thresh`` → 0; else ``rint(100 * (occ - free) / (occupied - free))``;
* ``raw``: ``round(255 * shade)`` when in 0..100, else -1.

Row 0 of the image is the *top* of the map: :attr:`OccupancyGrid.values` is flipped so that
row ``i`` is the cells whose lower edge lies ``i * resolution`` above the origin.  The origin
``[x, y, yaw]`` places cell (0, 0)'s lower-left corner and rotates the grid about it.

Pillow is imported only here, and only when a map is read.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import yaml

from tlmpc.base.errors import UsageError, error

MODES = ("trinary", "scale", "raw")
UNKNOWN = -1
FREE = 0
OCCUPIED = 100

#: Maps larger than this many cells are refused (a 16k x 16k grid is already 1 GB of floats).
MAX_CELLS = 64_000_000


@dataclass(frozen=True, slots=True, kw_only=True)
class OccupancyGrid:
    """An occupancy grid: values -1 (unknown), 0..100 (occupancy percent), y axis up."""

    values: npt.NDArray[np.int16] = field(compare=False)
    resolution: float
    origin: tuple[float, float, float]
    mode: str
    source: str

    @property
    def shape(self) -> tuple[int, int]:
        """(rows, columns)."""
        rows, cols = self.values.shape
        return int(rows), int(cols)

    def cell_area(self) -> float:
        """Area of one cell in square metres (map units)."""
        return self.resolution * self.resolution

    def to_world(self, x: float, y: float) -> tuple[float, float]:
        """Grid coordinates (in cells, y up) to world coordinates."""
        ox, oy, yaw = self.origin
        gx, gy = x * self.resolution, y * self.resolution
        c, s = math.cos(yaw), math.sin(yaw)
        return ox + c * gx - s * gy, oy + s * gx + c * gy


def _fail(code: str, message: str, file: str, hint: str | None = None) -> UsageError:
    return UsageError(error(code, message, hint=hint, file=file))


def _number(meta: dict[str, Any], key: str, file: str, default: float | None = None) -> float:
    value = meta.get(key, default)
    if value is None:
        raise _fail(
            "M003",
            f"the map has no `{key}`",
            file,
            hint="a map_server map needs image, resolution, origin, occupied_thresh, free_thresh",
        )
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise _fail("M004", f"`{key}` is not a number: {value!r}", file)
    return float(value)


def read_metadata(path: Path) -> dict[str, Any]:
    """The map YAML, checked: resolution > 0, 0 <= free <= occupied <= 1, a known mode."""
    file = str(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise _fail("M001", f"cannot read map {file}: {exc}", file, hint="check the path") from None
    try:
        meta = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise _fail("M002", f"the map file is not YAML: {exc}", file) from None
    if not isinstance(meta, dict):
        raise _fail(
            "M002",
            "the map file is not a map_server YAML mapping",
            file,
            hint="expected keys image, resolution, origin, occupied_thresh, free_thresh",
        )
    image = meta.get("image")
    if not isinstance(image, str) or not image:
        raise _fail("M003", "the map has no `image`", file, hint="image: map.pgm")
    resolution = _number(meta, "resolution", file)
    if resolution <= 0:
        raise _fail("M004", f"`resolution` must be positive, got {resolution:g}", file)
    origin = meta.get("origin")
    if (
        not isinstance(origin, list)
        or len(origin) != 3
        or not all(
            isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
            for v in origin
        )
    ):
        raise _fail("M004", f"`origin` must be [x, y, yaw], got {origin!r}", file)
    occupied = _number(meta, "occupied_thresh", file)
    free = _number(meta, "free_thresh", file)
    negate = meta.get("negate", 0)
    if negate not in (0, 1, True, False):
        raise _fail("M004", f"`negate` must be 0 or 1, got {negate!r}", file)
    if not 0.0 <= free <= occupied <= 1.0:
        raise _fail(
            "M004",
            f"thresholds must satisfy 0 <= free_thresh <= occupied_thresh <= 1, "
            f"got free {free:g}, occupied {occupied:g}",
            file,
        )
    mode = meta.get("mode", "trinary")
    if mode not in MODES:
        raise _fail("M004", f"unknown map mode {mode!r}", file, hint="use trinary, scale or raw")
    return {
        "image": image,
        "resolution": resolution,
        "origin": (float(origin[0]), float(origin[1]), float(origin[2])),
        "occupied_thresh": occupied,
        "free_thresh": free,
        "negate": bool(negate),
        "mode": mode,
    }


def _pixels(path: Path, file: str) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.bool_] | None]:
    """Shade in [0, 1] per pixel (mean of colour channels) and, if any, opacity per pixel."""
    from PIL import Image, UnidentifiedImageError

    try:
        with Image.open(path) as image:
            if image.width * image.height > MAX_CELLS:
                raise _fail("M006", f"the map image has more than {MAX_CELLS} cells", file)
            mode = image.mode
            array = np.asarray(image)
    except FileNotFoundError:
        raise _fail(
            "M005",
            f"the map image {path} does not exist",
            file,
            hint="`image` is relative to the map YAML file",
        ) from None
    except (OSError, UnidentifiedImageError, ValueError, SyntaxError) as exc:
        raise _fail("M006", f"cannot read the map image {path}: {exc}", file) from None
    if mode == "1":
        return array.astype(np.float64), None
    if mode in ("I;16", "I;16B", "I;16L", "I"):
        top = 65535.0 if mode != "I" else float(max(int(array.max(initial=0)), 1))
        return array.astype(np.float64) / top, None
    if mode == "P":
        raise _fail("M006", "palette images are not supported", file, hint="save as greyscale")
    top = 255.0
    alpha: npt.NDArray[np.bool_] | None = None
    if array.ndim == 3:
        if mode in ("LA", "RGBA", "La", "RGBa"):
            alpha = array[..., -1] == 255
            array = array[..., :-1]
        shade = array.astype(np.float64).mean(axis=2) / top
    else:
        shade = array.astype(np.float64) / top
    return shade, alpha


def cell_values(
    shade: npt.NDArray[np.float64],
    opaque: npt.NDArray[np.bool_] | None,
    *,
    mode: str,
    negate: bool,
    occupied_thresh: float,
    free_thresh: float,
) -> npt.NDArray[np.int16]:
    """nav2's pixel → cell conversion (image rows, not yet flipped)."""
    occ = shade if negate else 1.0 - shade
    values = np.full(shade.shape, UNKNOWN, dtype=np.int16)
    if mode == "raw":
        percent = np.round(shade * 255.0)
        inside = (percent >= FREE) & (percent <= OCCUPIED)
        values[inside] = percent[inside].astype(np.int16)
        return values
    occupied = occupied_thresh < occ
    free = occ < free_thresh
    values[occupied] = OCCUPIED
    values[free & ~occupied] = FREE
    if mode == "scale":
        between = ~occupied & ~free
        span = occupied_thresh - free_thresh
        if span > 0:
            scaled = np.rint((occ - free_thresh) / span * 100.0)
            values[between] = scaled[between].astype(np.int16)
        if opaque is not None:
            values[~opaque] = UNKNOWN
    return values


def read_map(path: Path) -> OccupancyGrid:
    """Read a map_server map; raise :class:`UsageError` (M001–M006) on bad input."""
    meta = read_metadata(path)
    image_path = Path(meta["image"])
    if not image_path.is_absolute():
        image_path = path.parent / image_path
    shade, opaque = _pixels(image_path, str(path))
    if shade.ndim != 2 or shade.size == 0:
        raise _fail("M006", f"the map image {image_path} has no pixels", str(path))
    values = cell_values(
        shade,
        opaque,
        mode=meta["mode"],
        negate=meta["negate"],
        occupied_thresh=meta["occupied_thresh"],
        free_thresh=meta["free_thresh"],
    )
    return OccupancyGrid(
        values=np.ascontiguousarray(values[::-1]),
        resolution=meta["resolution"],
        origin=meta["origin"],
        mode=meta["mode"],
        source=str(path),
    )
