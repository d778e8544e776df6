"""The documentation stays true: every CLI flag is documented, every doc link resolves."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tlmpc.cli import build_parser

ROOT = Path(__file__).resolve().parent.parent


def _subcommands() -> dict[str, object]:
    parser = build_parser()
    action = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    choices = action.choices
    assert isinstance(choices, dict)
    return dict(choices)


@pytest.mark.parametrize("command", sorted(_subcommands()))
def test_every_flag_is_in_the_cli_reference(command: str) -> None:
    reference = (ROOT / "docs" / "cli.md").read_text()
    assert f"`tlmpc {command}" in reference
    subparser = _subcommands()[command]
    for action in subparser._actions:  # type: ignore[attr-defined]
        for flag in action.option_strings:
            if flag in ("-h", "--help"):
                continue
            assert f"`{flag}" in reference or f", `{flag}" in reference, (command, flag)


def test_markdown_links_resolve() -> None:
    for page in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        for target in re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", page.read_text()):
            if target.startswith(("http://", "https://")):
                continue
            assert (page.parent / target).exists(), f"{page.name}: broken link {target}"


# --- shown outputs are the code's, and docs speak of this repository only -------------------

from docs_outputs import PAGES, normalise, page_outputs, shown_runs  # noqa: E402


@pytest.mark.slow
@pytest.mark.parametrize("page", [p for p in PAGES if shown_runs(p)])
def test_shown_outputs_are_what_the_code_prints(page: str) -> None:
    """`python tests/docs_outputs.py --write` regenerates them after a deliberate change."""
    for shown, actual in page_outputs(page):
        assert normalise(actual) == normalise(shown.shown), f"{page}: $ {shown.command}"


def test_every_shown_run_is_checked() -> None:
    pages = {p.relative_to(ROOT).as_posix() for p in [ROOT / "README.md", *ROOT.glob("docs/*.md")]}
    with_runs = {p for p in pages if "```console" in (ROOT / p).read_text()}
    assert with_runs <= set(PAGES)
    # a ```text block right after a shell command would be a shown output nobody checks
    for page in pages:
        text = (ROOT / page).read_text()
        assert not re.search(r"```sh\n[^`]*\btlmpc [^`]*```\s*```text", text), page


_REPO_PATH = re.compile(r"`((?:specs|docs|tests|tlmpc|schemas|bench)/[A-Za-z0-9_./-]+)`")


def test_docs_refer_only_to_files_in_the_repository() -> None:
    for page in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        text = page.read_text()
        assert "/work/" not in text, page.name
        assert not re.search(r"(^|[\s(`])(/home/|/tmp/|~/|\.\./shared)", text), page.name
        for target in re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", text):
            if target.startswith(("http://", "https://")):
                continue
            resolved = (page.parent / target).resolve()
            assert resolved.is_relative_to(ROOT), f"{page.name}: {target} is outside"
        for path in _REPO_PATH.findall(text):
            if any(c in path for c in "*{}") or path.endswith("/"):
                continue
            assert (ROOT / path).exists(), f"{page.name}: `{path}` is not in the repository"


def test_code_comments_refer_to_no_outside_files() -> None:
    for source in sorted((ROOT / "tlmpc").rglob("*.py")):
        text = source.read_text()
        assert "/work/" not in text, source
        assert "shared/data" not in text, source


_ROW = re.compile(
    r"^\| \[(?P<name>[\w-]+)\]\(\.\./specs/[\w-]+\.yaml\) \| `(?P<ltl>[^`]+)` \| "
    r"\**(?P<triangles>[\d,]+)\** \| (?P<states>\d+) \| (?P<plan>[^|]+) \| "
    r"(?P<steps>\d+) / (?P<jumps>\d+) \| (?P<trajectory>[^|]+) \|",
    re.MULTILINE,
)


def _example_rows() -> list[dict[str, str]]:
    return [m.groupdict() for m in _ROW.finditer((ROOT / "docs" / "examples.md").read_text())]


def test_the_examples_table_lists_every_spec() -> None:
    names = {row["name"] for row in _example_rows()}
    assert names == {p.stem for p in (ROOT / "specs").glob("*.yaml")}


@pytest.mark.slow
@pytest.mark.parametrize("row", _example_rows(), ids=lambda r: r["name"])
def test_the_examples_table_is_what_compile_gives(row: dict[str, str], tmp_path: Path) -> None:
    import io
    import json

    from tlmpc.cli import main

    out = tmp_path / "out"
    spec = ROOT / "specs" / f"{row['name']}.yaml"
    assert (
        main(["compile", str(spec), "-o", str(out), "-q"], out=io.StringIO(), err=io.StringIO())
        == 0
    )
    summary = json.loads((out / "summary.json").read_text())
    sizes = {stage["name"]: stage["sizes"] for stage in summary["stages"]}
    if "…" not in row["ltl"]:
        assert row["ltl"] == summary["formula"]
    assert int(row["triangles"].replace(",", "")) == sizes["abstraction"]["triangles"]
    assert int(row["states"]) == sizes["automaton"]["states"]
    plan = summary["plan"]
    prefix, rest = (part.strip() for part in row["plan"].split("+"))
    assert int(prefix) == plan["prefix_length"]
    if rest == "stay":
        assert plan["stay"] is True
    else:
        assert plan["stay"] is False
        assert rest == f"{plan['cycle_length']}-triangle cycle"
    assert (int(row["steps"]), int(row["jumps"])) == (
        sizes["control"]["steps"],
        sizes["control"]["jumps"],
    )
    duration = re.match(r"([\d.]+) s", row["trajectory"].strip())
    assert duration is not None
    assert duration.group(1) == f"{sizes['simulate']['duration']:.1f}"
    robustness = re.search(r"robustness ([\d.]+)", row["trajectory"])
    if robustness is not None:
        assert robustness.group(1) == f"{summary['verdict']['robustness']:.2f}"
