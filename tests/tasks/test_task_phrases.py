"""Task phrases compile to the documented LTL (the table in docs/task-phrases.md)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tlmpc.base.errors import InvalidInputError
from tlmpc.ltl import parse_ltl, to_text
from tlmpc.tasks import compile_phrase, compile_phrases

GROUPS = {"rooms": ["r1", "r2", "r3"]}
TABLE = [
    ("visit a", "F a"),
    ("visit a then b then c", "F(a & F(b & F c))"),
    ("visit a, b and c", "F a & F b & F c"),
    ("avoid a, b", "G !a & G !b"),
    ("never visit a", "G !a"),
    ("avoid a until b", "!a U b"),
    ("visit a then b while avoiding c", "F(a & F b) & G !c"),
    ("visit b while avoiding c, d", "F b & G !c & G !d"),
    ("visit a, b and c then go to d", "F(a & F d) & F(b & F d) & F(c & F d)"),
    ("visit all rooms then d", "F(r1 & F d) & F(r2 & F d) & F(r3 & F d)"),
    ("patrol a, b", "G F a & G F b"),
    ("visit a infinitely often", "G F a"),
    ("stay in a", "F G a"),
    ("eventually stay in a", "F G a"),
    ("always stay in a", "G a"),
    ("whenever a, visit b", "G(a -> F b)"),
    ("visit a then return to h", "F(a & F h)"),
    ("visit all rooms", "F r1 & F r2 & F r3"),
    ("visit any rooms", "F(r1 | r2 | r3)"),
]


@pytest.mark.parametrize(("phrase", "ltl"), TABLE)
def test_phrase_compiles_to_documented_ltl(phrase: str, ltl: str) -> None:
    assert compile_phrase(phrase, groups=GROUPS) == parse_ltl(ltl)


@pytest.mark.parametrize(
    "phrase",
    [
        "visit p2 then p3 then p4 then return to p1 while avoiding p2 and p3",
        "Visit p2, then p3, then p4 and, finally, return to p1 while avoiding p2 and p3",
    ],
)
def test_the_papers_sentence(phrase: str) -> None:
    expected = "F(p2 & F(p3 & F(p4 & ((!p2 & !p3) U p1))))"
    assert to_text(compile_phrase(phrase)) == expected


def test_keywords_are_case_insensitive() -> None:
    assert compile_phrase("VISIT a THEN b") == parse_ltl("F(a & F b)")


def test_phrases_are_conjoined_and_all_problems_reported() -> None:
    assert compile_phrases(["visit a", "avoid o"]) == parse_ltl("F a & G !o")
    with pytest.raises(InvalidInputError) as caught:
        compile_phrases(
            ["vist a", "visit b", "go somewhere"], file="m.yaml", positions=[(4, 5), (5, 5), (6, 5)]
        )
    lines = [d.line for d in caught.value.diagnostics]
    assert lines == [4, 6]


def test_unknown_phrase_lists_the_known_ones() -> None:
    with pytest.raises(InvalidInputError) as caught:
        compile_phrase("vist a", file="m.yaml", line=2, col=5)
    diagnostic = caught.value.diagnostics[0]
    assert diagnostic.code == "T001"
    assert "did you mean 'visit'" in (diagnostic.hint or "")
    assert "patrol A, B" in (diagnostic.hint or "")


def test_unknown_group() -> None:
    with pytest.raises(InvalidInputError) as caught:
        compile_phrase("visit all roms", groups=GROUPS)
    assert caught.value.diagnostics[0].code == "T002"
    assert "rooms" in (caught.value.diagnostics[0].hint or "")


@pytest.mark.parametrize(
    "duration", ["9" * 400 + " s", "2" + "0" * 307 + " minutes", "2" + "0" * 308 + ".5 seconds"]
)
def test_a_duration_past_the_float_range_is_refused_at_the_duration(duration: str) -> None:
    # read as inf it would make "within" bound nothing
    with pytest.raises(InvalidInputError) as caught:
        compile_phrase(f"visit a within {duration}", file="m.yaml", line=3, col=5)
    found = caught.value.diagnostics[0]
    assert (found.code, found.line, found.col) == ("T004", 3, 20)
    assert compile_phrase("visit a within 1" + "0" * 306 + " s") == parse_ltl("F[0,1e306] a")


def test_names_keep_positions_inside_the_phrase() -> None:
    formula = compile_phrase("visit kitchen", file="m.yaml", line=9, col=5)
    prop = next(n for n in formula.walk() if hasattr(n, "name"))
    assert prop.span is not None
    assert (prop.span.line, prop.span.col) == (9, 11)


def test_the_documentation_table_is_true() -> None:
    doc = (Path(__file__).resolve().parents[2] / "docs" / "task-phrases.md").read_text()
    rows = re.findall(r"^\| `([^`]+)` \| `([^`]+)` \|", doc, flags=re.MULTILINE)
    assert len(rows) >= len(TABLE)
    for phrase, ltl in rows:
        assert compile_phrase(phrase, groups=GROUPS) == parse_ltl(ltl.replace("\\|", "|")), phrase


WITHOUT_SENSORS = """\
version: 1
workspace: {boundary: {rect: [0, 0, 10, 10]}}
regions:
  dock: {rect: [1, 1, 2, 2]}
  lab: {rect: [4, 1, 5, 2]}
groups: {both: [dock, lab]}
robot: {start: [0.5, 0.5], max_speed: 1.0}
task:
"""


def test_names_of_the_wrong_kind_are_reported_without_sensors() -> None:
    # no `sensors:`, `actions:` or `assumptions:`: a region is still no condition or action
    from tlmpc.mission import load_mission_text

    task = "  - if you sense dock then do lab\n  - never enter lab while both\n"
    with pytest.raises(InvalidInputError) as caught:
        load_mission_text(WITHOUT_SENSORS + task, "m.yaml")
    found = [(d.code, d.line, d.col, d.message) for d in caught.value.diagnostics]
    assert found == [
        ("T020", 9, 18, "'dock' is a region, not a sensor"),
        ("T020", 9, 31, "'lab' is a region, not an action"),
        ("T020", 10, 27, "'both' is a group, not a sensor"),
    ]
    mission = load_mission_text(WITHOUT_SENSORS + "  - whenever dock, visit both\n", "m.yaml")
    assert to_text(mission.formula) == "G(dock -> F(dock | lab))"
