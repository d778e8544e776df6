"""`tlmpc check` on a ROS map_server map YAML: checked as a map, not refused as a mission.

The pre-commit hook's default `files:` takes everything under `missions/`, where `tlmpc new map
-o missions/site.yaml` writes the map beside the mission; a keepout mask lives there too.
"""

from __future__ import annotations

import io
import json
from pathlib import Path

import pytest

from tlmpc.cli import main

ROOT = Path(__file__).resolve().parents[2]


def run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    return main(["check", *argv], out=out, err=err), out.getvalue(), err.getvalue()


def _room(folder: Path, cols: int = 6, rows: int = 4) -> bytes:
    """A PGM of ``cols`` x ``rows`` cells, free inside a one-cell wall, written by hand."""
    cells = bytearray()
    for row in range(rows):
        for col in range(cols):
            wall = row in (0, rows - 1) or col in (0, cols - 1)
            cells.append(0 if wall else 254)
    data = f"P5\n{cols} {rows}\n255\n".encode("ascii") + bytes(cells)
    (folder / "room.pgm").write_bytes(data)
    return data


MAP = """\
image: room.pgm
resolution: 0.5
origin: [0.0, 0.0, 0.0]
negate: 0
occupied_thresh: 0.65
free_thresh: 0.196
"""


def _where(text: str, key: str) -> tuple[int, int]:
    """The 1-based line and column of ``key``'s value in ``text``."""
    for number, line in enumerate(text.splitlines(), start=1):
        if line.startswith(f"{key}:"):
            return number, len(key) + 3
    raise AssertionError(key)


def test_new_map_beside_its_mission_passes_the_hook(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "missions").mkdir()
    assert (
        main(["new", "map", "-o", "missions/site.yaml"], out=io.StringIO(), err=io.StringIO()) == 0
    )
    code, _, err = run("missions/site.yaml", "missions/site-map.yaml")
    assert code == 0, err
    assert "missions/site-map.yaml: note[M020]: a ROS map_server map, not a mission: " in err
    assert "error" not in err
    assert err.rstrip().endswith("1 of 1 mission file(s) valid; 1 of 1 map file(s) valid")


def test_a_valid_map_gets_one_note_with_its_size(tmp_path: Path) -> None:
    _room(tmp_path)
    (tmp_path / "room.yaml").write_text(MAP)
    code, _, err = run(str(tmp_path / "room.yaml"))
    assert code == 0, err
    notes = [line for line in err.splitlines() if "[M020]" in line]
    assert notes == [
        f"{tmp_path / 'room.yaml'}: note[M020]: a ROS map_server map, not a mission: checked "
        "as a map (6x4 cells of 0.5 m), valid"
    ]
    assert err.rstrip().endswith("1 of 1 map file(s) valid")


@pytest.mark.parametrize(
    ("change", "code", "key"),
    [
        (("image: room.pgm", "image: gone.pgm"), "M005", "image"),
        (("image: room.pgm", "image: junk.pgm"), "M006", "image"),
        (("resolution: 0.5", 'resolution: "0.5"'), "M004", "resolution"),
        (("resolution: 0.5", "resolution: -0.5"), "M004", "resolution"),
        (("free_thresh: 0.196", "free_thresh: 0.9"), "M004", "free_thresh"),
        (("negate: 0", "negate: 0\nmode: fancy"), "M004", "mode"),
    ],
)
def test_a_broken_map_is_invalid_at_its_key(
    tmp_path: Path, change: tuple[str, str], code: str, key: str
) -> None:
    _room(tmp_path)
    (tmp_path / "junk.pgm").write_bytes(b"not an image")
    text = MAP.replace(*change)
    path = tmp_path / "map.yaml"
    path.write_text(text)
    exit_code, _, err = run(str(path))
    assert exit_code == 1, err
    line, col = _where(text, key)
    first = err.splitlines()[0]
    assert first.startswith(f"{path}:{line}:{col}: error[{code}]: "), err
    assert "  hint: " in err
    assert "M020" not in err
    assert "S001" not in err
    assert err.rstrip().endswith("0 of 1 map file(s) valid, 1 invalid")


def test_a_map_lacking_a_key_is_still_a_map(tmp_path: Path) -> None:
    _room(tmp_path)
    path = tmp_path / "map.yaml"
    path.write_text(MAP.replace("origin: [0.0, 0.0, 0.0]\n", ""))
    code, _, err = run(str(path))
    assert code == 1
    assert err.startswith(f"{path}:1:1: error[M003]: the map has no `origin`")


@pytest.mark.parametrize(
    "text",
    [
        "users: [alice, bob]\nread: true\n",  # a permissions file under missions/
        "image: room.pgm\nmode: trinary\n",  # one map key is no map
        MAP + "version: 1\n",  # a mission key: a (broken) mission, not a map
    ],
)
def test_a_yaml_that_is_neither_keeps_the_mission_errors(tmp_path: Path, text: str) -> None:
    _room(tmp_path)
    path = tmp_path / "other.yaml"
    path.write_text(text)
    code, _, err = run(str(path))
    assert code == 1
    assert "error[S00" in err
    assert "M020" not in err
    assert "error[M0" not in err
    assert err.rstrip().endswith("0 of 1 mission file(s) valid, 1 invalid")


def test_json_marks_the_map_with_its_note(tmp_path: Path) -> None:
    import jsonschema

    _room(tmp_path)
    (tmp_path / "room.yaml").write_text(MAP)
    code, out, _ = run("--json", str(tmp_path / "room.yaml"), str(ROOT / "specs" / "example1.yaml"))
    assert code == 0
    document = json.loads(out)
    schema = json.loads((ROOT / "schemas" / "cli-output.schema.json").read_text())
    jsonschema.validate(document, schema)
    room, mission = document["result"]["files"]
    assert room["ok"] is True
    assert room["ltl"] is None
    assert [d["code"] for d in room["diagnostics"]] == ["M020"]
    assert mission["ok"] is True
    assert mission["ltl"]


def test_an_invalid_mission_loads_no_map_reader(tmp_path: Path) -> None:
    """Asking whether a broken mission is a map reads its keys only: no numpy, no Pillow."""
    import subprocess
    import sys

    path = tmp_path / "mission.yaml"
    path.write_text((ROOT / "specs" / "example1.yaml").read_text().replace("visit p2", "visit p9"))
    script = (
        "import io, sys\n"
        "from tlmpc.cli import main\n"
        f"code = main(['check', {str(path)!r}], out=io.StringIO(), err=io.StringIO())\n"
        "print(code, sorted(m for m in ('numpy', 'PIL') if m in sys.modules))\n"
    )
    result = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, check=True
    )
    assert result.stdout.split("\n")[0] == "1 []", result.stdout + result.stderr


def test_explain_prints_the_missions_formulas_only(tmp_path: Path) -> None:
    _room(tmp_path)
    (tmp_path / "room.yaml").write_text(MAP)
    example = str(ROOT / "specs" / "example1.yaml")
    code, out, _ = run("--explain", str(tmp_path / "room.yaml"), example)
    assert code == 0
    assert out.splitlines()[0] == f"{example}: F(p2 & F(p3 & F(p4 & ((!p2 & !p3) U p1))))"
    assert "room.yaml" not in out
