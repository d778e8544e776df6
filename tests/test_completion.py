"""`tlmpc completion`: the bash script, run in a real bash, completes what the parser accepts."""

from __future__ import annotations

import argparse
import io
import shutil
import subprocess
from pathlib import Path

import pytest

from tlmpc.cli import COMMAND_MODULES, build_parser, main

BASH = shutil.which("bash")
pytestmark = pytest.mark.skipif(BASH is None, reason="bash is not installed")


def _script(shell: str) -> str:
    out = io.StringIO()
    assert main(["completion", shell], out=out, err=io.StringIO()) == 0
    return out.getvalue()


def _complete(script: Path, *words: str) -> list[str]:
    assert BASH is not None
    quoted = " ".join(f"'{w}'" for w in words)
    program = (
        f"source '{script}'; COMP_WORDS=(tlmpc {quoted}); COMP_CWORD={len(words)}; "
        '_tlmpc; printf "%s\\n" "${COMPREPLY[@]}"'
    )
    result = subprocess.run(
        [BASH, "--noprofile", "--norc", "-c", program],
        capture_output=True,
        text=True,
        check=True,
        cwd=script.parent,
    )
    return [line for line in result.stdout.splitlines() if line]


def test_commands_flags_and_choices_complete_as_the_parser_accepts(tmp_path: Path) -> None:
    script = tmp_path / "tlmpc.bash"
    script.write_text(_script("bash"))
    names = [name.replace("_", "-") for name in COMMAND_MODULES]
    assert sorted(_complete(script, "")) == sorted(names)
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    for name, command in sub.choices.items():
        flags = sorted(_complete(script, name, "-"))
        expected = sorted(s for a in command._actions for s in a.option_strings)
        assert flags == expected, name
        for action in command._actions:
            if action.option_strings and action.choices:
                for flag in action.option_strings:
                    values = _complete(script, name, flag, "")
                    assert values == [str(c) for c in action.choices], (name, flag)


def test_zsh_and_fish_scripts_name_every_command() -> None:
    zsh = _script("zsh")
    assert zsh.startswith("# tlmpc completion for zsh")
    assert "bashcompinit" in zsh
    fish = _script("fish")
    for name in COMMAND_MODULES:
        assert f"-a {name.replace('_', '-')} " in fish
