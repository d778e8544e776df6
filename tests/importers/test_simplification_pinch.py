"""The import's simplification never pinches the free space: no passage narrower than half a
cell appears between walls that the exact pixel geometry keeps a cell or more apart.

Oracle: the mission's own narrow-passage search (an independent edge-pair search over the
imported rings) on random grids, and the real warehouse map whose import used to show a
0.000125 m passage (4/1000 of a cell) that the map does not have.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from robot_data import image_from_free, require_shared, write_map

from tlmpc.base.errors import UsageError
from tlmpc.importers.maps import ImportSettings, import_map
from tlmpc.mission.holes import passage_search


@given(st.integers(0, 2**32 - 1), st.floats(0.15, 0.35))
@settings(max_examples=30, deadline=None)
def test_no_passage_narrower_than_half_a_cell(seed: int, density: float) -> None:
    rng = np.random.default_rng(seed)
    free = rng.random((24, 24)) > density
    free[[0, -1], :] = False
    free[:, [0, -1]] = False
    with tempfile.TemporaryDirectory() as folder:
        path = write_map(Path(folder), "m", image_from_free(free), resolution=1.0)
        try:
            imported = import_map(path, ImportSettings(min_area=0.0))
        except UsageError:  # a grid with no usable free space
            return
    narrow, complete = passage_search(imported.boundary, imported.holes, width=0.5)
    assert complete
    assert narrow == [], narrow[:3]


def test_the_warehouse_import_has_only_the_maps_own_passages() -> None:
    maps = require_shared("maps")
    imported = import_map(
        maps / "warehouse.yaml",
        keepout=maps / "warehouse_keepout.yaml",
        speed=maps / "warehouse_speed.yaml",
    )
    cell = imported.resolution
    narrow, _ = passage_search(imported.boundary, imported.holes, width=0.75 * cell)
    assert narrow == [], [(w, a) for w, a, *_ in narrow[:3]]
