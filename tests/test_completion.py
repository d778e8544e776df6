"""`tlmpc completion`: the bash script, run in a real bash, completes what the parser accepts."""

from __future__ import annotations

import argparse
import io
import shlex
import shutil
import subprocess
from pathlib import Path

import pytest
from ci_oracles import oracle_required

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
    fish = _script("fish")
    before = "-n 'not __fish_tlmpc_command'"
    for option in ("-l version", "-l help", "-s h"):
        assert f"complete -c tlmpc {before} {option}\n" in fish
    # -f: the templates only, no file names, until one is given
    assert (
        "complete -c tlmpc -f -n '__fish_tlmpc_using new; and not "
        "__fish_seen_subcommand_from reach-avoid patrol map' -a 'reach-avoid patrol map'\n"
    ) in fish
    assert "complete -c tlmpc -n '__fish_tlmpc_using new' -l output -r\n" in fish


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


def test_a_flag_given_as_flag_equals_value_counts_as_the_parser_counts(tmp_path: Path) -> None:
    # bash splits `--out=x` at the `=` (COMP_WORDBREAKS): the words the function sees
    script = _bash_script(tmp_path)
    (tmp_path / "mission.yaml").write_text("")
    stages = _complete(script, "stage", "")
    assert _complete(script, "stage", "--out", "=", "x", "") == stages
    assert _complete(script, "stage", "-o", "=", "x", "pla") == ["plan"]
    assert _complete(script, "plot", "--format", "=", "s") == ["svg"]
    # the cursor right after the `=`: bash completes the empty word after it
    assert _complete(script, "plot", "--format", "=") == ["svg", "png", "both"]
    assert _complete(script, "compile", "--until", "=", "abs") == ["abstraction"]
    assert _complete(script, "check", "--json", "--explain", "=", "mi") == ["mission.yaml"]
    # a value holding `=` is still one flag's value
    assert _complete(script, "stage", "--out", "=", "a", "=", "b", "pla") == ["plan"]
    # `--` alone is not a flag to glue to
    assert _complete(script, "new", "--", "p") == ["patrol"]


ZSH = shutil.which("zsh")

# Types each line into an interactive zsh (in a zpty), presses TAB, and prints the edit buffer:
# what a user of the documented install sees.  zpty -r waits for the printed marker, so no
# delay is guessed.
_ZSH_DRIVER = r"""
zmodload zsh/zpty || exit 3
script=$1 dir=$2
shift 2
zpty tlmpc_z zsh -f -i
zpty -w tlmpc_z "PS1='> '; unsetopt beep; LISTMAX=100000; cd ${(q)dir}"
zpty -w tlmpc_z "autoload -U compinit && compinit -u -D && eval \"\$(<${(q)script})\""
zpty -w tlmpc_z "tlmpc_dump() { zle -I; print -r -- \"@@[\$BUFFER]@@\"; BUFFER=''; }"
zpty -w tlmpc_z "zle -N tlmpc_dump; bindkey '^X' tlmpc_dump; print tlmpc-ready-\$((6*7))"
zpty -r tlmpc_z ignored '*tlmpc-ready-42*' || exit 3
local out
for line in "$@"; do
  zpty -w -n tlmpc_z "$line"$'\t\C-x'
  zpty -r tlmpc_z out '*@@\[*\]@@*' || exit 3
  out=${out##*@@\[}
  print -r -- "${out%\]@@*}"
done
zpty -d tlmpc_z
"""


def _zsh_buffers(directory: Path, *lines: str) -> list[str]:
    """The command line after typing each of ``lines`` and TAB in a real zsh."""
    assert ZSH is not None
    script = directory / "tlmpc.zsh"
    script.write_text(_script("zsh"))
    driver = directory / "drive.zsh"
    driver.write_text(_ZSH_DRIVER)
    result = subprocess.run(
        [ZSH, "-f", str(driver), str(script), str(directory), *lines],
        capture_output=True,
        text=True,
        timeout=120,  # a guard against a hung pty, not a budget
    )
    if result.returncode == 3:
        pytest.skip("zsh has no zpty module")
    assert result.returncode == 0, result.stderr
    return result.stdout.splitlines()


@oracle_required(ZSH is not None, "zsh")
def test_zsh_inserts_file_names_quoted_once(tmp_path: Path) -> None:
    assert ZSH is not None
    for name in ("zz file1", "a$b*c", "it's"):
        (tmp_path / name).write_text("")
    buffers = _zsh_buffers(
        tmp_path,
        "tlmpc plot zz",
        "tlmpc check a",
        "tlmpc view it",
        "tlmpc plot --log=zz",
        "tlmpc stage --out=x pla",
        "tlmpc plot --format=s",
        "tlmpc compile --until=abs",
    )
    # zsh reads each completed word back as the file's own name (an oracle independent of
    # the script: zsh's own word splitting and quote removal)
    words = [
        subprocess.run(
            [ZSH, "-f", "-c", "print -rl -- ${(Q)${(z)1}}", "zsh", line],
            capture_output=True,
            text=True,
            check=True,
        ).stdout.splitlines()
        for line in buffers
    ]
    assert words[0] == ["tlmpc", "plot", "zz file1"]
    assert words[1] == ["tlmpc", "check", "a$b*c"]
    assert words[2] == ["tlmpc", "view", "it's"]
    assert words[3] == ["tlmpc", "plot", "--log=zz file1"]
    assert words[4] == ["tlmpc", "stage", "--out=x", "plan"]
    assert words[5] == ["tlmpc", "plot", "--format=svg"]
    assert words[6] == ["tlmpc", "compile", "--until=abstraction"]


FISH = shutil.which("fish")


def _fish_complete(directory: Path, line: str) -> list[str]:
    assert FISH is not None
    script = directory / "tlmpc.fish"
    script.write_text(_script("fish"))
    program = f"source {shlex.quote(str(script))}; complete -C {shlex.quote(line)}"
    result = subprocess.run(
        [FISH, "--no-config", "-c", program], capture_output=True, text=True, check=True
    )
    return sorted(entry.split("\t")[0] for entry in result.stdout.splitlines())


@oracle_required(FISH is not None, "fish")
def test_fish_offers_the_flags_of_the_command_word_only(tmp_path: Path) -> None:
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))

    def flags(name: str, start: str) -> list[str]:
        found = {s for a in sub.choices[name]._actions for s in a.option_strings}
        return sorted(s for s in found if s.startswith(start))

    # `plot` and `verify` are stage names and command names; `verify` may name a file
    assert _fish_complete(tmp_path, "tlmpc stage plot -") == flags("stage", "-")
    assert _fish_complete(tmp_path, "tlmpc stage verify --") == flags("stage", "--")
    assert _fish_complete(tmp_path, "tlmpc check verify --") == flags("check", "--")
    assert _fish_complete(tmp_path, "tlmpc --help plot --f") == flags("plot", "--f")
    assert _fish_complete(tmp_path, "tlmpc -") == sorted(
        s
        for a in parser._actions
        if not isinstance(a, argparse._SubParsersAction)
        for s in a.option_strings
    )
