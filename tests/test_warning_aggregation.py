"""Warnings alike but for names and numbers are printed as one line, whatever their code.

The oracle knows which template made each warning (the template is the "kind"): the printed
lines must be one per kind that occurs twice or more among the warnings (one per warning for a
kind that occurs once), errors and notes one each, in the order of first occurrence; each
folded line names how many and every other member's names and numbers (up to the shown count).
"""

from __future__ import annotations

import io
import json

from hypothesis import given
from hypothesis import strategies as st

from tlmpc.base.errors import Diagnostic
from tlmpc.io.aggregate import SHOWN
from tlmpc.io.report import Reporter

#: Kinds of warning: code, severity, message template (slots {0}, {1}: a name, a number).
KINDS = [
    ("A011", "warning", "region '{0}' is not reachable from the start: piece {1}"),
    ("G021", "warning", "a passage only {1} wide at ({1}, 2.5), 40 times narrower than the map"),
    ("G021", "warning", "hole '{0}' touches the boundary"),
    ("M030", "warning", "key '{0}' is unknown and ignored"),
    ("I011", "note", "sensor '{0}' is never read after t={1}"),
    ("U120", "error", "region '{0}' is listed twice"),
]

names = st.text(alphabet="abcdefghijklmnopqrstuvwxyz_", min_size=1, max_size=6)
numbers = st.floats(min_value=0.001, max_value=1e6, allow_nan=False).map(lambda v: f"{v:.4g}")
items = st.lists(
    st.tuples(st.integers(0, len(KINDS) - 1), names, numbers, st.integers(1, 400)),
    max_size=40,
)


def _diagnostic(kind: int, name: str, number: str, line: int) -> Diagnostic:
    code, severity, template = KINDS[kind]
    return Diagnostic(
        code=code,
        severity=severity,  # type: ignore[arg-type]
        message=template.format(name, number),
        hint="look at it",
        file="mission.yaml",
        line=line,
    )


def _printed(diagnostics: list[Diagnostic], json_mode: bool = False) -> tuple[list[str], str]:
    out, err = io.StringIO(), io.StringIO()
    reporter = Reporter(command="compile", json=json_mode, out=out, err=err)
    reporter.diagnose(diagnostics)
    reporter.finish(0, {})
    lines = [line for line in err.getvalue().splitlines() if not line.startswith("  hint:")]
    return lines, out.getvalue()


@given(items)
def test_alike_warnings_print_as_one_line_per_kind(
    drawn: list[tuple[int, str, str, int]],
) -> None:
    diagnostics = [_diagnostic(*item) for item in drawn]
    lines, _ = _printed(diagnostics)
    # the oracle: the expected printed sequence, by kinds
    count = {k: sum(1 for d in drawn if d[0] == k) for k in range(len(KINDS))}
    expected: list[tuple[int, list[tuple[int, str, str, int]]]] = []
    placed: set[int] = set()
    for item in drawn:
        kind = item[0]
        if KINDS[kind][1] != "warning" or count[kind] == 1:
            expected.append((kind, [item]))
        elif kind not in placed:
            placed.add(kind)
            expected.append((kind, [d for d in drawn if d[0] == kind]))
    assert len(lines) == len(expected)
    for line, (kind, members) in zip(lines, expected, strict=True):
        code, severity, template = KINDS[kind]
        assert f"{severity}[{code}]" in line
        first = template.format(*members[0][1:3])
        assert first in line
        if len(members) > 1:
            assert f"{len(members)} warnings like this one" in line
            for _, name, number, _ in members[1 : SHOWN + 1]:
                if "{0}" in template:
                    assert f"'{name}'" in line
                if "{1}" in template:
                    assert number in line
            if len(members) - 1 > SHOWN:
                assert f"and {len(members) - 1 - SHOWN} more" in line


def test_the_json_envelope_keeps_every_warning() -> None:
    drawn = [(0, f"r{k}", "1", 3) for k in range(24)]
    _, out = _printed([_diagnostic(*item) for item in drawn], json_mode=True)
    listed = json.loads(out)["diagnostics"]
    assert [d["message"] for d in listed] == [
        f"region 'r{k}' is not reachable from the start: piece 1" for k in range(24)
    ]


def test_twenty_four_regions_fold_into_one_line() -> None:
    drawn = [(0, f"dock{k}", str(k % 3), 10 + k) for k in range(24)]
    lines, _ = _printed([_diagnostic(*item) for item in drawn])
    assert lines == [
        "mission.yaml:10: warning[A011]: 24 warnings like this one: region 'dock0' is not "
        "reachable from the start: piece 0; the others: 'dock1' 1 (line 11), 'dock2' 2 "
        "(line 12), 'dock3' 0 (line 13), 'dock4' 1 (line 14), 'dock5' 2 (line 15), 'dock6' 0 "
        "(line 16), 'dock7' 1 (line 17), 'dock8' 2 (line 18) and 15 more"
    ]


def test_notes_in_order_stay_as_they_are() -> None:
    # the environment's play: steps that differ only in numbers and names, read in order
    play = [
        Diagnostic(code="Q111", severity="note", message=f"the environment wins: {k}: in 'r{k}'")
        for k in range(5)
    ]
    lines, _ = _printed(play)
    assert lines == [f"<input>: note[Q111]: the environment wins: {k}: in 'r{k}'" for k in range(5)]
