"""The faster paths written for hostile sizes give exactly what the slow, obvious ones give.

* Cells unioned one edge-connected piece at a time equal shapely's union of every cell square.
* Waypoints YAML written line by line equals PyYAML's ``safe_dump`` of the same document.
* The YAML limit counts a document's values with aliases expanded, as a full expansion does.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
import shapely
import yaml
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from tlmpc.base.errors import UsageError
from tlmpc.exports.formats import waypoints_yaml
from tlmpc.exports.plan import Plan, Waypoint
from tlmpc.importers.polygonize import cells_to_geometry
from tlmpc.io.inputs import load_small_yaml


@given(arrays(np.bool_, st.tuples(st.integers(1, 12), st.integers(1, 12))))
def test_pieces_unioned_apart_equal_one_union_of_all_cells(mask: np.ndarray) -> None:
    squares = [shapely.box(c, r, c + 1, r + 1) for r, c in zip(*np.nonzero(mask), strict=True)]
    expected = shapely.union_all(squares)
    found = cells_to_geometry(mask)
    assert found.is_valid
    assert shapely.equals(found, expected) or (found.is_empty and expected.is_empty)
    # and the pieces are the edge-connected ones: no two share more than points
    parts = list(getattr(found, "geoms", [found]))
    for i, a in enumerate(parts):
        for b in parts[i + 1 :]:
            assert a.intersection(b).area == 0.0
            assert a.boundary.intersection(b.boundary).length == 0.0


finite = st.floats(allow_nan=False, allow_infinity=False, width=64)
names = st.text(max_size=12)


@given(
    points=st.lists(st.tuples(finite, finite, finite, finite), max_size=6),
    name=names,
    frame=names,
    loop=st.one_of(st.none(), st.integers(0, 5)),
)
def test_waypoints_yaml_is_pyyamls_text(
    points: list[tuple[float, float, float, float]], name: str, frame: str, loop: int | None
) -> None:
    plan = Plan(
        samples=np.zeros((1, 3)),
        loop_start=None,
        name=name,
        boundary=((0.0, 0.0), (1.0, 0.0), (0.0, 1.0)),
        holes=(),
        regions={},
        formula="G F a",
    )
    waypoints = [Waypoint(t=t, x=x, y=y, yaw=yaw) for t, x, y, yaw in points]
    document: dict[str, Any] = {
        "format": "tlmpc.waypoints/1",
        "mission": name,
        "task": "G F a",
        "frame_id": frame,
        "loop_start": loop,
        "waypoints": [
            {
                "t": w.t,
                "x": w.x,
                "y": w.y,
                "yaw": w.yaw,
                "orientation": {
                    "x": 0.0,
                    "y": 0.0,
                    "z": math.sin(w.yaw / 2.0),
                    "w": math.cos(w.yaw / 2.0),
                },
            }
            for w in waypoints
        ],
    }
    expected = yaml.safe_dump(document, sort_keys=False, default_flow_style=None)
    assert waypoints_yaml(plan, waypoints, loop, frame) == expected


def _expanded_size(value: Any) -> int:
    """Values in ``value`` counted one by one (what the YAML would be with aliases copied)."""
    if isinstance(value, list):
        return 1 + sum(_expanded_size(v) for v in value)
    if isinstance(value, dict):
        return 1 + sum(1 + _expanded_size(v) for v in value.values())
    return 1


@given(levels=st.integers(1, 6), width=st.integers(1, 6), limit=st.integers(5, 3000))
def test_the_yaml_limit_counts_values_with_aliases_expanded(
    levels: int, width: int, limit: int
) -> None:
    lines = ["a0: &a0 [" + ", ".join(["1"] * width) + "]"]
    for level in range(1, levels):
        lines.append(f"a{level}: &a{level} [" + ", ".join([f"*a{level - 1}"] * width) + "]")
    text = "\n".join(lines) + "\n"
    size = _expanded_size(yaml.safe_load(text))
    if size <= limit:
        assert load_small_yaml(text, "f.yaml", code="M002", max_values=limit) is not None
    else:
        with pytest.raises(UsageError):
            load_small_yaml(text, "f.yaml", code="M002", max_values=limit)
