"""Start-up imports: what a compile loads, checked in fresh interpreters."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _run(code: str) -> dict[str, object]:
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True
    )
    result: dict[str, object] = json.loads(done.stdout.strip().splitlines()[-1])
    return result


def test_lean_listing_keeps_unused_numpy_submodules_out_and_restores() -> None:
    result = _run(
        """
import json, sys
import numpy
before = (sorted(dir(numpy)), list(numpy.__all__))
from tlmpc.startup import lean_numpy_listing, UNUSED_SUBMODULES
with lean_numpy_listing():
    inside = sorted(dir(numpy)), list(numpy.__all__)
    import scipy.sparse
    from scipy.sparse.csgraph import connected_components
    graph = scipy.sparse.coo_matrix(([1, 1], ([0, 1], [1, 2])), shape=(4, 4))
    count = int(connected_components(graph, directed=False)[0])
loaded = sorted(m for m in sys.modules if m.split(".")[:2] in
    [["numpy", n] for n in UNUSED_SUBMODULES])
after = (sorted(dir(numpy)), list(numpy.__all__))
print(json.dumps({
    "restored": after == before,
    "hidden": sorted(set(before[0]) - set(inside[0])),
    "hidden_all": sorted(set(before[1]) - set(inside[1])),
    "loaded": loaded, "count": count,
}))
"""
    )
    assert result["restored"] is True
    assert result["hidden"] == ["ctypeslib", "f2py", "testing"]
    assert result["hidden_all"] == ["ctypeslib", "f2py", "testing"]
    assert result["loaded"] == []
    assert result["count"] == 2  # scipy works as before: {0,1,2} and {3}


def test_lean_listing_does_nothing_once_scipy_is_loaded() -> None:
    result = _run(
        """
import json
import numpy, scipy.sparse
from tlmpc.startup import lean_numpy_listing
with lean_numpy_listing():
    inside = "f2py" in dir(numpy)
print(json.dumps({"inside": inside}))
"""
    )
    assert result["inside"] is True


def test_the_abstraction_stage_imports_no_scipy() -> None:
    result = _run(
        f"""
import json, sys
from tlmpc.mission import load_mission
from tlmpc.abstraction import build_abstraction
mission = load_mission({str(ROOT / "specs" / "example8.yaml")!r})
built = build_abstraction(mission)
print(json.dumps({{"scipy": sorted(m for m in sys.modules if m.startswith("scipy")),
    "components": int(built.component.max()) + 1}}))
"""
    )
    assert result["scipy"] == []
    assert result["components"] == 1
