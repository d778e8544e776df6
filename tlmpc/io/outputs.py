"""The output policy every writer follows, and the text every exported name becomes.

* A command never writes over one of the files it reads (:func:`refuse_input_as_output`,
  U043): ``view -o LOG``, ``export -o OUT/mission.json``, ``import-map MAP.yaml -o MAP.yaml``
  would otherwise replace their own input with their output.
* Files are replaced atomically (:func:`tlmpc.io.outdir.replace_file`); a user's file in a
  folder tlmpc did not write is replaced only with ``--force`` (U012).
* A name (a mission's, a region's, a frame's) that goes into exported text is
  :func:`plain_name`: control characters, newlines and invisible direction controls become
  visible escapes, so a name can neither add a line to a CSV or YAML file nor reorder what a
  reader sees; :func:`csv_cell` also neutralises a cell a spreadsheet would run as a formula.
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterable
from pathlib import Path

from tlmpc.base.errors import UsageError, error, is_unsafe_char, printable


def plain_name(text: str) -> str:
    """``text`` on one line: control, newline and direction characters escaped."""
    return printable(text, keep="")


def has_unsafe_chars(text: str) -> bool:
    """Whether ``text`` holds a character :func:`plain_name` would escape."""
    return not text.isprintable() and any(is_unsafe_char(ch) for ch in text)


#: First characters that make a spreadsheet read a cell as a formula (``=``, ``+``, ``-``,
#: ``@``) or that some spreadsheets strip before doing so (tab, carriage return).
_FORMULA_START = ("=", "+", "-", "@", "\t", "\r")


def csv_cell(text: str) -> str:
    """``text`` as one CSV cell: on one line, a leading formula character neutralised by a
    ``'`` (the spreadsheet convention for "this is text"), quoted when it holds a separator
    or a quote."""
    cell = plain_name(text)
    if cell.startswith(_FORMULA_START):
        cell = "'" + cell
    if any(ch in cell for ch in ",;\"'\t "):
        cell = '"' + cell.replace('"', '""') + '"'
    return cell


def yaml_float(value: float) -> str:
    """A float as PyYAML's SafeRepresenter writes it: ``repr``, with ``.0`` before a bare
    exponent (YAML 1.1 reads ``1e-12`` as text: its floats need a decimal point)."""
    if value != value:
        return ".nan"
    if value in (math.inf, -math.inf):
        return ".inf" if value > 0 else "-.inf"
    text = repr(float(value)).lower()
    if "." not in text and "e" in text:
        text = text.replace("e", ".0e", 1)
    return text


def same_file(a: Path, b: Path) -> bool:
    """Whether ``a`` and ``b`` name one file (through any path or link; by their absolute
    paths when either is missing)."""
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.abspath(a) == os.path.abspath(b)


def refuse_input_as_output(output: Path, inputs: Iterable[Path | None], flag: str = "-o") -> None:
    """Refuse (U043, exit 2) an output path that names one of the command's inputs (the same
    file, through any path or link): writing it would replace what is being read."""
    for source in inputs:
        if source is None:
            continue
        if same_file(output, source):
            raise UsageError(
                error(
                    "U043",
                    f"{flag} {plain_name(str(output))} is an input of this command "
                    f"({plain_name(str(source))}); it would be overwritten",
                    hint=f"choose another {flag} path",
                    file=str(output),
                )
            )
