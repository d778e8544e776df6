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
