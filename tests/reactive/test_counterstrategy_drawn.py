"""An unrealizable reactive mission's OUT shows how the environment wins.

``tlmpc compile`` exits 1 and writes mission.json, abstraction.json and counterstrategy.json;
the play in it is a path of the environment's winning strategy (checked node by node against
the counterstrategy graph the solver computes), each step's point lies in its face (shapely,
on the abstraction's triangles), and ``tlmpc plot`` and ``tlmpc view`` draw the same places
with the same texts.
"""

from __future__ import annotations

import io
import json
from pathlib import Path

import jsonschema
import shapely
from reactive_missions import GUARD_UNREALIZABLE

from tlmpc.abstraction import build_abstraction
from tlmpc.cli import main
from tlmpc.io.schema_check import load_schema
from tlmpc.mission import load_mission
from tlmpc.reactive.synthesize import synthesize
from tlmpc.render.scene import play_marks
from tlmpc.render.svg import PLAY_COLOUR


def run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out=out, err=err)
    return code, out.getvalue(), err.getvalue()


def test_the_unrealizable_output_draws_the_environments_play(tmp_path: Path) -> None:
    source = tmp_path / "guard.yaml"
    source.write_text(GUARD_UNREALIZABLE)
    out = tmp_path / "out"
    code, _, err = run("compile", str(source), "-o", str(out))
    assert code == 1, err
    assert "Q110" in err
    document = json.loads((out / "counterstrategy.json").read_text())
    jsonschema.validate(document, load_schema("counterstrategy"))
    assert {p["text"] for p in document["core"]} == {
        "never enter lab while alarm",
        "visit lab infinitely often",
    }

    # the play is a path of the counterstrategy graph
    mission = load_mission(source)
    abstraction = build_abstraction(mission)
    found = synthesize(mission, abstraction)
    assert found.counter is not None
    counter = found.counter
    play = document["play"]
    assert play

    def matches(node: int, step: dict[str, object]) -> bool:
        state = counter.states[node]
        sensors = step["sensors"]
        assert isinstance(sensors, dict)
        return (
            state["face"] == step["face"]
            and state["goal"] == step["heading"]
            and all(state[name] == value for name, value in sensors.items())
        )

    current = {n for n in counter.initial if matches(n, play[0])}
    for step in play[1:]:
        current = {a for n in current for a in counter.answers[n] if matches(a, step)}
        assert current, f"step {step['step']} does not follow from the one before"

    # each step's point lies in its face, and the face's regions are the step's
    faces = found.game.faces
    for step in play:
        members = [t for t in range(abstraction.num_triangles) if faces.face_of[t] == step["face"]]
        shape = shapely.union_all(
            [shapely.Polygon(abstraction.vertices[abstraction.triangles[t]]) for t in members]
        )
        assert shape.buffer(1e-9).contains(shapely.Point(step["position"]))
        assert sorted(step["regions"]) == sorted(faces.letters[step["face"]])

    # plot and view draw the same marks
    code, _, err = run("plot", str(out))
    assert code == 0, err
    svg = (out / "plan.svg").read_text()
    marks, route = play_marks(document)
    assert svg.count(f'fill="{PLAY_COLOUR}" stroke="#fff"') == len(marks)
    for mark in marks:
        assert f">{mark.text}</text>" in svg
    assert "how the environment wins" in svg
    page = tmp_path / "view.html"
    code, _, err = run("view", str(out), "-o", str(page))
    assert code == 0, err
    html = page.read_text()
    for mark in marks:
        assert json.dumps(mark.text) in html
    assert len(route) >= 2
