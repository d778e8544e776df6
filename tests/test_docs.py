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
    return dict(action.choices)  # type: ignore[attr-defined]


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
