"""Read ROS map_server / nav2 occupancy-grid maps (``map.yaml`` + image) into cell values.

The conversion follows nav2's ``map_io`` exactly: a pixel's *shade* is the mean of its colour
channels divided by the channel maximum (255, or 65535 for a 16-bit image; in ``trinary`` mode
an alpha channel is averaged in with the three colour channels); ``occ = shade`` when
``negate`` else ``1 - shade``;

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
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from tlmpc.base.errors import UsageError, error
from tlmpc.importers.map_keys import KEY_EXAMPLES, MAX_MAP_YAML_BYTES
from tlmpc.io.inputs import brief, load_small_yaml, open_regular, read_text
from tlmpc.io.outputs import yaml_float

MODES = ("trinary", "scale", "raw")
UNKNOWN = -1
FREE = 0
OCCUPIED = 100

#: Maps larger than this many cells are refused (a 16k x 16k grid is already 1 GB of floats).
MAX_CELLS = 64_000_000

#: The largest image file read (a 64-million-cell 16-bit PGM is 128 MB).
MAX_IMAGE_BYTES = 512 * 1024 * 1024

#: The smallest and largest cell size accepted: beyond these a cell's square, its area or
#: the map's extent leaves the range of floating point (1e-300 squared is 0).
MIN_RESOLUTION = 1e-9
MAX_RESOLUTION = 1e9

#: Origins farther out than this put the map beyond where a float resolves a cell.
MAX_COORDINATE = 1e12

#: The hint of a diagnostic about either threshold.
_THRESHOLDS_HINT = (
    "free_thresh and occupied_thresh are occupancies from 0 to 1: a cell is free below "
    "free_thresh and occupied above occupied_thresh, so free_thresh <= occupied_thresh "
    "(nav2's map_saver writes free_thresh: 0.25, occupied_thresh: 0.65)"
)


@dataclass(frozen=True, slots=True, kw_only=True)
class OccupancyGrid:
    """An occupancy grid: values -1 (unknown), 0..100 (occupancy percent), y axis up."""

    values: npt.NDArray[np.int16] = field(compare=False)
    resolution: float
    origin: tuple[float, float, float]
    mode: str
    source: str
    #: the image file the cells were read from
    image: str = ""
    #: where each key's value is written in the map YAML: (line, column), 1-based
    places: Mapping[str, tuple[int, int]] = field(default_factory=dict, compare=False)

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


def _fail(
    code: str,
    message: str,
    file: str,
    hint: str | None = None,
    at: tuple[int, int] | None = None,
) -> UsageError:
    line, col = at if at is not None else (None, None)
    return UsageError(error(code, message, hint=hint, file=file, line=line, col=col))


@dataclass(frozen=True, slots=True)
class _Written:
    """Where a key's value is written in the map YAML, and whether it is a quoted scalar."""

    line: int
    col: int
    quoted: bool


#: What each key of a map YAML holds, as the hint of a diagnostic about its value.
_KEY_HINTS = {
    "image": "image is the map image's file name, relative to this YAML file, e.g. map.pgm",
    "resolution": "resolution is the size of one cell in metres, e.g. 0.05",
    "origin": "origin is the pose of the map's lower-left corner, [x, y, yaw] in metres and "
    "radians, e.g. [-10.0, -10.0, 0.0]",
    "occupied_thresh": _THRESHOLDS_HINT,
    "free_thresh": _THRESHOLDS_HINT,
    "negate": "negate: 0 when white pixels are free (as map_saver writes), 1 when black ones are",
    "mode": "use trinary, scale or raw",
}


@dataclass(frozen=True, slots=True)
class _MapText:
    """Where the map YAML writes its mapping and each top-level key's value."""

    values: Mapping[str, _Written]
    #: where the mapping starts: the place of a diagnostic about a key it lacks
    mapping: tuple[int, int]

    def at(self, key: str) -> tuple[int, int]:
        """Where ``key``'s value is written, else where the mapping starts."""
        place = self.values.get(key)
        return self.mapping if place is None else (place.line, place.col)


def _written(text: str) -> _MapText:
    """Each top-level key's value as written (the last of a repeated key, as the data has it).

    Only called on text that ``load_small_yaml`` read, so it is small and within the limits."""
    import yaml

    try:
        root = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.YAMLError:  # pragma: no cover - the text was just read as YAML
        return _MapText({}, (1, 1))
    if root is None:  # an empty document
        return _MapText({}, (1, 1))
    found: dict[str, _Written] = {}
    if isinstance(root, yaml.MappingNode):
        for key, value in root.value:
            if isinstance(key, yaml.ScalarNode):
                mark = value.start_mark
                quoted = isinstance(value, yaml.ScalarNode) and value.style in ("'", '"')
                found[key.value] = _Written(mark.line + 1, mark.column + 1, quoted)
    return _MapText(found, (root.start_mark.line + 1, root.start_mark.column + 1))


def _missing(key: str, file: str, written: _MapText) -> UsageError:
    """M003: the map lacks ``key`` (or gives it no value), at the mapping (or the empty value)."""
    return _fail(
        "M003",
        f"the map has no `{key}`",
        file,
        hint="a map_server map needs image, resolution, origin, occupied_thresh and "
        f"free_thresh: add `{key}: {KEY_EXAMPLES[key]}`",
        at=written.at(key),
    )


def _number(meta: dict[str, Any], key: str, file: str, written: _MapText) -> float:
    value = meta.get(key)
    if value is None:
        raise _missing(key, file, written)
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        place = written.values.get(key)
        hint = _KEY_HINTS[key]
        finite = isinstance(value, str) and _finite_text(value)
        if finite and place is not None and place.quoted:
            hint = (
                "the value is in quotes, so YAML reads it as text: write the number without "
                f"quotes, {key}: {yaml_float(float(value))}"
            )
        elif finite:
            hint = (
                "YAML 1.1 reads this as text: write it with a decimal point and a signed "
                "exponent, e.g. 1.0e-3"
            )
        raise _fail(
            "M004",
            f"`{key}` is not a finite number: {brief(value)}",
            file,
            hint=hint,
            at=written.at(key),
        )
    return float(value)


def _finite_text(text: str) -> bool:
    """Whether ``text`` reads as a finite number."""
    try:
        return math.isfinite(float(text))
    except ValueError:
        return False


def read_metadata(path: Path) -> dict[str, Any]:
    """The map YAML, checked: resolution > 0, 0 <= free <= occupied <= 1, a known mode."""
    file = str(path)
    text = read_text(path, limit=MAX_MAP_YAML_BYTES, code="M001", what="map")
    meta = load_small_yaml(text, file, code="M002")
    written = _written(text)
    if not isinstance(meta, dict):
        raise _fail(
            "M002",
            "the map file is not a map_server YAML mapping",
            file,
            hint="expected keys image, resolution, origin, occupied_thresh, free_thresh",
            at=written.mapping,
        )

    def bad(key: str, message: str) -> UsageError:
        """M004 at ``key``'s value, with what the key holds as the hint."""
        return _fail("M004", message, file, hint=_KEY_HINTS[key], at=written.at(key))

    image = meta.get("image")
    if image is None:
        raise _missing("image", file, written)
    if not isinstance(image, str) or not image:
        raise bad("image", f"`image` must be the image's file name, got {brief(image)}")
    resolution = _number(meta, "resolution", file, written)
    if not MIN_RESOLUTION <= resolution <= MAX_RESOLUTION:
        raise bad(
            "resolution",
            f"`resolution` must be between {MIN_RESOLUTION:g} and {MAX_RESOLUTION:g} "
            f"(metres per cell), got {resolution:g}",
        )
    origin = meta.get("origin")
    if origin is None:
        raise _missing("origin", file, written)
    if (
        not isinstance(origin, list)
        or len(origin) != 3
        or not all(
            isinstance(v, int | float)
            and not isinstance(v, bool)
            and math.isfinite(v)
            and abs(v) <= MAX_COORDINATE
            for v in origin
        )
    ):
        raise bad(
            "origin",
            f"`origin` must be [x, y, yaw] of finite numbers (at most {MAX_COORDINATE:g} "
            f"in size), got {brief(origin)}",
        )
    occupied = _number(meta, "occupied_thresh", file, written)
    free = _number(meta, "free_thresh", file, written)
    negate = meta.get("negate", 0)
    if negate not in (0, 1, True, False):
        raise bad("negate", f"`negate` must be 0 or 1, got {brief(negate)}")
    if not 0.0 <= free <= occupied <= 1.0:
        # the value outside 0..1; when both lie inside it (in the wrong order), free_thresh
        outside = [
            key
            for key, v in (("free_thresh", free), ("occupied_thresh", occupied))
            if not 0.0 <= v <= 1.0
        ]
        culprit = outside[0] if outside else "free_thresh"
        raise bad(
            culprit,
            f"thresholds must satisfy 0 <= free_thresh <= occupied_thresh <= 1, "
            f"got free {free:g}, occupied {occupied:g}",
        )
    mode = meta.get("mode", "trinary")
    if mode not in MODES:
        raise bad("mode", f"unknown map mode {brief(mode)}")
    return {
        "image": image,
        "resolution": resolution,
        "origin": (float(origin[0]), float(origin[1]), float(origin[2])),
        "occupied_thresh": occupied,
        "free_thresh": free,
        "negate": bool(negate),
        "mode": mode,
        "places": {key: (place.line, place.col) for key, place in written.values.items()},
    }


def _pixels(
    path: Path, file: str, at: tuple[int, int] | None = None
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64] | None]:
    """Shade in [0, 1] per pixel (mean of colour channels) and, if the image has an alpha
    channel, its alpha in [0, 1] per pixel (1: opaque).

    Problems are reported in the map YAML ``file``, at ``at`` (where it names the image)."""
    import warnings

    from tlmpc.base.extras import require

    def fail(code: str, message: str, hint: str) -> UsageError:
        return _fail(code, message, file, hint=hint, at=at)

    try:
        Image = require("PIL.Image", "reading a map image")
    except UsageError as exc:  # placed where the map YAML names the image
        raise fail("U060", exc.diagnostics[0].message, exc.diagnostics[0].hint or "") from None
    from PIL import UnidentifiedImageError

    if not path.exists():
        raise fail(
            "M005",
            f"the map image {path} does not exist",
            hint="`image` is relative to the map YAML file",
        )
    try:
        with (
            open_regular(path, code="M006", what="map image") as stream,
            warnings.catch_warnings(),
        ):
            # The size is checked from the header, before any pixel is decoded; Pillow's own
            # "decompression bomb" check (a warning, then an error) is ours to report.
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            if os.fstat(stream.fileno()).st_size > MAX_IMAGE_BYTES:
                raise fail(
                    "M006",
                    f"the map image {path} is larger than {MAX_IMAGE_BYTES >> 20} MiB",
                    hint="crop or downsample the map",
                )
            with Image.open(stream) as image:
                if image.width * image.height > MAX_CELLS:
                    raise fail(
                        "M006",
                        f"the map image {path} is {image.width}x{image.height} pixels, more "
                        f"than {MAX_CELLS:,} cells",
                        hint="crop or downsample the map",
                    )
                mode = image.mode
                array = np.asarray(image)
    except UsageError as exc:
        # open_regular's refusal names the image; it is reported in the map YAML, at `image`
        line, col = at if at is not None else (None, None)
        raise UsageError(
            [
                error(d.code, d.message, hint=d.hint, file=file, line=line, col=col)
                for d in exc.diagnostics
            ]
        ) from None
    except Image.DecompressionBombError:
        raise fail(
            "M006",
            f"the map image {path} declares more than {MAX_CELLS:,} cells",
            hint="crop or downsample the map",
        ) from None
    except UnidentifiedImageError:
        # Pillow's message names the open stream object, which tells the reader nothing.
        raise fail(
            "M006",
            f"cannot read the map image {path}: it is not in an image format Pillow knows, "
            "or its header is malformed (a negative or missing size, say)",
            hint=_IMAGE_HINT,
        ) from None
    except MemoryError:
        raise fail(
            "M006",
            f"cannot read the map image {path}: not enough memory to decode it",
            hint="crop or downsample the map",
        ) from None
    except (OSError, ValueError, SyntaxError) as exc:
        raise fail(
            "M006", f"cannot read the map image {path}: {_reason(exc)}", hint=_IMAGE_HINT
        ) from None
    if mode == "1":
        return array.astype(np.float64), None
    if mode in ("I;16", "I;16B", "I;16L", "I"):
        # 16-bit greyscale (Pillow reads a 16-bit PGM as "I", its values rescaled to 0..65535
        # whatever the file's maxval): the channel maximum is 65535, as for map_server. Not
        # the image's own brightest pixel: a map whose lightest cells are unknown grey would
        # turn them free.
        if array.size and (int(array.min()) < 0 or int(array.max()) > 65535):
            raise fail(
                "M006",
                f"the map image {path} has pixel values beyond 16 bits "
                f"({int(array.min())} to {int(array.max())})",
                hint=_IMAGE_HINT,
            )
        return array.astype(np.float64) / 65535.0, None
    if mode == "P":
        raise fail("M006", "palette images are not supported", hint="save as greyscale")
    top = 255.0
    alpha: npt.NDArray[np.float64] | None = None
    if array.ndim == 3:
        if mode in ("LA", "RGBA", "La", "RGBa"):
            alpha = array[..., -1].astype(np.float64) / top
            array = array[..., :-1]
        shade = array.astype(np.float64).mean(axis=2) / top
    else:
        shade = array.astype(np.float64) / top
    return shade, alpha


_IMAGE_HINT = (
    "a map image is a greyscale (or RGB) PGM, PNG or BMP file as map_saver writes it; "
    "open it in an image viewer and save it again as an 8-bit greyscale PGM or PNG"
)
#: An object's repr inside a decoder's message (``<_io.BufferedReader name=3>``).
_OBJECT_REPR = re.compile(r"\s*<[^<>]*>")


def _reason(exc: BaseException) -> str:
    """A decoder's whole message, on one line, without object reprs."""
    text = " ".join(_OBJECT_REPR.sub("", str(exc)).split())
    return text or f"the decoder failed ({type(exc).__name__})"


def cell_values(
    shade: npt.NDArray[np.float64],
    alpha: npt.NDArray[np.float64] | None,
    *,
    mode: str,
    negate: bool,
    occupied_thresh: float,
    free_thresh: float,
) -> npt.NDArray[np.int16]:
    """nav2's pixel → cell conversion (image rows, not yet flipped) of the colour channels'
    ``shade`` and, for an image with an alpha channel, its ``alpha`` (1: opaque).

    As in nav2's ``map_io``, ``trinary`` averages the alpha in with the three colour channels
    (a grey channel counts as all three): a transparent pixel is darker, so a white one is
    not free; ``scale`` makes every pixel that is not fully opaque unknown; ``raw`` ignores
    the alpha."""
    if alpha is not None and mode == "trinary":
        shade = (3.0 * shade + alpha) / 4.0
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
        if alpha is not None:
            values[alpha < 1.0] = UNKNOWN
    return values


def read_map(path: Path) -> OccupancyGrid:
    """Read a map_server map; raise :class:`UsageError` (M001–M006) on bad input."""
    meta = read_metadata(path)
    image_path = Path(meta["image"])
    if not image_path.is_absolute():
        image_path = path.parent / image_path
    named = meta["places"].get("image")
    shade, alpha = _pixels(image_path, str(path), named)
    if shade.ndim != 2 or shade.size == 0:
        raise _fail(
            "M006", f"the map image {image_path} has no pixels", str(path), _IMAGE_HINT, named
        )
    values = cell_values(
        shade,
        alpha,
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
        image=str(image_path),
        places=meta["places"],
    )
