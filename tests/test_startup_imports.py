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


def test_a_compile_imports_no_scipy_lark_or_numpy_test_modules(tmp_path: Path) -> None:
    """A whole compile of Example 8 (figure included) loads none of the libraries it does not
    use: scipy, lark, matplotlib, jsonschema, numpy's f2py and testing."""
    result = _run(
        f"""
import io, json, sys
from tlmpc.cli import main
code = main(["compile", {str(ROOT / "specs" / "example8.yaml")!r}, "-o", {str(tmp_path / "out")!r},
             "-q"], io.StringIO(), io.StringIO())
heavy = ("scipy", "lark", "matplotlib", "jsonschema", "numpy.f2py", "numpy.testing")
print(json.dumps({{"code": code, "loaded": sorted(
    m for m in sys.modules if any(m == h or m.startswith(h + ".") for h in heavy))}}))
"""
    )
    assert result["code"] == 0
    assert result["loaded"] == []


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
