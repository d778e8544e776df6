"""`tlmpc plot`: logs over the map, their violations, zoom; compile draws without matplotlib."""

from __future__ import annotations

import html
import io
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from tlmpc.cli import main

ROOT = Path(__file__).resolve().parents[2]


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out=out, err=err)
    return code, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def example1(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("plot") / "example1"
    code, _, err = run_cli("compile", str(ROOT / "specs" / "example1.yaml"), "-o", str(out), "-q")
    assert code == 0, err
    return out


def test_a_log_leaving_the_map_is_drawn_with_its_violation_marked(example1: Path) -> None:
    log = example1 / "robot.csv"
    # From the start (1.5, 1.5) straight out through the left wall of the 10 x 10 map.
    log.write_text("t,x,y\n" + "".join(f"{i},{1.5 - 0.5 * i},1.5\n" for i in range(8)))
    code, _, err = run_cli("plot", str(example1), "--log", str(log))
    assert code == 0, err
    assert "violated" in err
    svg = (example1 / "log.svg").read_text()
    assert "recorded log" in svg
    assert "violation 1" in svg
    # The verifier's own verdict names the same violation.
    code, out, _ = run_cli(
        "verify", str(log), "--mission", str(ROOT / "specs" / "example1.yaml"), "--json"
    )
    assert code == 1
    verdict = json.loads(out)["result"]
    messages = [
        verdict[k]["message"] for k in ("workspace_violation", "counterexample") if verdict[k]
    ]
    assert messages
    # The legend spells the verifier's message out (wrapped on words).
    first_words = " ".join(messages[0].split()[:3])
    assert html.escape(first_words) in svg


def test_a_given_verdict_is_used_instead_of_verifying(example1: Path) -> None:
    code, _, err = run_cli(
        "plot",
        str(example1),
        "--log",
        str(example1 / "trace.json"),
        "--verdict",
        str(example1 / "verdict.json"),
    )
    assert code == 0, err
    assert "satisfied; 0 violation(s) marked" in err
    assert "violation 1" not in (example1 / "log.svg").read_text()


def test_zoom_draws_the_window_only(example1: Path) -> None:
    code, _, err = run_cli("plot", str(example1), "--zoom", "0,0,4,4")
    assert code == 0, err
    svg = (example1 / "plan.svg").read_text()
    assert ">p1</text>" in svg
    assert ">p3</text>" not in svg  # p3 lies in [6.5, 9.5]^2, outside the window


@pytest.mark.parametrize("window", ["1,2,3", "0,0,0,1", "a,b,c,d", "0,0,nan,1"])
def test_a_bad_zoom_is_a_usage_error(example1: Path, window: str) -> None:
    code, _, err = run_cli("plot", str(example1), "--zoom", window)
    assert code == 2
    assert "zoom" in err


def test_compile_draws_its_picture_without_importing_matplotlib(tmp_path: Path) -> None:
    # Load-independent stand-in for a start-up time budget: the default figure must not
    # pull in the plotting library (about half a second to import).
    program = (
        "import sys\n"
        "from tlmpc.cli import main\n"
        f"code = main(['compile', {str(ROOT / 'specs' / 'example1.yaml')!r}, '-o', "
        f"{str(tmp_path / 'out')!r}, '-q'])\n"
        "print(code, sorted(m for m in sys.modules if m.split('.')[0] == 'matplotlib')[:3])\n"
    )
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    result = subprocess.run(
        [sys.executable, "-c", program], capture_output=True, text=True, env=env, check=False
    )
    assert result.stdout.strip() == "0 []", result.stderr
    assert (tmp_path / "out" / "plan.svg").is_file()
    assert not (tmp_path / "out" / "plan.png").exists()
