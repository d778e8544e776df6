"""Run the commands the docs show and compare (or rewrite) the output shown under them.

A shown run is a ```console block: lines starting with ``$ `` are commands, the lines after
each command are its output (stdout and stderr as a terminal would interleave them).  Blocks
of one page run in order in one scratch directory in which ``specs/`` is this repository's.
A page may need a run first, declared in an HTML comment: ``<!-- setup: tlmpc compile ... -->``;
a ```yaml block right after ``<!-- file: NAME -->`` is written to ``NAME`` in the scratch
directory before the page's commands run (the README's `mission.yaml`).

Numbers that depend on the machine rather than on the code — stage seconds and the plot's
byte sizes — are normalised before comparing.

    python tests/docs_outputs.py          # report differences
    python tests/docs_outputs.py --write  # rewrite the shown outputs from the code
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PAGES = (
    "README.md",
    "docs/quickstart.md",
    "docs/task-phrases.md",
    "docs/verify.md",
    "docs/errors.md",
    "docs/cli.md",
)

_BLOCK = re.compile(r"```console\n(.*?)```", re.DOTALL)
_SETUP = re.compile(r"<!-- setup: (.*?) -->")
_FILE = re.compile(r"<!-- file: (\S+) -->\s*```yaml\n(.*?)```", re.DOTALL)


@dataclass(frozen=True)
class ShownRun:
    """One command of a page and the output the page shows for it."""

    page: str
    command: str
    shown: str


def shown_runs(page: str) -> list[ShownRun]:
    """The commands and shown outputs of ``page``, in order."""
    runs: list[ShownRun] = []
    for block in _BLOCK.findall((ROOT / page).read_text()):
        command: str | None = None
        lines: list[str] = []
        for line in block.splitlines():
            if line.startswith("$ "):
                if command is not None:
                    runs.append(ShownRun(page, command, "\n".join(lines)))
                command, lines = line[2:], []
            else:
                lines.append(line)
        if command is not None:
            runs.append(ShownRun(page, command, "\n".join(lines)))
    return runs


def normalise(text: str) -> str:
    """Machine-dependent numbers out: stage seconds, plot byte sizes."""
    text = re.sub(r"^(\[\d+/\d+\] \S+\s+)\d+\.\d+ s", r"\1#.### s", text, flags=re.MULTILINE)
    text = re.sub(r"(png|svg) bytes \d+", r"\1 bytes #", text)
    return text.rstrip("\n")


def run(command: str, cwd: Path) -> str:
    """The output of one shown command (``tlmpc`` is this checkout's)."""
    argv = shlex.split(command)
    if argv[0] != "tlmpc":
        raise ValueError(f"docs may only show tlmpc commands here, not {command!r}")
    env = dict(os.environ, PYTHONPATH=str(ROOT), PYTHONUNBUFFERED="1", COLUMNS="100")
    result = subprocess.run(
        [sys.executable, "-m", "tlmpc", *argv[1:]],
        cwd=cwd,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        check=False,
    )
    return result.stdout


def page_outputs(page: str) -> list[tuple[ShownRun, str]]:
    """Every shown run of ``page`` with the output the code gives now."""
    with tempfile.TemporaryDirectory(prefix="tlmpc-docs-") as scratch:
        cwd = Path(scratch)
        (cwd / "specs").symlink_to(ROOT / "specs")
        (cwd / "tests").symlink_to(ROOT / "tests")
        text = (ROOT / page).read_text()
        for name, content in _FILE.findall(text):
            (cwd / name).write_text(content)
        for setup in _SETUP.findall(text):
            run(setup, cwd)
        return [(shown, run(shown.command, cwd)) for shown in shown_runs(page)]


def rewrite(page: str) -> bool:
    """Replace the page's shown outputs by the real ones; True when something changed."""
    outputs = iter(page_outputs(page))
    text = (ROOT / page).read_text()

    def block(match: re.Match[str]) -> str:
        body: list[str] = []
        for line in match.group(1).splitlines():
            if line.startswith("$ "):
                shown, actual = next(outputs)
                assert shown.command == line[2:]
                body.append(line)
                body.extend(actual.rstrip("\n").splitlines())
        return "```console\n" + "\n".join(body) + "\n```"

    new = _BLOCK.sub(block, text)
    changed = new != text
    (ROOT / page).write_text(new)
    return changed


def main() -> int:
    """Report or (``--write``) fix every page's shown outputs."""
    write = "--write" in sys.argv[1:]
    status = 0
    for page in PAGES:
        if write:
            print(f"{page}: {'rewritten' if rewrite(page) else 'up to date'}")
            continue
        for shown, actual in page_outputs(page):
            if normalise(actual) != normalise(shown.shown):
                status = 1
                print(f"{page}: $ {shown.command}\n--- shown\n{shown.shown}\n--- actual\n{actual}")
    return status


if __name__ == "__main__":
    sys.exit(main())
