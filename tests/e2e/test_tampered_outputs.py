"""Tampered output folders: `plot` and `export` reject them with a diagnostic, never crash."""

from __future__ import annotations

import io
import json
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from tlmpc.cli import main

ROOT = Path(__file__).resolve().parents[2]


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    return main(list(argv), out=out, err=err), out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def compiled(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("tamper") / "example1"
    code, _, err = run_cli("compile", str(ROOT / "specs" / "example1.yaml"), "-o", str(out), "-q")
    assert code == 0, err
    return out


Doc = dict[str, Any]


def edit(name: str, change: Callable[[Doc], None]) -> Callable[[Path], None]:
    def apply(directory: Path) -> None:
        path = directory / name
        document = json.loads(path.read_text())
        change(document)
        path.write_text(json.dumps(document))

    return apply


def write(name: str, text: str) -> Callable[[Path], None]:
    def apply(directory: Path) -> None:
        (directory / name).write_text(text)

    return apply


def replace_by_folder(name: str) -> Callable[[Path], None]:
    def apply(directory: Path) -> None:
        (directory / name).unlink()
        (directory / name).mkdir()

    return apply


def set_key(key: str, value: Any) -> Callable[[Doc], None]:
    return lambda d: d.__setitem__(key, value)


TAMPERINGS: dict[str, Callable[[Path], None]] = {
    "triangle index": edit("abstraction.json", lambda d: d["triangles"][0].__setitem__(0, 10**6)),
    "neighbour index": edit("abstraction.json", lambda d: d["neighbors"][3].__setitem__(1, 10**6)),
    "letter index": edit("abstraction.json", lambda d: d["letter_of"].__setitem__(0, 999)),
    "short letter_of": edit("abstraction.json", lambda d: d["letter_of"].pop()),
    "start": edit("abstraction.json", set_key("start", 10**9)),
    "unknown letter region": edit("abstraction.json", lambda d: d["letters"].append(["ghost"])),
    "hostile region": edit(
        "abstraction.json", lambda d: d["regions"].__setitem__('a"];x', d["regions"]["p1"])
    ),
    "vertices as text": edit("abstraction.json", set_key("vertices", "many")),
    "no triangles key": edit("abstraction.json", lambda d: d.pop("triangles")),
    "formula": edit("mission.json", set_key("formula", "F (")),
    "formula region": edit("mission.json", set_key("formula", "F zzz")),
    "formula type": edit("mission.json", set_key("formula", 42)),
    "witness index": edit("witness.json", lambda d: d["prefix"].append(10**7)),
    "witness prefix emptied": edit("witness.json", set_key("prefix", [])),
    "witness word cut": edit("witness.json", lambda d: d["word"].pop()),
    "witness states cut": edit("witness.json", lambda d: d["prefix_states"].pop()),
    "trace NaN": write(
        "trace.json",
        (ROOT / "specs" / "example1.yaml").read_text()
        and '{"format": "tlmpc.trace/1", '
        '"points": [[0, NaN, 1]], "ltl": "F p1", "regions": {}, "workspace": {}, '
        '"boundary": "right", "loop_start": null}',
    ),
    "truncated": write("abstraction.json", '{"format": "tlmpc.abstraction/1", "vert'),
    "format": edit("abstraction.json", set_key("format", "tlmpc.witness/1")),
    "deep": write("mission.json", "[" * 100_000 + "]" * 100_000),
    "huge int": write("mission.json", '{"format": "tlmpc.mission/1", "x": ' + "9" * 5000 + "}"),
    "folder": replace_by_folder("abstraction.json"),
    "not UTF-8": write("mission.json", "\udcff"),
}


@pytest.mark.parametrize("tampering", sorted(TAMPERINGS))
def test_tampered_output_is_rejected(compiled: Path, tmp_path: Path, tampering: str) -> None:
    copy = tmp_path / "out"
    shutil.copytree(compiled, copy)
    try:
        TAMPERINGS[tampering](copy)
    except UnicodeEncodeError:
        (copy / "mission.json").write_bytes(b'{"format": "\xff"}')
    picture = (copy / "plan.svg").read_bytes()
    for argv in (("plot", str(copy)), *(("export", str(copy), "--format", f) for f in FORMATS)):
        code, out, err = run_cli(*argv)
        if tampering.startswith(("witness", "trace NaN")) and argv[0] == "export":
            assert code == 0, err  # export does not read the witness or the trace
            continue
        assert code == 2, (argv, err)
        assert "error[U0" in err, err
        assert "Traceback" not in err
        assert out == ""
    assert (copy / "plan.svg").read_bytes() == picture


FORMATS = ("promela", "smv", "dot")


def test_untampered_output_still_plots_and_exports(compiled: Path, tmp_path: Path) -> None:
    copy = tmp_path / "out"
    shutil.copytree(compiled, copy)
    assert run_cli("plot", str(copy))[0] == 0
    for fmt in FORMATS:
        assert run_cli("export", str(copy), "--format", fmt)[0] == 0


def test_mathtext_in_the_mission_name_is_drawn_literally(compiled: Path, tmp_path: Path) -> None:
    copy = tmp_path / "out"
    shutil.copytree(compiled, copy)
    edit("mission.json", set_key("name", r"$\foo$ and $x^{$"))(copy)
    code, _, err = run_cli("plot", str(copy))
    assert code == 0, err


def test_stage_verify_of_an_edited_trace_that_fails_is_the_folders_answer(
    compiled: Path, tmp_path: Path
) -> None:
    # cut to its first samples and declared to stay there: a trajectory that never gets done
    copy = tmp_path / "out"
    shutil.copytree(compiled, copy)
    trace = json.loads((copy / "trace.json").read_text())
    trace["points"] = trace["points"][:5]
    trace["loop_start"] = None
    (copy / "trace.json").write_text(json.dumps(trace))
    code, _, err = run_cli("stage", "verify", str(copy))
    assert code == 1, err  # a no, as `tlmpc verify` answers it; not an internal error
    assert err.startswith(f"{copy / 'trace.json'}: error[U077]: the trajectory in trace.json"), err
    assert "{" not in err.splitlines()[0]  # the verifier's words, not a raw record
    assert "Traceback" not in err
