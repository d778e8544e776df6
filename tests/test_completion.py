"""`tlmpc completion`: the bash script, run in a real bash, completes what the parser accepts."""

from __future__ import annotations

import argparse
import io
import shutil
import subprocess
from pathlib import Path

import pytest

from tlmpc.cli import COMMAND_MODULES, build_parser, main
from tlmpc.commands import completion

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


def _bash_script(directory: Path) -> Path:
    script = directory / "tlmpc.bash"
    script.write_text(_script("bash"))
    return script


def test_a_file_name_with_a_space_is_one_candidate(tmp_path: Path) -> None:
    script = _bash_script(tmp_path)
    (tmp_path / "my mission.yaml").write_text("")
    (tmp_path / "my*star.yaml").write_text("")
    (tmp_path / "other.yaml").write_text("")
    assert sorted(_complete(script, "check", "my")) == ["my mission.yaml", "my*star.yaml"]
    assert _complete(script, "check", "my ") == ["my mission.yaml"]
    assert _complete(script, "compile", "-o", "my ") == ["my mission.yaml"]


def test_tlmpc_own_flags_complete_before_the_command(tmp_path: Path) -> None:
    script = _bash_script(tmp_path)
    assert sorted(_complete(script, "-")) == ["--help", "--version", "-h"]
    assert _complete(script, "--v") == ["--version"]
    assert _complete(script, "--h") == ["--help"]
    # the command is the first word that is not a flag
    assert _complete(script, "--help", "check", "--e") == ["--explain"]


def test_an_argument_with_choices_is_offered_only_its_choices(tmp_path: Path) -> None:
    script = _bash_script(tmp_path)
    (tmp_path / "mission.yaml").write_text("")
    (tmp_path / "out").mkdir()
    assert _complete(script, "new", "") == ["reach-avoid", "patrol", "map"]
    assert _complete(script, "completion", "") == ["bash", "zsh", "fish"]
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    stage = next(a for a in sub.choices["stage"]._actions if a.dest == "name")
    stages = [str(c) for c in stage.choices or ()]
    assert _complete(script, "stage", "") == stages
    # a flag's value is not the positional argument: the stage's name is still to come
    assert _complete(script, "stage", "-o", "out", "") == stages
    assert _complete(script, "stage", "--force", "") == stages
    # after the choice, or as a flag's value, file names again
    assert sorted(_complete(script, "stage", "plan", "")) == ["mission.yaml", "out", "tlmpc.bash"]
    assert _complete(script, "new", "map", "-o", "mi") == ["mission.yaml"]
    assert _complete(script, "import-map", "--start", "1", "2", "mi") == ["mission.yaml"]
    assert _complete(script, "new", "--", "p") == ["patrol"]


def test_zsh_and_fish_scripts_keep_file_names_whole_and_offer_flags_and_choices() -> None:
    zsh = _script("zsh")
    # zsh runs the bash function through bashcompinit, which has no mapfile: a read loop fills
    # COMPREPLY, never an unquoted $(...) that splits names at spaces
    assert "mapfile" not in zsh
    assert "COMPREPLY=($(" not in zsh
    assert "COMPREPLY=( $(" not in zsh
    assert "while IFS= read -r line" in zsh
    assert "printf '%q'" in zsh
    fish = _script("fish")
    names = " ".join(name.replace("_", "-") for name in COMMAND_MODULES)
    before = f"-n 'not __fish_seen_subcommand_from {names}'"
    for option in ("-l version", "-l help", "-s h"):
        assert f"complete -c tlmpc {before} {option}\n" in fish
    # -f: the templates only, no file names, until one is given
    assert (
        "complete -c tlmpc -f -n '__fish_seen_subcommand_from new; and not "
        "__fish_seen_subcommand_from reach-avoid patrol map' -a 'reach-avoid patrol map'\n"
    ) in fish
    assert "complete -c tlmpc -n '__fish_seen_subcommand_from new' -l output -r\n" in fish


def test_flag_values_and_repeated_choices_count_as_the_parser_counts(tmp_path: Path) -> None:
    # a parser of its own: no tlmpc command has a two-word flag before an argument with choices
    parser = argparse.ArgumentParser(prog="tlmpc")
    sub = parser.add_subparsers()
    command = sub.add_parser("pick")
    command.add_argument("--pair", nargs=2)
    command.add_argument("first", choices=("a", "b"))
    command.add_argument("rest", nargs="+", choices=("x", "y"))
    sub.add_parser("take").add_argument("path")
    script = tmp_path / "pick.bash"
    script.write_text(completion.bash_script(completion._commands(parser)))
    (tmp_path / "-odd.yaml").write_text("")
    assert _complete(script, "pick", "--pair", "1", "2", "") == ["a", "b"]
    assert _complete(script, "pick", "a", "") == ["x", "y"]
    assert _complete(script, "pick", "a", "x", "y", "") == ["x", "y"]
    # after `--` a word starting with `-` is an argument, never a flag
    assert _complete(script, "pick", "-") == ["-h", "--help", "--pair"]
    assert _complete(script, "pick", "--", "a", "x", "-") == []
    assert _complete(script, "take", "-") == ["-h", "--help"]
    assert _complete(script, "take", "--", "-") == ["-odd.yaml"]
