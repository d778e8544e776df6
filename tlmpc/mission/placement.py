"""Line and column for diagnostics that a later stage locates only by a JSON path.

The stages after loading see the typed mission, not the YAML text, so a problem they find in
a value (``robot.disturbance`` too large for the mesh's corners) names the value by its JSON
path. Before such a diagnostic reaches the user, :func:`placed` reads the mission's text once
more and gives it the line and column of that value, so every diagnostic of the mission file
is printed as ``file:line:col``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from pathlib import Path as FilePath

from tlmpc.base.errors import Diagnostic
from tlmpc.io import json_places
from tlmpc.mission.yamlpos import Path, load_positioned


def parse_json_path(text: str) -> Path | None:
    """``("regions", "p1", 0)`` for ``$.regions.p1[0]``; None for text that is not one
    (:func:`tlmpc.io.json_places.parse_json_path`)."""
    keys = json_places.parse_json_path(text)
    return None if keys is None else tuple(keys)


def placed(
    diagnostics: Sequence[Diagnostic], source: str | None, text: str | None = None
) -> tuple[Diagnostic, ...]:
    """``diagnostics`` with a line and column for each one of the mission file ``source``
    that has a JSON path but no line (the rest unchanged, in the same order).

    ``text`` is the mission's YAML when it is not read from ``source``. When the text cannot
    be read or parsed any more (the file changed under the run), the diagnostics keep only
    their file and path.
    """

    def unplaced(diagnostic: Diagnostic) -> bool:
        return diagnostic.line is None and diagnostic.path is not None and diagnostic.file == source

    if source is None or not any(unplaced(d) for d in diagnostics):
        return tuple(diagnostics)
    if text is None:
        try:
            text = FilePath(source).read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError):
            return tuple(diagnostics)
    document = load_positioned(text, source, lazy=True)[0]
    if document is None:
        return tuple(diagnostics)
    result: list[Diagnostic] = []
    for diagnostic in diagnostics:
        path = (
            parse_json_path(diagnostic.path)
            if unplaced(diagnostic) and diagnostic.path is not None
            else None
        )
        if path is None:
            result.append(diagnostic)
            continue
        line, col = document.value_at(path)
        result.append(dataclasses.replace(diagnostic, line=line, col=col))
    return tuple(result)


__all__ = ["parse_json_path", "placed"]
