"""``tlmpc new TEMPLATE [-o FILE]``: write a mission to start from."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TextIO

NAME = "new"
HELP = "write a mission template (reach-avoid, patrol, map) to start from"
DESCRIPTION = """\
Write a small mission of the kind TEMPLATE names, ready to edit: reach-avoid (go somewhere
without entering a region, come back), patrol (visit places again and again) or map (a mission
on a ROS occupancy-grid map).  The file starts with a yaml-language-server line naming the
mission schema installed with tlmpc, so editors with a YAML language server (VS Code's YAML
extension, Neovim, Helix ...) complete and check the keys as you type.  Without -o the mission
is printed.  With -o, map also writes the map it names beside the mission (an empty room,
FILE-map.yaml and FILE-map.pgm after FILE's name, to replace with your own), so the mission
compiles as written.  An existing file is never overwritten (exit 2)."""

TEMPLATES = ("reach-avoid", "patrol", "map")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the command's flags."""
    parser.add_argument("template", choices=TEMPLATES, help="which mission to start from")
    # a string, not a Path: Path drops the trailing "/" that says the user named a directory
    parser.add_argument("-o", "--output", help="the file to write (default: print)")


def schema_line() -> str:
    """The modeline that points a YAML language server at the installed mission schema."""
    from tlmpc.io.schema_check import schema_dir

    return f"# yaml-language-server: $schema={(schema_dir() / 'mission.schema.json').as_uri()}\n"


# The map template's own line naming its map: the one line `tlmpc new map -o FILE` rewrites
# to the map it writes beside FILE.
MAP_LINE = "workspace: {map: map.yaml}\n"

# The map written beside the map template: a 4 m x 4 m room (40 x 40 cells of 0.1 m, walls one
# cell thick) with its lower-left corner at (-1, -1), around the template's start (0, 0) and
# dock [1, 2] x [1, 2].
_CELLS = 40
_RESOLUTION = 0.1
_ORIGIN = (-1.0, -1.0, 0.0)


def template_text(name: str, map_name: str | None = None) -> str:
    """The template ``name`` with the schema line on top; ``map_name``, for the map template,
    is the map file the mission names instead of ``map.yaml``."""
    from importlib import resources

    body = (resources.files("tlmpc.templates") / f"{name}.yaml").read_text(encoding="utf-8")
    if map_name is not None:
        body = body.replace(MAP_LINE, f"workspace: {{map: {yaml_string(map_name)}}}\n")
    return schema_line() + body


def yaml_string(text: str) -> str:
    """``text`` as a double-quoted YAML scalar on one line that reads back as ``text`` exactly
    (spaces, colons, quotes, control characters and characters beyond U+FFFF included).

    PyYAML's own emitter writes it, so every escape is one YAML defines (``\\U0001F600``
    for an emoji: a JSON string's surrogate pair ``\\ud83d\\ude00`` is not a YAML
    character)."""
    import math

    import yaml

    return yaml.safe_dump(text, default_style='"', allow_unicode=True, width=math.inf).rstrip("\n")


def map_files(mission: Path) -> tuple[Path, Path]:
    """The map YAML and image that ``tlmpc new map -o mission`` writes beside ``mission``:
    named after it, so two missions in one folder get a map each."""
    stem = mission.stem or mission.name
    return mission.with_name(f"{stem}-map.yaml"), mission.with_name(f"{stem}-map.pgm")


def map_image() -> bytes:
    """The room's occupancy grid as a binary PGM: 254 free, 0 occupied (walls at the edge)."""
    rows = []
    for row in range(_CELLS):
        edge = row in (0, _CELLS - 1)
        cells = [0 if edge or col in (0, _CELLS - 1) else 254 for col in range(_CELLS)]
        rows.append(bytes(cells))
    return f"P5\n{_CELLS} {_CELLS}\n255\n".encode("ascii") + b"".join(rows)


def map_metadata(image: Path) -> str:
    """The map_server YAML of the room, naming ``image`` (beside it)."""
    x, y, yaw = _ORIGIN
    return (
        "# The map of `tlmpc new map`: an empty room to replace with your robot's map.\n"
        f"image: {yaml_string(image.name)}\n"
        f"resolution: {_RESOLUTION}\n"
        f"origin: [{x}, {y}, {yaw}]\n"
        "negate: 0\n"
        "occupied_thresh: 0.65\n"
        "free_thresh: 0.196\n"
    )


def _file_name(output: str) -> Path:
    """``-o OUTPUT`` as the file to write; refused (U093) when it names no file: empty, a
    directory (``dir/``, ``.``, ``..``, ``/``), where a mission cannot be written."""
    import os

    from tlmpc.base.errors import UsageError, error

    if os.path.basename(output) in ("", ".", ".."):
        raise UsageError(
            error(
                "U093",
                f"cannot write {output!r}: it names a directory or nothing, not a file",
                hint="give the mission's file name with -o, such as -o mission.yaml",
                file=output or None,
            )
        )
    return Path(output)


def run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Print the template or write it to a new file."""
    from tlmpc.base.errors import EXIT_OK, UsageError, error
    from tlmpc.io.outdir import replace_file
    from tlmpc.io.report import Reporter

    reporter = Reporter.for_args(args, out, err)
    if args.output is None:
        return reporter.finish(EXIT_OK, text=template_text(args.template))
    target = _file_name(args.output)
    written: dict[Path, bytes]
    if args.template == "map":
        # the mission names a map: write one beside it, or the mission does not compile
        map_yaml, image = map_files(target)
        written = {
            image: map_image(),
            map_yaml: map_metadata(image).encode("utf-8"),
            target: template_text("map", map_yaml.name).encode("utf-8"),
        }
    else:
        written = {target: template_text(args.template).encode("utf-8")}
    # every file checked before any is written (the mission first, the name the user gave)
    for path in sorted(written, key=lambda p: p != target):
        if path.exists() or path.is_symlink():
            raise UsageError(
                error(
                    "U094",
                    f"{path} exists: tlmpc new never overwrites a file",
                    hint="choose another name with -o, or remove the file first",
                    file=str(path),
                )
            )
    if not target.parent.is_dir():
        raise UsageError(
            error(
                "U093",
                f"cannot write {target}: {target.parent} is not a directory",
                hint="create the directory first, or choose another file with -o",
                file=str(target),
            )
        )
    for path, data in written.items():  # the mission last: it names the others
        replace_file(path, data)
    if len(written) > 1:
        reporter.note(f"wrote the map {', '.join(str(p) for p in written if p != target)}")
    reporter.note(f"wrote {target}: edit it, then `tlmpc check {_shell_word(target)}`")
    return reporter.finish(EXIT_OK)


def _shell_word(path: Path) -> str:
    """``path`` as one word a POSIX shell passes to tlmpc as that file: quoted when it holds
    spaces, quotes or wildcards, and not taken for a flag when it starts with ``-``."""
    import shlex

    name = str(path)
    return shlex.quote(f"./{name}" if name.startswith("-") else name)
