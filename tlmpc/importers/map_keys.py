"""The keys of a ROS map_server map YAML, and whether a YAML file is one, without its image.

Light on purpose (neither numpy nor Pillow): ``tlmpc check`` asks it of every file that is no
valid mission, and :mod:`tlmpc.importers.occupancy` reads the map itself.
"""

from __future__ import annotations

from pathlib import Path

from tlmpc.base.errors import UsageError
from tlmpc.io.inputs import load_small_yaml, read_text

#: A map YAML is a handful of keys; anything larger is not one.
MAX_MAP_YAML_BYTES = 1024 * 1024

#: A value to write for each key every map gives, for the hint of a map that lacks it.
KEY_EXAMPLES = {
    "image": "map.pgm",
    "resolution": "0.05",
    "origin": "[0.0, 0.0, 0.0]",
    "occupied_thresh": "0.65",
    "free_thresh": "0.25",
}

#: The keys every map_server map YAML gives (M003 names the one a map lacks).
REQUIRED_KEYS = tuple(KEY_EXAMPLES)


def looks_like_map(path: Path, *, foreign_keys: frozenset[str] = frozenset()) -> bool:
    """Whether the YAML file at ``path`` is meant as a map_server map: a mapping of at most
    :data:`MAX_MAP_YAML_BYTES` with at least two of :data:`REQUIRED_KEYS` (so a map lacking
    one is still a map, whose reader then says which) and none of ``foreign_keys`` (the keys
    of another kind of document, e.g. a mission's).  A file that cannot be read or parsed
    as YAML is not recognised as a map."""
    try:
        text = read_text(path, limit=MAX_MAP_YAML_BYTES, code="M001", what="map")
        data = load_small_yaml(text, str(path), code="M002")
    except UsageError:
        return False
    if not isinstance(data, dict) or any(key in foreign_keys for key in data):
        return False
    return sum(key in data for key in REQUIRED_KEYS) >= 2
