"""`tlmpc.read_output` reads automaton.hoa as it reads every artifact: bounded, and an
undecodable one is a located U001 (a UsageError), never a bare UnicodeDecodeError."""

from __future__ import annotations

from pathlib import Path

import pytest

import tlmpc
from tlmpc.io.outdir import write_artifacts
from tlmpc.pipeline.stages import compile_mission

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def automaton_output(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("out")
    write_artifacts(
        folder, compile_mission(ROOT / "specs" / "example1.yaml", until="automaton").artifacts
    )
    return folder


def test_the_hoa_text_is_read_back(automaton_output: Path) -> None:
    compiled = tlmpc.read_output(automaton_output)
    assert compiled.artifacts["automaton.hoa"] == (automaton_output / "automaton.hoa").read_text()
    assert compiled.artifacts["automaton.hoa"].startswith("HOA: v1")


def test_an_undecodable_hoa_is_u001_at_its_first_bad_byte(
    automaton_output: Path, tmp_path: Path
) -> None:
    folder = tmp_path / "out"
    folder.mkdir()
    for entry in automaton_output.iterdir():
        (folder / entry.name).write_bytes(entry.read_bytes())
    (folder / "automaton.hoa").write_bytes(b'HOA: v1\nname: "\xff\xfe"\n')
    with pytest.raises(tlmpc.UsageError) as refused:
        tlmpc.read_output(folder)
    diagnostic = refused.value.diagnostics[0]
    assert (diagnostic.code, diagnostic.line, diagnostic.col) == ("U001", 2, 8)
    assert diagnostic.file == str(folder / "automaton.hoa")
    assert diagnostic.hint
