"""Fuzzing the CLI: missions, traces and output folders drawn by hypothesis.

Every answer must be exit 0, 1 or 2 with diagnostics of the form ``LOCATION: error[CODE]:``;
never exit 3, a traceback or an escaped exception.  Output folders must never lose a user's
file.  The example budget follows the hypothesis profile (``ci`` is smaller, never zero).
"""

from __future__ import annotations

import io
import json
import os
import re
import string
from pathlib import Path

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tlmpc.cli import main
from tlmpc.io.outdir import KNOWN_ARTIFACTS, MARKER

ROOT = Path(__file__).resolve().parents[2]
SPECS = sorted((ROOT / "specs").glob("*.yaml"))
DIAGNOSTIC = re.compile(r"^\S.*: (error|warning|note)\[[A-Z]\d{3}\]: ")
FUZZ = settings(suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    return main(list(argv), out=out, err=err), out.getvalue(), err.getvalue()


def assert_clean_answer(code: int, err: str) -> None:
    assert code in (0, 1, 2), err
    assert "Traceback" not in err
    assert "internal error" not in err
    assert "\x1b" not in err
    for line in err.splitlines():
        if "error[" in line and not line.startswith("  "):
            assert DIAGNOSTIC.match(line), line


HOSTILE_TEXT = st.sampled_from(
    [
        '*/ init { c_code { system("touch PWNED") } } /*',
        "\x1b[31m",
        "$\\foo$",
        "a\nb",
        "\u202e",
        "1e-6",
        "&a",
        "*a",
        "!!python/object:os.system",
        "{",
        "[" * 50,
        "\x00",
        "9" * 5000,
        ".nan",
        "-.inf",
        "~",
        "yes",
        "0x1F",
        "<<",
    ]
)

# --- missions ---------------------------------------------------------------------------------


def _mutate(text: str, data: st.DataObject) -> str:
    for _ in range(data.draw(st.integers(1, 4), label="edits")):
        kind = data.draw(st.sampled_from(["delete", "insert", "line", "replace", "dup"]))
        if not text:
            text = data.draw(HOSTILE_TEXT)
            continue
        at = data.draw(st.integers(0, len(text) - 1), label="at")
        if kind == "delete":
            text = text[:at] + text[at + data.draw(st.integers(1, 20)) :]
        elif kind == "insert":
            piece = data.draw(HOSTILE_TEXT | st.text(string.printable, max_size=8))
            text = text[:at] + piece + text[at:]
        elif kind == "line":
            lines = text.splitlines()
            del lines[data.draw(st.integers(0, max(len(lines) - 1, 0)))]
            text = "\n".join(lines) + "\n"
        elif kind == "replace":
            token = data.draw(st.sampled_from([":", "[", "]", "{", "}", ",", "-", " ", "\t"]))
            text = text[:at] + token + text[at + 1 :]
        else:
            end = min(len(text), at + data.draw(st.integers(1, 80)))
            text = text[:end] + text[at:end] + text[end:]
    return text


@pytest.mark.slow
@FUZZ
@given(st.data())
def test_mutated_missions_get_clean_answers(tmp_path: Path, data: st.DataObject) -> None:
    spec = data.draw(st.sampled_from(SPECS), label="spec")
    text = _mutate(spec.read_text(), data)
    path = tmp_path / "mission.yaml"
    path.write_text(text, encoding="utf-8", errors="surrogatepass")
    code, _, err = run_cli("check", str(path))
    assert_clean_answer(code, err)
    code, _, err = run_cli("check", "--json", str(path))
    assert_clean_answer(code, err)


VALUES = st.recursive(
    st.none()
    | st.booleans()
    | st.integers(-(10**20), 10**20)
    | st.floats(allow_nan=True, allow_infinity=True)
    | st.text(max_size=10)
    | HOSTILE_TEXT,
    lambda inner: (
        st.lists(inner, max_size=5) | st.dictionaries(st.text(max_size=6), inner, max_size=5)
    ),
    max_leaves=25,
)
KEYS = st.sampled_from(
    ["version", "name", "workspace", "regions", "groups", "robot", "task", "ltl", "options"]
)


@pytest.mark.slow
@FUZZ
@given(st.dictionaries(KEYS, VALUES, max_size=9), st.booleans())
def test_random_mission_documents_get_clean_answers(
    tmp_path: Path, document: dict[str, object], compile_too: bool
) -> None:
    path = tmp_path / "mission.yaml"
    path.write_text(yaml.safe_dump(document), encoding="utf-8")
    code, _, err = run_cli("check", str(path))
    assert_clean_answer(code, err)
    if compile_too:
        code, _, err = run_cli("compile", str(path), "-o", str(tmp_path / "out"), "--until", "load")
        assert_clean_answer(code, err)


# --- traces ------------------------------------------------------------------------------------

SAMPLES = st.lists(
    st.lists(st.floats(-1e6, 1e6) | st.integers(-5, 5) | VALUES, min_size=0, max_size=4),
    max_size=6,
)


@pytest.mark.slow
@FUZZ
@given(
    st.fixed_dictionaries(
        {"format": st.sampled_from(["tlmpc.trace/1", "tlmpc.trace/9", "x"])},
        optional={
            "ltl": st.sampled_from(["G F a", "F (", "a U b", "X a", "!a"]) | VALUES,
            "regions": st.dictionaries(
                st.sampled_from(["a", "b", "\x1b[1m"]),
                st.just([[0, 0], [2, 0], [2, 2], [0, 2]]) | VALUES,
                max_size=3,
            )
            | VALUES,
            "points": SAMPLES | VALUES,
            "loop_start": st.integers(-2, 8) | VALUES,
            "max_speed": st.floats() | VALUES,
            "workspace": VALUES,
            "boundary": st.sampled_from(["right", "closed", "open"]) | VALUES,
        },
    ),
    st.booleans(),
)
def test_random_traces_get_clean_answers(
    tmp_path: Path, document: dict[str, object], as_json: bool
) -> None:
    path = tmp_path / "trace.json"
    path.write_text(json.dumps(document))
    argv = ["verify", str(path), *(["--json"] if as_json else [])]
    code, out, err = run_cli(*argv)
    assert_clean_answer(code, err)
    if as_json and out:
        json.loads(out, parse_constant=lambda c: (_ for _ in ()).throw(ValueError(c)))


@FUZZ
@given(st.text(alphabet='0123456789.,-+eEnaif \t\r\n"x', max_size=300))
def test_random_csv_traces_get_clean_answers(tmp_path: Path, text: str) -> None:
    path = tmp_path / "trace.csv"
    path.write_text(text)
    code, _, err = run_cli("verify", str(path), "--mission", str(ROOT / "specs" / "example1.yaml"))
    assert_clean_answer(code, err)


# --- output folders ----------------------------------------------------------------------------

ENTRY_NAMES = st.sampled_from(sorted(KNOWN_ARTIFACTS | {MARKER, "notes.txt", "thesis.tex"}))
ENTRY_KINDS = st.sampled_from(["file", "folder", "link", "marker"])


@FUZZ
@given(
    st.dictionaries(ENTRY_NAMES, ENTRY_KINDS, max_size=6),
    st.booleans(),
    st.sampled_from(["folder", "missing", "file", "link"]),
)
def test_output_folders_never_lose_user_files(
    tmp_path: Path, entries: dict[str, str], force: bool, shape: str
) -> None:
    base = tmp_path / f"case{len(list(tmp_path.iterdir()))}"
    base.mkdir()
    out = base / "out"
    outside = base / "outside.txt"
    outside.write_text("outside")
    if shape == "file":
        out.write_text("a file")
    elif shape == "link":
        out.symlink_to(outside)
    elif shape == "folder":
        out.mkdir()
        for name, kind in entries.items():
            path = out / name
            if kind == "folder":
                path.mkdir()
                (path / "inside.txt").write_text("mine")
            elif kind == "link":
                path.symlink_to(outside)
            elif kind == "marker" or name == MARKER:
                path.write_text("tlmpc.io.outdir/1\n" if kind == "marker" else "mine")
            else:
                path.write_text(f"user {name}")
    before = _snapshot(out) if out.is_dir() and not out.is_symlink() else None
    marked = (
        out.is_dir()
        and not out.is_symlink()
        and (out / MARKER).is_file()
        and ((out / MARKER).read_text().startswith("tlmpc.io.outdir/"))
    )
    spec = str(ROOT / "specs" / "example1.yaml")
    argv = [
        "compile",
        spec,
        "-o",
        str(out),
        "--until",
        "load",
        "-q",
        *(["--force"] if force else []),
    ]
    code, _, err = run_cli(*argv)
    assert_clean_answer(code, err)
    assert outside.read_text() == "outside"
    assert sorted(p.name for p in base.iterdir()) == sorted(
        ["out", "outside.txt"] if shape != "missing" or code == 0 else ["outside.txt"]
    )
    if before is not None and not marked and len(before) > 0:
        after = _snapshot(out)
        for name, content in before.items():  # every user entry survives (forced runs add)
            if not force or name.split(os.sep)[0] not in KNOWN_ARTIFACTS:
                assert after.get(name) == content, name
    if code == 0:
        assert (out / "mission.json").is_file()


def _snapshot(directory: Path) -> dict[str, str]:
    result: dict[str, str] = {}
    for path in sorted(directory.rglob("*")):
        key = str(path.relative_to(directory))
        if path.is_symlink():
            result[key] = "-> " + os.readlink(path)
        elif path.is_dir():
            result[key] = "<dir>"
        else:
            result[key] = path.read_text(errors="replace")
    return result
