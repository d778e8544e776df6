"""Loading valid missions: defaults, shapes, groups, formula."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tlmpc.base.errors import InvalidInputError, UsageError
from tlmpc.ltl import parse_ltl
from tlmpc.mission import check_text, load_mission, load_mission_text

ROOT = Path(__file__).resolve().parents[2]
SPECS = sorted((ROOT / "specs").glob("*.yaml"))

MINIMAL = """\
version: 1
workspace:
  boundary: [[0, 0], [4, 0], [4, 3], [0, 3]]
regions:
  a: {rect: [0.5, 0.5, 1.5, 1.5]}
  b: [[3, 2], [2, 2], [2, 1]]
groups: {both: [a, b]}
robot: {start: [0.2, 0.2]}
ltl: "F both"
"""


@pytest.mark.parametrize("path", SPECS, ids=lambda p: p.stem)
def test_every_spec_is_valid(path: Path) -> None:
    mission = load_mission(path)
    assert mission.regions
    assert mission.formula.props() <= set(mission.region_names)


def test_defaults_and_shapes() -> None:
    mission = load_mission_text(MINIMAL, "minimal.yaml")
    assert mission.name == "minimal"
    assert mission.robot.max_speed == 1.0
    assert mission.options.min_angle == 20.0
    assert mission.options.cost == "length"
    assert mission.options.boundary == "right"
    assert mission.region("a").polygon == ((0.5, 0.5), (1.5, 0.5), (1.5, 1.5), (0.5, 1.5))
    # groups in LTL mean "any region of the group"
    assert mission.formula == parse_ltl("F(a | b)")


def test_paper_example1_means_the_papers_formula() -> None:
    mission = load_mission(ROOT / "specs" / "example1.yaml")
    assert str(mission.formula) == "F(p2 & F(p3 & F(p4 & ((!p2 & !p3) U p1))))"


def test_all_problems_are_reported_in_one_run() -> None:
    text = MINIMAL.replace("{rect: [0.5, 0.5, 1.5, 1.5]}", "{rect: [1.5, 0.5, 0.5, 1.5]}")
    text = text.replace('"F both"', '"F bth & X a"')
    codes = {d.code for d in check_text(text, "m.yaml")}
    assert {"G001", "L004"} <= codes


def test_unknown_region_has_a_did_you_mean_at_its_position() -> None:
    diagnostics = check_text(MINIMAL.replace('"F both"', '"F bth"'), "m.yaml")
    assert [(d.code, d.line, d.col) for d in diagnostics] == [("L010", 9, 9)]
    assert "did you mean 'both'" in (diagnostics[0].hint or "")


def test_unreadable_file_is_a_usage_error(tmp_path: Path) -> None:
    with pytest.raises(UsageError):
        load_mission(tmp_path / "missing.yaml")


def test_invalid_mission_raises_with_every_diagnostic() -> None:
    with pytest.raises(InvalidInputError) as caught:
        load_mission_text("version: 1\n", "m.yaml")
    assert len(caught.value.diagnostics) >= 3


def test_generated_example8_is_up_to_date() -> None:
    import runpy

    module = runpy.run_path(str(ROOT / "specs" / "generate_example8.py"))
    assert module["render"]() == (ROOT / "specs" / "example8.yaml").read_text()


yaml_scalars = st.one_of(
    st.integers(-(10**30), 10**30),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=8),
    st.booleans(),
    st.none(),
)
yaml_values = st.recursive(
    yaml_scalars,
    lambda inner: st.one_of(
        st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=6), inner, max_size=4)
    ),
    max_leaves=20,
)


@settings(deadline=None)
@given(st.binary(max_size=300))
def test_random_bytes_never_crash(data: bytes) -> None:
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        return
    for diagnostic in check_text(text, "fuzz.yaml"):
        assert diagnostic.code[0] in "YSGLT"


@pytest.mark.slow
@settings(deadline=None)
@given(
    st.dictionaries(
        st.sampled_from(
            [
                "version",
                "workspace",
                "regions",
                "robot",
                "task",
                "ltl",
                "options",
                "groups",
                "name",
                "x",
            ]
        ),
        yaml_values,
        max_size=8,
    )
)
def test_random_structures_never_crash(document: dict[str, object]) -> None:
    import json

    check_text(json.dumps(document, allow_nan=True), "fuzz.yaml")


@pytest.mark.parametrize("depth", [100, 5000])
def test_deep_nesting_is_a_diagnostic(depth: int) -> None:
    diagnostics = check_text("[" * depth + "]" * depth, "deep.yaml")
    assert diagnostics
    assert diagnostics[0].code.startswith(("Y", "S"))


def test_alias_bomb_is_a_diagnostic() -> None:
    lines = ['a0: &a0 ["x", "x", "x", "x", "x", "x", "x", "x", "x", "x"]']
    for i in range(1, 9):
        refs = ", ".join([f"*a{i - 1}"] * 10)
        lines.append(f"a{i}: &a{i} [{refs}]")
    diagnostics = check_text("\n".join(lines) + "\n", "bomb.yaml")
    assert any(d.code == "Y003" for d in diagnostics)


def test_huge_numbers_are_not_finite() -> None:
    diagnostics = check_text(MINIMAL.replace("[0.2, 0.2]", "[1.0e+999, 0.2]"), "m.yaml")
    assert [d.code for d in diagnostics] == ["Y005"]
    assert not math.isfinite(float("1.0e+999"))


# --- positions inside strings written over several YAML lines ---------------------------------

REGIONS_ABC = """\
version: 1
workspace: {boundary: {rect: [0, 0, 10, 10]}}
regions:
  a: {rect: [1, 1, 2, 2]}
  b: {rect: [4, 1, 5, 2]}
  c: {rect: [7, 1, 8, 2]}
  d: {rect: [7, 7, 8, 8]}
robot: {start: [0.5, 0.5], max_speed: 1.0}
"""


def _place_of(text: str, piece: str, offset: int = 0) -> tuple[int, int]:
    """The 1-based line and column of ``piece`` (which occurs once in ``text``) + ``offset``."""
    assert text.count(piece) == 1, piece
    index = text.index(piece) + offset
    return text.count("\n", 0, index) + 1, index - (text.rfind("\n", 0, index) + 1) + 1


def _found(text: str) -> list[tuple[str, int | None, int | None]]:
    return [(d.code, d.line, d.col) for d in check_text(text, "m.yaml")]


PHRASES = [
    "visit {0} then {1} while avoiding {2}",
    "visit {0}, {1} and {2} then go to {3}",
    "avoid {0}, {1} until {2}",
    "patrol {0}, {1}, {2}",
    "visit {0} then {1} then return to {2}",
    "visit {0} infinitely often",
]
FORMULAS = [
    "F {0} & G !{1} & ({2} U {3})",
    "G (F {0} -> F ({1} | {2}))",
    "F ( {0} & F {1} ) & G ! {2}",
    '"{0}" W {1}',
]


@st.composite
def _laid_out(draw: st.DrawFn) -> tuple[str, str]:
    """A task phrase or an `ltl:` formula naming `zz` once, in a random YAML layout; the
    mission and the piece of it where `zz` is written (it occurs nowhere else)."""
    ltl = draw(st.booleans())
    template = draw(st.sampled_from(FORMULAS if ltl else PHRASES))
    slots = template.count("{")
    names = draw(st.permutations(["a", "b", "c", "d"]))[:slots]
    names[draw(st.integers(0, slots - 1))] = "zz"
    words = template.format(*names).split(" ")
    breaks = draw(st.lists(st.booleans(), min_size=len(words), max_size=len(words)))
    lines: list[list[str]] = [[]]
    for word, cut in zip(words, breaks, strict=True):
        if cut and lines[-1]:
            lines.append([])
        lines[-1].append(word)
    style = draw(st.sampled_from(["plain", "'", '"', '"\\', "|", "|-", "|+", ">", ">-"]))
    if ltl and style == "plain" and words[0].startswith('"'):
        style = "'"  # a plain scalar cannot start with a quote
    indent = " " * draw(st.integers(4, 7))
    prefix = draw(st.sampled_from(["", "!!str ", "&anchor "]))
    rows = [" ".join(line) for line in lines]
    if style == '"':
        rows = [row.replace('"', '\\"') for row in rows]
        if draw(st.booleans()):  # an escape for a character of another name
            rows = [row.replace("a", "\\x61", 1) if "zz" not in row else row for row in rows]
    if style in ("|", "|-", "|+", ">", ">-"):
        comment = draw(st.sampled_from(["", "  # a comment"]))
        body = f"{prefix}{style}{comment}\n" + "".join(f"{indent}{row}\n" for row in rows)
    elif style == '"\\':  # double quotes, every line break escaped (the space kept before it)
        rows = [row.replace('"', '\\"') for row in rows]
        body = f'{prefix}"' + f" \\\n{indent}".join(rows) + '"\n'
    else:
        quote = "" if style == "plain" else style
        body = f"{prefix}{quote}" + f"\n{indent}".join(rows) + f"{quote}\n"
    # a quoted name (`"zz"` in LTL) is placed at its opening quote
    piece = "zz" if '"zz"' not in words else '\\"zz' if style.startswith('"') else '"zz'
    if ltl:
        return REGIONS_ABC + "ltl: " + body, piece
    return REGIONS_ABC + "task:\n  - " + body, piece


@settings(max_examples=150, deadline=None)
@given(_laid_out())
def test_an_unknown_name_is_placed_where_it_is_written_in_any_yaml_layout(
    case: tuple[str, str],
) -> None:
    text, piece = case
    line, col = _place_of(text, piece)
    assert _found(text) == [("L010", line, col)], text


@pytest.mark.parametrize(
    ("task", "code", "piece", "offset"),
    [
        # T003: a region named like a keyword, on a literal block's indented second line
        ("task:\n  - |\n    visit a then\n      then\n", "T003", "  then\n", 2),
        # T020: a region as a condition, in single quotes over a blank line
        ("task:\n  - 'if you sense\n\n    dock then do beep'\n", "T020", "    dock then", 4),
        # T020 in a folded block
        ("task:\n  - >-\n    if you sense s\n    then do a\n", "T020", " a\n", 1),
        # T021: the `while` condition of a folded block's second line
        (
            "task:\n  - >-\n    when s, go to a and stay\n    there while all of s, t\n",
            "T021",
            "s, t\n",
            0,
        ),
        # T010 in double quotes with escapes before the name
        ('task:\n  - "visit \\x61 then \\\n    d while\\x20avoiding d"\n', "T010", "avoiding d", 9),
        # L010 in a multi-line assumption
        ("task: [visit a]\nassumptions:\n  - |\n    G (s ->\n      F zz)\n", "L010", "zz", 0),
    ],
)
def test_phrase_codes_are_placed_in_multi_line_strings(
    task: str, code: str, piece: str, offset: int
) -> None:
    text = (
        REGIONS_ABC.replace(
            "  d: ", "  dock: {rect: [4, 4, 5, 5]}\n  then: {rect: [1, 4, 2, 5]}\n  d: "
        )
        + "sensors: {s: null, t: null}\nactions: {beep: null}\n"
        + task
    )
    line, col = _place_of(text, piece, offset)
    assert (code, line, col) in _found(text), _found(text)


def test_a_contradiction_is_placed_at_the_first_character_of_a_block() -> None:
    text = REGIONS_ABC + "task:\n  - |\n      avoid a\n  - visit a\n"
    line, col = _place_of(text, "avoid a")
    assert _found(text) == []
    mission = load_mission_text(text, "m.yaml")
    assert mission.task_positions[0] == (line, col)
    from tlmpc.commands.check import _contradictions

    found = _contradictions(Path("m.yaml"), mission)
    assert [(d.code, d.line, d.col) for d in found] == [("T011", line, col)]


def test_task_parts_of_a_multi_line_formula_start_where_written() -> None:
    from tlmpc.mission.parts import task_parts

    text = REGIONS_ABC + 'task:\n  - >-\n    visit a\n    then b\nltl: "F c &\n     G !d"\n'
    parts = task_parts(load_mission_text(text, "m.yaml"))
    assert [(p.text, p.line, p.col) for p in parts] == [
        ("visit a\nthen b".replace("\n", " "), *_place_of(text, "visit a")),
        ("F c", *_place_of(text, "F c")),
        ("G !d", *_place_of(text, "G !d")),
    ]
    (b,) = [p for p in parts[0].formula.walk() if getattr(p, "name", None) == "b"]
    assert b.span is not None
    assert (b.span.line, b.span.col) == _place_of(text, "b\n")
