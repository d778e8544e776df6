"""Names and messages with characters no picture can hold as they are: control and direction
characters, noncharacters (U+FFFE and U+FFFF are not XML characters) and lone surrogates (not
UTF-8) reach the SVG and the PNG as visible escapes, whatever file they came from."""

from __future__ import annotations

import io
import json
import unicodedata
from pathlib import Path
from xml.etree import ElementTree

import pytest

from tlmpc.base.errors import UNSAFE_RANGES, is_unsafe_char, printable
from tlmpc.cli import main

ROOT = Path(__file__).resolve().parents[2]
SVG = "{http://www.w3.org/2000/svg}"

_DIRECTION_AND_LINE = set(
    "\u061c\u200e\u200f\u202a\u202b\u202c\u202d\u202e\u2066\u2067\u2068\u2069\u2028\u2029"
)


def _unsafe_by_definition(code: int) -> bool:
    """The escaping rule from the Unicode character database: controls (Cc), surrogates (Cs),
    noncharacters (U+FDD0..U+FDEF and the last two code points of every plane), and the
    direction and line controls."""
    ch = chr(code)
    return (
        unicodedata.category(ch) in ("Cc", "Cs")
        or 0xFDD0 <= code <= 0xFDEF
        or code % 0x10000 in (0xFFFE, 0xFFFF)
        or ch in _DIRECTION_AND_LINE
    )


def test_the_one_escaping_rule_is_the_definition_for_every_code_point() -> None:
    for code in range(0x110000):
        assert is_unsafe_char(chr(code)) == _unsafe_by_definition(code), hex(code)
    assert all(first <= last for first, last in UNSAFE_RANGES)
    assert list(UNSAFE_RANGES) == sorted(UNSAFE_RANGES)


def test_printable_text_can_be_written_as_utf8_and_xml() -> None:
    text = "a\x00\x7f\x85\ufffe\uffff\ud800\udfff\ufdd0\U0001fffe\U0010ffff\u202e😀é"
    shown = printable(text, keep="")
    assert shown == (
        "a\\x00\\x7f\\x85\\ufffe\\uffff\\ud800\\udfff\\ufdd0\\U0001fffe\\U0010ffff\\u202e😀é"
    )
    shown.encode("utf-8")
    ElementTree.fromstring(f"<t>{shown}</t>")


def _run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out=out, err=err)
    return code, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def compiled(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("unsafe") / "out"
    code, _, err = _run("compile", str(ROOT / "specs" / "example1.yaml"), "-o", str(out), "-q")
    assert code == 0, err
    return out


def _svg_texts(path: Path) -> list[str]:
    root = ElementTree.parse(path).getroot()  # fails on a character XML does not allow
    texts = [t.text or "" for t in root.iter(f"{SVG}text")]
    texts += [t.text or "" for t in root.iter(f"{SVG}title")]
    return texts


@pytest.mark.parametrize("name", ["site \ufffe B", "site \uffff B", "site \ud800 B"])
def test_a_mission_name_no_xml_file_can_hold_is_escaped(
    compiled: Path, tmp_path: Path, name: str
) -> None:
    out = tmp_path / "out"
    out.mkdir()
    for path in compiled.iterdir():
        (out / path.name).write_bytes(path.read_bytes())
    mission = json.loads((out / "mission.json").read_text())
    mission["name"] = name
    # JSON's \uXXXX escapes: a lone surrogate is valid JSON text
    (out / "mission.json").write_text(json.dumps(mission))
    for argv in (("plot", str(out)), ("stage", "plot", str(out))):
        code, _, err = _run(*argv)
        assert code == 0, err
        texts = _svg_texts(out / "plan.svg")
        assert printable(name, keep="") in texts
        assert not any(is_unsafe_char(ch) for text in texts for ch in text)


def test_a_verdict_message_no_xml_file_can_hold_is_escaped(compiled: Path, tmp_path: Path) -> None:
    log = tmp_path / "log.csv"
    log.write_text("t,x,y\n" + "".join(f"{i},{1.5 - 0.5 * i},1.5\n" for i in range(8)))
    code, verdict_json, err = _run(
        "verify", str(log), "--mission", str(ROOT / "specs" / "example1.yaml"), "--json"
    )
    verdict = json.loads(verdict_json)["result"]
    assert verdict["format"].startswith("tlmpc.verdict/"), err
    for key in ("counterexample", "workspace_violation"):
        if verdict.get(key):
            verdict[key]["message"] = "left \ud800 the \uffff map"
    (tmp_path / "verdict.json").write_text(json.dumps(verdict))
    code, _, err = _run(
        "plot", str(compiled), "--log", str(log), "--verdict", str(tmp_path / "verdict.json")
    )
    assert code == 0, err
    texts = _svg_texts(compiled / "log.svg")
    assert any("left \\ud800 the \\uffff map" in text for text in texts)


@pytest.mark.parametrize(
    "window",
    ["-1e308,-1e308,1e308,1e308", "-1e308,0,1e308,1", "0,-1.7e308,1,1.7e308"],
)
def test_a_zoom_window_wider_than_the_largest_float_is_a_usage_error(
    compiled: Path, window: str
) -> None:
    code, _, err = _run("plot", str(compiled), f"--zoom={window}")
    assert code == 2, err
    assert "--zoom" in err
    assert "finite" in err
