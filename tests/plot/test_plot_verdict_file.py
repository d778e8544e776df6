"""`tlmpc plot OUT --verdict FILE`: the given verdict is checked against the verdict schema.

A verdict the scene cannot draw (a position that is no pair of numbers, a time that is no
number) is a malformed input file, exit 2 with U071 at the file, never an internal error.
"""

from __future__ import annotations

import io
import json
import math
import re
from pathlib import Path
from typing import Any

import pytest

from tlmpc.cli import main

ROOT = Path(__file__).resolve().parents[2]
MISSION = ROOT / "specs" / "example1.yaml"
NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|[-+]?(?:inf|nan)", re.I)


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out=out, err=err)
    return code, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def compiled(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, Any]]:
    """A compile output and the verifier's verdict of a log leaving its map."""
    folder = tmp_path_factory.mktemp("verdict")
    out = folder / "out"
    code, _, err = run_cli("compile", str(MISSION), "-o", str(out), "-q")
    assert code == 0, err
    log = folder / "off.csv"
    log.write_text("t,x,y\n0,1.5,1.5\n1,50,50\n2,1.5,1.5\n")
    code, text, _ = run_cli("verify", str(log), "--mission", str(MISSION), "--json")
    assert code == 1
    verdict: dict[str, Any] = json.loads(text)["result"]
    assert verdict["workspace_violation"]["position"] is not None
    return out, verdict


def test_the_verifiers_verdict_is_drawn(compiled: tuple[Path, dict[str, Any]]) -> None:
    out, verdict = compiled
    path = out.parent / "violated.json"
    path.write_text(json.dumps(verdict))
    code, _, err = run_cli("plot", str(out), "--verdict", str(path))
    assert code == 0, err
    assert "violation 1" in (out / "plan.svg").read_text()


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("position", "abc"),
        ("position", [1]),
        ("position", [1, 2, 3]),
        ("position", [None, None]),
        ("position", ["a", "b"]),
        ("time", "x"),
    ],
)
def test_a_violation_the_scene_cannot_draw_is_a_malformed_file(
    compiled: tuple[Path, dict[str, Any]], field: str, value: Any
) -> None:
    out, verdict = compiled
    bad = json.loads(json.dumps(verdict))
    bad["workspace_violation"][field] = value
    path = out.parent / "bad.json"
    path.write_text(json.dumps(bad))
    before = (out / "plan.svg").read_bytes()
    code, _, err = run_cli("plot", str(out), "--verdict", str(path))
    assert code == 2, err
    assert f"{path}: error[U071]" in err
    assert "internal error" not in err
    assert (out / "plan.svg").read_bytes() == before


def test_another_documents_format_is_refused(compiled: tuple[Path, dict[str, Any]]) -> None:
    out, verdict = compiled
    path = out.parent / "future.json"
    path.write_text(json.dumps({**verdict, "format": "tlmpc.verdict/9"}))
    code, _, err = run_cli("plot", str(out), "--verdict", str(path))
    assert code == 2
    assert "error[U071]" in err


# A violation's position is a point of a trace, which the verifier reads within ±1e12 only;
# one farther out is refused by the verdict schema (U071) and never reaches the picture, where
# it would write `inf` into the path data.
def _with_position(
    compiled: tuple[Path, dict[str, Any]], position: list[float], name: str
) -> tuple[Path, Path]:
    out, verdict = compiled
    edited = json.loads(json.dumps(verdict))
    edited["workspace_violation"]["position"] = position
    path = out.parent / name
    path.write_text(json.dumps(edited))
    return out, path


def _path_numbers(svg: str) -> list[str]:
    return [n for d in re.findall(r' d="([^"]*)"', svg) for n in NUMBER.findall(d)]


@pytest.mark.parametrize("position", [[1e308, -1e308], [1.5, -1e13], [2e12, 3.0]])
def test_a_position_beyond_what_the_verifier_reads_is_refused(
    compiled: tuple[Path, dict[str, Any]], position: list[float]
) -> None:
    out, path = _with_position(compiled, position, "far.json")
    before = (out / "plan.svg").read_bytes()
    code, _, err = run_cli("plot", str(out), "--verdict", str(path))
    assert code == 2, err
    assert f"{path}: error[U071]" in err
    assert "position" in err
    assert (out / "plan.svg").read_bytes() == before


def test_a_position_at_the_bound_is_drawn_with_finite_numbers(
    compiled: tuple[Path, dict[str, Any]],
) -> None:
    out, path = _with_position(compiled, [1e12, -1e12], "edge.json")
    code, _, err = run_cli("plot", str(out), "--verdict", str(path))
    assert code == 0, err
    numbers = _path_numbers((out / "plan.svg").read_text())
    assert numbers
    assert all(math.isfinite(float(n)) for n in numbers)


def test_a_listed_violation_beyond_the_bound_is_refused(
    compiled: tuple[Path, dict[str, Any]],
) -> None:
    out, verdict = compiled
    edited = json.loads(json.dumps(verdict))
    far = {"conjunct": "G inside", "time": 1.0, "position": [0.0, -1e300], "message": "far"}
    edited["violations"] = [*edited["violations"], far]
    path = out.parent / "listed.json"
    path.write_text(json.dumps(edited))
    code, _, err = run_cli("plot", str(out), "--verdict", str(path))
    assert code == 2, err
    assert f"{path}: error[U071]" in err
    assert "violations[" in err
