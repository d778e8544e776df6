"""One line for many warnings of one kind.

A map with dozens of racks gives dozens of warnings that differ only in a name, a number or a
line ("region 'rack7' is not reachable...", "a passage only 0.05 wide at (3, 4)...").  Printed
one by one they bury everything else.  :func:`aggregate` folds the warnings of one report that
share their code, file and *shape* (the message and hint with every quoted name and every
number taken out) into one diagnostic: the first one's text, how many there are, and what
differs in the others.  Errors are never folded: each is a thing to fix at its place; nor are
notes: they explain an error or a warning, often as steps in order (the environment's play).
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import replace

from tlmpc.base.errors import Diagnostic

#: The parts of a message that vary between warnings of one kind: quoted names, numbers.
SLOT = re.compile(
    r"'(?:[^'\\]|\\.)*'"
    r'|"(?:[^"\\]|\\.)*"'
    r"|(?<![\w.])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?![\w.])"
)

#: How many of the others an aggregated message lists by what differs.
SHOWN = 8


def shape(text: str | None) -> str | None:
    """``text`` with every quoted name and every number replaced by one placeholder."""
    return None if text is None else SLOT.sub("\x00", text)


def _key(diagnostic: Diagnostic) -> tuple[object, ...]:
    return (
        diagnostic.code,
        diagnostic.severity,
        diagnostic.file,
        diagnostic.path is None,
        shape(diagnostic.message),
        shape(diagnostic.hint),
    )


def aggregate(diagnostics: Sequence[Diagnostic]) -> list[Diagnostic]:
    """The diagnostics with each group of two or more alike warnings folded into one, at the
    place of the group's first member; errors, notes and lone warnings unchanged."""
    groups: dict[tuple[object, ...], list[Diagnostic]] = {}
    for diagnostic in diagnostics:
        if diagnostic.severity == "warning":
            groups.setdefault(_key(diagnostic), []).append(diagnostic)
    result = []
    for diagnostic in diagnostics:
        if diagnostic.severity != "warning":
            result.append(diagnostic)
            continue
        group = groups[_key(diagnostic)]
        if len(group) == 1:
            result.append(diagnostic)
        elif group[0] is diagnostic:
            result.append(_folded(group))
    return result


def _folded(group: list[Diagnostic]) -> Diagnostic:
    """One diagnostic for the group: the first one's text, then what differs in the others."""
    first = group[0]
    slots = [SLOT.findall(d.message) for d in group]
    varying = [k for k in range(len(slots[0])) if len({tuple(s)[k] for s in slots}) > 1]
    lines_differ = len({d.line for d in group}) > 1
    others = []
    for diagnostic, values in zip(group[1:], slots[1:], strict=True):
        summary = " ".join(values[k] for k in varying) or "the same"
        if lines_differ and diagnostic.line is not None:
            summary += f" (line {diagnostic.line})"
        others.append(summary)
    listed = ", ".join(others[:SHOWN])
    if len(others) > SHOWN:
        listed += f" and {len(others) - SHOWN} more"
    kind = "warnings" if first.severity == "warning" else "notes"
    message = f"{len(group)} {kind} like this one: {first.message}; the others: {listed}"
    return replace(first, message=message)
