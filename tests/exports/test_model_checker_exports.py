"""`tlmpc export`: models SPIN and NuSMV read, whatever the map's size and the regions' names.

Oracles: SPIN itself (``spin -a``, gcc, ``pan``) on the Promela model, its trail replayed on
the abstraction; Spot for the SMV task, read back through NuSMV's LTL grammar (tokens and
constants as NuSMV's lexer has them), which is independent of tlmpc's printer.
"""

from __future__ import annotations

import io
import itertools
import json
import re
from pathlib import Path
from typing import Any

import pytest
import spin_runner as spin
from ci_oracles import import_oracle, oracle_required

from tlmpc.cli import main

needs_spin = oracle_required(spin.available(), "spin (and gcc)")


def run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    return main(list(argv), out=out, err=err), out.getvalue(), err.getvalue()


def compiled(tmp_path: Path, text: str) -> Path:
    mission = tmp_path / "mission.yaml"
    mission.write_text(text)
    out = tmp_path / "out"
    code, _, err = run("compile", str(mission), "-o", str(out), "--until", "abstraction", "-q")
    assert code == 0, err
    return out


def region_triangles(out: Path) -> dict[str, set[int]]:
    abstraction = json.loads((out / "abstraction.json").read_text())
    letters = [set(letter) for letter in abstraction["letters"]]
    members: dict[str, set[int]] = {name: set() for name in abstraction["regions"]}
    for triangle, letter in enumerate(abstraction["letter_of"]):
        for name in letters[letter]:
            members[name].add(triangle)
    return members


def spin_on(out: Path, *flags: str) -> spin.SpinTrail:
    model = out.parent / "model.pml"
    code, _, err = run("export", str(out), "-o", str(model), *flags)
    assert code == 0, err
    return spin.run_spin(model)


def check_trail(out: Path, trail: spin.SpinTrail) -> list[int]:
    """The triangles of SPIN's trail (start first), each a neighbour of the one before or
    itself."""
    abstraction = json.loads((out / "abstraction.json").read_text())
    path = [abstraction["start"], *trail.entered]
    for here, there in itertools.pairwise(path):
        assert there in abstraction["neighbors"][here], (here, there)
    return path


ROOM = """\
version: 1
workspace:
  boundary: {rect: [0, 0, 10, 10]}
regions:
  a: {rect: [0.5, 0.5, 4, 4]}
  b: {rect: [6, 6, 9.5, 9.5]}
robot: {start: [5, 5]}
options: {max_area: 0.1}
"""


@needs_spin
@pytest.mark.parametrize("bounce", [False, True])
def test_spin_reads_the_model_of_regions_of_hundreds_of_triangles(
    tmp_path: Path, bounce: bool
) -> None:
    out = compiled(tmp_path, ROOM + 'ltl: "G F a & G F b"\n')
    members = region_triangles(out)
    # SPIN's LTL parser failed on a region spelled out as `t == i || ...` past ~135 triangles
    assert min(len(members["a"]), len(members["b"])) > 150
    trail = spin_on(out, *(["--bounce"] if bounce else []))
    assert trail.found
    assert trail.cycle_from is not None
    path = check_trail(out, trail)
    cycle = set(path[1:][trail.cycle_from :])
    assert cycle & members["a"]  # the lasso's cycle visits both
    assert cycle & members["b"]


@needs_spin
@pytest.mark.parametrize(("start", "found"), [("[2, 2]", True), ("[5, 5]", False)])
def test_spin_sees_the_start_triangle_s_regions(tmp_path: Path, start: str, found: bool) -> None:
    """``a`` (no temporal operator) holds exactly when the robot starts in region a: the
    region's proposition is right before the first move."""
    out = compiled(tmp_path, ROOM.replace("[5, 5]", start) + 'ltl: "a & G !b"\n')
    assert spin_on(out).found is found


LONG = "n" * 300


@needs_spin
def test_region_names_of_any_length_are_exported(tmp_path: Path) -> None:
    """Region names longer than 64 characters are valid; SPIN's lexer overflows on ~500."""
    first, second, medium = LONG + "x", LONG + "y", "m" * 65
    out = compiled(
        tmp_path,
        f"""\
version: 1
workspace:
  boundary: {{rect: [0, 0, 10, 10]}}
regions:
  {first}: {{rect: [1, 1, 3, 3]}}
  {second}: {{rect: [7, 1, 9, 3]}}
  {medium}: {{rect: [4, 7, 6, 9]}}
robot: {{start: [5, 5]}}
ltl: "F {first} & G !{second} & F {medium}"
""",
    )
    for fmt in ("promela", "smv", "dot"):
        code, text, err = run("export", str(out), "--format", fmt)
        assert code == 0, err
        if fmt != "dot":
            assert f"p_{medium} " in text  # a name of up to 200 characters is kept whole
    code, promela, _ = run("export", str(out))
    identifiers = set(re.findall(r"\bp_\w+", promela))
    assert len(identifiers) == 3  # the two cut names stay distinct
    assert max(len(name) for name in identifiers) < 250
    members = region_triangles(out)
    trail = spin_on(out)
    assert trail.found
    visited = set(check_trail(out, trail))
    assert visited & members[first]
    assert visited & members[medium]
    assert not visited & members[second]


# NuSMV's LTL as its lexer (input.l) and grammar read it: constants are TRUE/FALSE only; any
# other word is an identifier, which must be DEFINEd.
_NUSMV_TOKEN = re.compile(r"\s*(<->|->|[()!&|]|[A-Za-z_][A-Za-z0-9_$#-]*)")
_NUSMV_OPERATORS = {"G", "F", "U", "V", "X", "TRUE", "FALSE"}


def nusmv_ltlspec_to_spot(model: str) -> str:
    """The ``LTLSPEC`` of an SMV model in Spot's syntax; every identifier must be DEFINEd."""
    defined = set(re.findall(r"^\s+(\w+) :=", model, re.MULTILINE))
    (spec,) = re.findall(r"^LTLSPEC (.*)$", model, re.MULTILINE)
    words: list[str] = []
    position = 0
    while position < len(spec):
        match = _NUSMV_TOKEN.match(spec, position)
        assert match, f"NuSMV cannot read {spec[position:]!r}"
        token, position = match.group(1), match.end()
        if token in ("TRUE", "FALSE"):
            words.append("1" if token == "TRUE" else "0")
        elif token in _NUSMV_OPERATORS or not (token[0].isalpha() or token[0] == "_"):
            words.append({"V": "R"}.get(token, token))
        else:
            assert token in defined, f"NuSMV: undefined identifier {token!r}"
            words.append(f'"{token}"')
    return " ".join(words)


@pytest.mark.parametrize(
    "task",
    [
        "true U a",
        "a U true",
        "G F (b | false)",
        "(a W false) | true",
        "a M b",
        "(a -> F b) <-> G !false",
        "G (a R (b W a))",
    ],
)
def test_the_smv_task_is_nusmv_ltl_with_its_meaning(tmp_path: Path, task: str) -> None:
    spot: Any = import_oracle("spot")
    out = compiled(tmp_path, ROOM.replace("max_area: 0.1", "max_area: 4") + f'ltl: "{task}"\n')
    code, model, err = run("export", str(out), "--format", "smv")
    assert code == 0, err
    written = spot.formula(nusmv_ltlspec_to_spot(model))
    spot_task = re.sub(r"\b([ab])\b", r'"p_\1"', task).replace("true", "1").replace("false", "0")
    assert spot.are_equivalent(written, spot.formula(f"!({spot_task})"))
