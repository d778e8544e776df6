"""``tlmpc completion bash|zsh|fish``: a shell completion script, generated from the parser."""

from __future__ import annotations

import argparse
import shlex
from dataclasses import dataclass
from typing import TextIO

NAME = "completion"
HELP = "print a shell completion script (bash, zsh or fish)"
DESCRIPTION = """\
Print a completion script for SHELL, generated from tlmpc's own command-line parser (so it
knows every command, flag and choice of this version):

  bash:  tlmpc completion bash > "$HOME/.local/share/bash-completion/completions/tlmpc"
  zsh:   echo 'eval "$(tlmpc completion zsh)"' >> "$HOME/.zshrc"
  fish:  tlmpc completion fish > "$HOME/.config/fish/completions/tlmpc.fish"

Commands complete after `tlmpc`, flags after `-` (tlmpc's own --help and --version too), a
flag's choices (compile --until, plot --format ...) after the flag, an argument with fixed
choices (new's templates, stage's names) to those choices only, and file names elsewhere."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the command's flags."""
    parser.add_argument("shell", choices=("bash", "zsh", "fish"), help="the shell")


@dataclass(frozen=True)
class Command:
    """What completion needs to know of one command.

    ``values`` counts the words each flag that takes a value consumes (so that a flag's value
    is not taken for a positional argument); ``slots`` holds each positional argument's
    choices, empty for a file name; ``repeats`` says the last slot takes any number of words.
    """

    help: str
    flags: list[str]
    choices: dict[str, list[str]]
    values: dict[str, int]
    slots: list[list[str]]
    repeats: bool


@dataclass(frozen=True)
class Commands:
    """tlmpc's own flags (``--help``, ``--version``) and every command, by name."""

    flags: list[str]
    commands: dict[str, Command]


def _value_count(action: argparse.Action) -> int:
    """How many words after the flag are its value (an optional value is taken as absent)."""
    if isinstance(action.nargs, int):
        return action.nargs
    return 0 if action.nargs in (argparse.OPTIONAL, argparse.ZERO_OR_MORE) else 1


def _commands(parser: argparse.ArgumentParser) -> Commands:
    """tlmpc's own flags, and each command's help, flags, flags' choices and positionals."""
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    helps = {action.dest: action.help or "" for action in sub._choices_actions}
    found = {}
    for name, command in sub.choices.items():
        flags: list[str] = []
        choices: dict[str, list[str]] = {}
        values: dict[str, int] = {}
        slots: list[list[str]] = []
        repeats = False
        for action in command._actions:
            words = [str(c) for c in action.choices] if action.choices else []
            if action.option_strings:
                flags.extend(action.option_strings)
                for flag in action.option_strings:
                    if words:
                        choices[flag] = words
                    if _value_count(action):
                        values[flag] = _value_count(action)
            else:
                count = action.nargs if isinstance(action.nargs, int) else 1
                slots.extend([words] * count)
                repeats = action.nargs in (argparse.ONE_OR_MORE, argparse.ZERO_OR_MORE)
        found[name] = Command(helps.get(name, ""), flags, choices, values, slots, repeats)
    own = [
        s
        for a in parser._actions
        if not isinstance(a, argparse._SubParsersAction)
        for s in a.option_strings
    ]
    return Commands(own, found)


# Helpers shared by every generated script.  Candidates are read one per line into COMPREPLY:
# `COMPREPLY=($(compgen ...))` would split a file named `my mission.yaml` in two (and
# glob-expand a name with `*`).  `mapfile` would do the same in bash, but zsh runs this script
# through bashcompinit, which has no `mapfile`, so a `read` loop serves both.  Each candidate
# gets the prefix $2: zsh replaces a whole `--flag=value` word, bash only what follows the `=`.
# File names are inserted as they are: bash (-o filenames) and zsh's bashcompinit (compadd -f)
# each quote them themselves.
_BASH_HELPERS = r"""_tlmpc_reply() {
  local line
  while IFS= read -r line; do
    [ -n "$line" ] && COMPREPLY+=("${2-}$line")
  done <<< "$1"
}
_tlmpc_words() {
  _tlmpc_reply "$(compgen -W "$1" -- "$2")" "${3-}"
  # fixed words, not file names: no slash after one that happens to name a directory
  if [ -n "${BASH_VERSION-}" ]; then compopt +o filenames 2>/dev/null; fi
}
_tlmpc_files() {
  if [ -n "${2-}" ] && [ -n "${ZSH_VERSION-}" ]; then
    # zsh's compgen -f lists the files starting with the whole word (`--log=ma`), not $1
    local name
    for name in "$1"*; do
      if [ -e "$name" ]; then COMPREPLY+=("$2$name"); fi
    done
    return
  fi
  _tlmpc_reply "$(compgen -f -- "$1")" "${2-}"
}"""


def _pattern(*words: str) -> str:
    """A bash ``case`` pattern matching the words joined by a space, literally."""
    return shlex.quote(" ".join(words))


def bash_script(commands: Commands) -> str:
    """The bash completion function (zsh loads it through bashcompinit)."""
    table = commands.commands
    lines = [
        "# tlmpc completion for bash (generated by `tlmpc completion bash`)",
        _BASH_HELPERS,
        "_tlmpc() {",
        "  # the words up to the cursor as tlmpc reads them: bash splits `--flag=value` at the `=`",
        "  # (COMP_WORDBREAKS) into three words, zsh keeps one; glue bash's back together",
        "  local -a args=()",
        "  local j=0 k=-1 glue=0 w",
        '  while [ "$j" -le "$COMP_CWORD" ]; do',
        '    w="${COMP_WORDS[j]}"',
        "    j=$((j + 1))",
        '    if [ "$w" = "=" ] && [ "$k" -gt 0 ]; then',
        '      case "${args[k]}" in --) ;; -?*) glue=2;; esac  # the `=`, then the value',
        "    fi",
        '    if [ "$glue" -gt 0 ]; then',
        '      args[k]="${args[k]}$w"',
        "      glue=$((glue - 1))",
        "      continue",
        "    fi",
        "    k=$((k + 1))",
        '    args[k]="$w"',
        "  done",
        '  local cur="${args[k]}" prev="${args[k-1]}" cword=$k',
        '  local cmd="" i=1 n=0 skip=0 options=1 given',
        "  # the flag whose value is being completed, that value, and what goes before each",
        "  # candidate (bash completes after the `=` only, zsh the whole word)",
        '  local flag="$prev" value="$cur" before=""',
        '  case "$cur" in',
        "    --) ;;",
        '    -?*=*) flag="${cur%%=*}"',
        '      if [ "${COMP_WORDS[COMP_CWORD]}" = "$cur" ]; then',
        '        value="${cur#*=}"; before="$flag="',
        '      elif [ "${COMP_WORDS[COMP_CWORD]}" = "=" ]; then value=""',
        '      else value="${COMP_WORDS[COMP_CWORD]}"; fi;;',
        "  esac",
        "  COMPREPLY=()",
        "  # the command is the first word that is not a flag (tlmpc's own flags take no value)",
        '  while [ "$i" -lt "$cword" ]; do',
        '    w="${args[i]}"',
        "    i=$((i + 1))",
        '    case "$w" in -*) ;; *) cmd="$w"; break;; esac',
        "  done",
        '  if [ -z "$cmd" ]; then',
        '    case "$cur" in',
        f'      -*) _tlmpc_words {shlex.quote(" ".join(commands.flags))} "$cur";;',
        f'      *) _tlmpc_words {shlex.quote(" ".join(table))} "$cur";;',
        "    esac",
        "    return",
        "  fi",
        '  case "$cmd $flag" in',
    ]
    for name, command in table.items():
        for flag, values in command.choices.items():
            lines.append(
                f"    {_pattern(name, flag)}) _tlmpc_words {shlex.quote(' '.join(values))} "
                '"$value" "$before"; return;;'
            )
    lines += [
        "  esac",
        "  # which positional argument the current word is: flags and their values do not count",
        '  while [ "$i" -lt "$cword" ]; do',
        '    w="${args[i]}"',
        "    i=$((i + 1))",
        '    if [ "$skip" -gt 0 ]; then skip=$((skip - 1)); continue; fi',
        '    if [ "$options" = 1 ]; then',
        '      case "$w" in',
        "        --) options=0; continue;;",
        "        -?*)",
        "          # `--flag=value` holds the flag's first value",
        '          given=0; case "$w" in *=*) given=1; w="${w%%=*}";; esac',
        '          case "$cmd $w" in',
    ]
    for name, command in table.items():
        by_count: dict[int, list[str]] = {}
        for flag, count in command.values.items():
            by_count.setdefault(count, []).append(_pattern(name, flag))
        for count, patterns in sorted(by_count.items()):
            lines.append(f"            {'|'.join(patterns)}) skip=$(({count} - given));;")
    lines += [
        "          esac",
        "          continue;;",
        "      esac",
        "    fi",
        "    n=$((n + 1))",
        "  done",
        "  # the current word is a flag's value (a flag with choices was answered above)",
        '  if [ "$skip" -gt 0 ] || [ "$flag" != "$prev" ]; then',
        '    _tlmpc_files "$value" "$before"; return',
        "  fi",
        '  if [ "$options" = 1 ]; then',
        '    case "$cur" in',
        '      -*) case "$cmd" in',
    ]
    for name, command in table.items():
        lines.append(
            f"          {shlex.quote(name)}) _tlmpc_words {shlex.quote(' '.join(command.flags))} "
            '"$cur";;'
        )
    lines += [
        "        esac",
        "        return;;",
        "    esac",
        "  fi",
        "  # an argument with fixed choices takes nothing else; any other is a file",
        '  case "$cmd $n" in',
    ]
    for name, command in table.items():
        for index, values in enumerate(command.slots):
            if values:
                pattern = _pattern(name, str(index))
                if command.repeats and index == len(command.slots) - 1:
                    pattern = _pattern(name, "") + "*"
                lines.append(
                    f'    {pattern}) _tlmpc_words {shlex.quote(" ".join(values))} "$cur"; return;;'
                )
    lines += [
        "  esac",
        '  _tlmpc_files "$cur"',
        "}",
        "complete -o filenames -F _tlmpc tlmpc",
    ]
    return "\n".join(lines) + "\n"


def zsh_script(commands: Commands) -> str:
    """The bash function, loaded in zsh through bashcompinit."""
    return (
        "# tlmpc completion for zsh (generated by `tlmpc completion zsh`)\n"
        "autoload -U +X bashcompinit && bashcompinit\n" + bash_script(commands)
    )


#: fish functions the ``complete`` lines' conditions call: the command is the first word after
#: ``tlmpc`` that is not a flag (``__fish_seen_subcommand_from`` would also see a later word, a
#: stage's name ``plot`` or a file named ``verify``, and offer that command's flags).
_FISH_HELPERS = """\
function __fish_tlmpc_command --description 'the tlmpc command being completed'
    for word in (commandline -opc)[2..-1]
        if not string match -q -- '-*' $word
            echo $word
            return
        end
    end
    false
end
function __fish_tlmpc_using --description 'whether the tlmpc command is $argv[1]'
    set -l command (__fish_tlmpc_command)
    and test "$command" = $argv[1]
end"""


def fish_script(commands: Commands) -> str:
    """``complete`` lines for fish."""
    lines = ["# tlmpc completion for fish (generated by `tlmpc completion fish`)", _FISH_HELPERS]
    before = "-n 'not __fish_tlmpc_command'"
    for flag in commands.flags:
        lines.append(f"complete -c tlmpc {before} {_fish_option(flag)}")
    for name, command in commands.commands.items():
        lines.append(
            f"complete -c tlmpc -f {before} -a {shlex.quote(name)} -d {shlex.quote(command.help)}"
        )
        using = f"__fish_tlmpc_using {shlex.quote(name)}"
        seen = f"-n {shlex.quote(using)}"
        for flag in command.flags:
            values = command.choices.get(flag)
            if values:
                extra = f" -xa {shlex.quote(' '.join(values))}"
            else:
                # -r: the next word is the flag's value (a file), not a positional argument
                extra = " -r" if flag in command.values else ""
            lines.append(f"complete -c tlmpc {seen} {_fish_option(flag)}{extra}")
        for index, values in enumerate(command.slots):
            if not values:
                continue
            words = " ".join(values)
            if index == 0:
                # only these words (-f: no file names) until one of them is given
                condition = f"{using}; and not __fish_seen_subcommand_from {words}"
                lines.append(
                    f"complete -c tlmpc -f -n {shlex.quote(condition)} -a {shlex.quote(words)}"
                )
            else:  # fish cannot count positional arguments: offer the words beside files
                lines.append(f"complete -c tlmpc {seen} -a {shlex.quote(words)}")
    return "\n".join(lines) + "\n"


def _fish_option(flag: str) -> str:
    """A flag as fish's ``complete`` names it (``-l long`` or ``-s x``)."""
    return f"-l {flag[2:]}" if flag.startswith("--") else f"-s {flag[1:]}"


def run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Print the script (the whole parser comes from the command line's own factory)."""
    from tlmpc.base.errors import EXIT_OK
    from tlmpc.io.report import Reporter

    commands = _commands(args._full_parser())
    script = {"bash": bash_script, "zsh": zsh_script, "fish": fish_script}[args.shell](commands)
    return Reporter.for_args(args, out, err).finish(EXIT_OK, text=script)
