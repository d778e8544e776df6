"""The README's light install for the pre-commit hook, without Pillow: `check` of a map, or of a
mission on a map, names the missing package (U060) instead of failing with a traceback."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from tlmpc.base.extras import LIGHT_INSTALL_LACKS

BLOCKED = (
    "import sys\n"
    "class Block:\n"
    "    def find_spec(self, name, path=None, target=None):\n"
    "        if name.split('.')[0] == 'PIL':\n"
    "            raise ModuleNotFoundError(name + ' is not installed', name=name)\n"
    "sys.meta_path.insert(0, Block())\n"
    "from tlmpc.cli import main\n"
    "sys.exit(main(['check', *sys.argv[1:]]))\n"
)


@pytest.fixture
def site(tmp_path: Path) -> Path:
    (tmp_path / "missions").mkdir()
    made = subprocess.run(
        [sys.executable, "-m", "tlmpc", "new", "map", "-o", "missions/site.yaml"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        check=False,
    )
    assert made.returncode == 0, made.stderr
    return tmp_path


@pytest.mark.parametrize(
    ("file", "exit_code", "where"),
    [
        ("missions/site-map.yaml", 2, "missions/site-map.yaml:2:8"),  # at the map's `image`
        ("missions/site.yaml", 1, "missions/site.yaml:9:18"),  # at the mission's `map`
    ],
)
def test_check_without_pillow_names_it(site: Path, file: str, exit_code: int, where: str) -> None:
    result = subprocess.run(
        [sys.executable, "-c", BLOCKED, file], cwd=site, capture_output=True, text=True, check=False
    )
    assert result.returncode == exit_code, result.stderr
    assert "Traceback" not in result.stderr
    assert f"{where}: error[U060]: " in result.stderr
    assert "reading a map image needs the package 'PIL', which is not installed" in result.stderr
    assert f"pip install {LIGHT_INSTALL_LACKS['PIL']}" in result.stderr
    assert LIGHT_INSTALL_LACKS["PIL"] == "pillow"
