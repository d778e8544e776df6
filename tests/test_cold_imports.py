"""What ``tlmpc compile`` loads: a mission without sensors needs no game solver.

Every import is paid on every cold start (a compile from a shell or an editor); the BDD
library and the graph library behind it cost more than a small mission's whole compile.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _modules_after_compile(mission: Path, out: Path) -> tuple[int, list[str]]:
    script = (
        "import io, sys\n"
        "from tlmpc.cli import main\n"
        f"code = main(['compile', {str(mission)!r}, '-o', {str(out)!r}, '-q'],"
        " io.StringIO(), io.StringIO())\n"
        "heavy = sorted(m for m in sys.modules if m.split('.')[0] in ('dd', 'networkx')"
        " or m.startswith(('tlmpc.synth', 'tlmpc.reactive.synthesize')))\n"
        "print(code, ' '.join(heavy))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, check=True, cwd=ROOT
    )
    code, _, names = done.stdout.strip().partition(" ")
    return int(code), names.split()


def test_a_mission_without_sensors_compiles_without_the_game_solver(tmp_path: Path) -> None:
    code, heavy = _modules_after_compile(ROOT / "specs" / "example1.yaml", tmp_path / "out")
    assert code == 0
    assert heavy == []


def test_a_reactive_mission_still_loads_it(tmp_path: Path) -> None:
    # the other side of the same check: the names above are the solver's, so the first
    # test's empty list means something
    code, heavy = _modules_after_compile(
        ROOT / "specs" / "reactive" / "guard.yaml", tmp_path / "out"
    )
    assert code == 0
    assert "tlmpc.reactive.synthesize" in heavy
    assert "dd" in heavy
