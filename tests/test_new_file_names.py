"""`tlmpc new map -o FILE`: the mission and the map YAML name their files so that YAML reads
the names back exactly, whatever characters FILE's name holds."""

from __future__ import annotations

import io
from pathlib import Path

import pytest
import yaml

from tlmpc.cli import main
from tlmpc.commands.new import yaml_string


@pytest.mark.parametrize(
    "name",
    ["site😀.yaml", "𝔘 map 🛰.yaml", 'a"b\\c: #x.yaml', "tab\tand\u00a0space.yaml", "é.yaml"],
)
def test_the_written_mission_names_its_map_so_that_it_loads(tmp_path: Path, name: str) -> None:
    target = tmp_path / name
    out, err = io.StringIO(), io.StringIO()
    assert main(["new", "map", "-o", str(target)], out=out, err=err) == 0, err.getvalue()
    map_yaml = tmp_path / f"{target.stem}-map.yaml"
    # both YAML readers (libyaml's and PyYAML's own) read back the files' real names
    loaders = [yaml.SafeLoader] + ([yaml.CSafeLoader] if hasattr(yaml, "CSafeLoader") else [])
    for loader in loaders:
        mission = yaml.load(target.read_text(encoding="utf-8"), Loader=loader)
        assert mission["workspace"]["map"] == map_yaml.name
        assert (tmp_path / mission["workspace"]["map"]).is_file()
        metadata = yaml.load(map_yaml.read_text(encoding="utf-8"), Loader=loader)
        assert metadata["image"] == f"{target.stem}-map.pgm"
        assert (tmp_path / metadata["image"]).is_file()
    # and tlmpc checks the mission from another directory
    err = io.StringIO()
    assert main(["check", str(target)], out=io.StringIO(), err=err) == 0, err.getvalue()


def test_a_yaml_string_is_one_line_that_reads_back_exactly() -> None:
    for text in ["", "x" * 300 + " y" * 200, "\x00\x1b\x85\u2028\ufeff", "😀", "- [a]: {b}", "~"]:
        written = yaml_string(text)
        assert "\n" not in written
        assert yaml.load(written, Loader=yaml.SafeLoader) == text


@pytest.mark.parametrize("template", ["reach-avoid", "patrol", "map"])
@pytest.mark.parametrize("output", ["", ".", "..", "/", "{dir}/", "{dir}/new/", "{dir}/new/."])
def test_an_output_naming_a_directory_or_nothing_is_refused(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, template: str, output: str
) -> None:
    """`-o` names the mission's file: a name with no file in it (empty, `.`, a trailing
    `/`) is refused, exit 2, and nothing is written anywhere under the folder."""
    monkeypatch.chdir(tmp_path)
    target = output.format(dir=tmp_path)
    err = io.StringIO()
    assert main(["new", template, "-o", target], out=io.StringIO(), err=err) == 2
    assert "error[U093]" in err.getvalue()
    assert list(tmp_path.rglob("*")) == []
