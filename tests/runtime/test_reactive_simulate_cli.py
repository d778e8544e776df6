"""``tlmpc simulate OUT --sensors ...`` on a compiled reactive mission: the trace it writes,
sensor files in both layouts, and located refusals."""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any

import pytest

from tlmpc.cli import main
from tlmpc.io.schema_check import validation_errors

pytest.importorskip("spot")

import itertools

from reactive_runs import check_run

ROOT = Path(__file__).resolve().parents[2]


def run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    return main(list(argv), out=out, err=err), out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def guard(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("guard") / "out"
    code, _, err = run("compile", str(ROOT / "specs" / "reactive" / "guard.yaml"), "-o", str(out))
    assert code == 0, err
    return out


@pytest.mark.parametrize("kind", ["random", "adversarial"])
def test_simulate_writes_a_checked_trace(guard: Path, tmp_path: Path, kind: str) -> None:
    trace_path = tmp_path / "trace.json"
    code, out, err = run(
        "simulate",
        str(guard),
        "--sensors",
        kind,
        "--events",
        "50",
        "--seed",
        "2",
        "-o",
        str(trace_path),
    )
    assert code == 0, err
    assert "ran 50 event(s)" in out
    trace = json.loads(trace_path.read_text())
    assert validation_errors(trace, "trace") == []
    assert trace["end"] == "open"
    assert trace["loop_start"] is None
    assert trace["sensors"] == ["alarm", "person"]  # by name, as mission.json keeps them
    assert trace["actions"] == ["camera"]
    assert trace["assumptions"] == ["G F !person", "!alarm"]
    for points in trace["signals"].values():
        assert points[0][0] == trace["points"][0][0]
        times = [t for t, _ in points]
        assert times == sorted(set(times))
        values = [v for _, v in points]
        assert all(a != b for a, b in itertools.pairwise(values))
    check_run(trace, json.loads((guard / "strategy.json").read_text()))


@pytest.mark.parametrize("kind", ["random", "adversarial"])
@pytest.mark.parametrize("seed", ["0", "3"])
def test_simulate_reports_the_verifiers_verdict(
    guard: Path, tmp_path: Path, kind: str, seed: str
) -> None:
    trace_path = tmp_path / "trace.json"
    code, out, err = run(
        "simulate",
        str(guard),
        "--sensors",
        kind,
        "--seed",
        seed,
        "--events",
        "60",
        "--json",
        "-o",
        str(trace_path),
    )
    result = json.loads(out)["result"]
    # the command's verdict is the standalone verifier's on the trace it wrote ...
    verify_code, verify_out, _ = run("verify", str(trace_path), "--json")
    assert json.loads(verify_out)["result"]["verdict"] == result["outcome"]
    # ... and an open run of a winning strategy breaks no guarantee: goals stay inconclusive
    assert result["outcome"] == "inconclusive"
    assert (code, verify_code) == (0, 4), err


def test_a_run_that_breaks_a_guarantee_exits_1(
    guard: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from tlmpc.runtime import reactive_loop

    real = reactive_loop.run_reactive

    def camera_never_on(*args: Any, **kwargs: Any) -> reactive_loop.ReactiveRun:
        # the robot forgets "if you sense person then do camera" while the run is recorded
        run = real(*args, **kwargs)
        start = run.trace["points"][0][0]
        run.trace["signals"]["camera"] = [[start, False]]
        return run

    monkeypatch.setattr(reactive_loop, "run_reactive", camera_never_on)
    trace_path = tmp_path / "trace.json"
    code, out, _ = run(
        "simulate",
        str(guard),
        "--sensors",
        "adversarial",
        "--events",
        "60",
        "--json",
        "-o",
        str(trace_path),
    )
    trace = json.loads(trace_path.read_text())
    assert any(value for _, value in trace["signals"]["person"])  # a person was sensed
    result = json.loads(out)["result"]
    assert result["outcome"] == "violated"
    assert code == 1
    assert any("G(person -> camera)" in v for v in result["violations"])


def test_json_report(guard: Path) -> None:
    code, out, _ = run("simulate", str(guard), "--events", "10", "--json")
    assert code == 0
    result = json.loads(out)["result"]
    assert result["events"] == 10
    assert result["environment"] == "random"


LONG = "t,sensor,value\n0,person,false\n0,alarm,false\n2.5,person,true\n9,person,0\n"
WIDE = "# a comment\nt,alarm,person\n0,false,false\n2.5,false,true\n9,false,false\n"


@pytest.mark.parametrize("text", [LONG, WIDE], ids=["long", "wide"])
def test_sensor_files_in_both_layouts(guard: Path, tmp_path: Path, text: str) -> None:
    readings = tmp_path / "readings.csv"
    readings.write_text(text)
    trace_path = tmp_path / "trace.json"
    code, _, err = run(
        "simulate",
        str(guard),
        "--sensors",
        str(readings),
        "--events",
        "30",
        "-o",
        str(trace_path),
    )
    assert code == 0, err
    trace = json.loads(trace_path.read_text())
    assert trace["signals"]["person"] == [[0.0, False], [2.5, True], [9.0, False]]
    assert trace["signals"]["alarm"] == [[0.0, False]]
    # the camera follows the person (if you sense person then do camera), at the same instant
    assert [t for t, v in trace["signals"]["camera"] if v] == [2.5]
    check_run(trace, json.loads((guard / "strategy.json").read_text()))


@pytest.mark.parametrize(
    ("text", "code", "line", "col"),
    [
        ("t,sensor,value\n0,person,false\n0,alarm,maybe\n", "U103", 3, 9),
        ("t,sensor,value\n0,person,false\n0,door,true\n", "U102", 3, 3),
        ("t,alarm\n0,false\n", "U102", 1, 1),
        ("t,person,alarm\n0,false,false\n-1,true,false\n", "U103", 3, 1),
        ("t,person,alarm\n0,false,false\n5,true,false\n3,true,false\n", "U104", 4, 1),
        ("t,person,alarm\n1,false,false\n", "U104", 2, 1),
        ("t,sensor,value\n0,person,false\n", "U104", 2, 1),
        # one instant, two values of one sensor: long and wide
        ("t,sensor,value\n0,person,false\n0,alarm,false\n0,person,true\n", "U104", 4, 1),
        ("t,person,alarm\n0,false,false\n1,true,false\n1,false,true\n", "U104", 4, 1),
        ("t,person,alarm\n0,false\n", "U103", 2, 1),
        # the initial assumption !alarm
        ("t,person,alarm\n0,false,true\n", "Q120", 2, 1),
    ],
)
def test_bad_sensor_files_are_refused_where_they_are_wrong(
    guard: Path, tmp_path: Path, text: str, code: str, line: int, col: int
) -> None:
    readings = tmp_path / "readings.csv"
    readings.write_text(text)
    status, out, err = run("simulate", str(guard), "--sensors", str(readings))
    assert status == 1, err
    assert f"{readings}:{line}:{col}: error[{code}]" in err
    assert out == ""


def test_usage_errors(guard: Path, tmp_path: Path) -> None:
    status, _, err = run("simulate", str(guard), "--events", "0")
    assert status == 2
    assert "error[U105]" in err
    status, _, err = run("simulate", str(guard), "--cycles", "2")
    assert status == 2
    assert "error[U100]" in err
    status, _, err = run("simulate", str(guard), "--sensors", str(tmp_path / "missing.csv"))
    assert status == 2
    assert "error[U101]" in err
    static = tmp_path / "static"
    assert run("compile", str(ROOT / "specs" / "patrol.yaml"), "-o", str(static))[0] == 0
    status, _, err = run("simulate", str(static), "--sensors", "random")
    assert status == 2
    assert "error[U100]" in err


def test_a_strategy_of_another_mission_is_refused(guard: Path, tmp_path: Path) -> None:
    import shutil

    other = tmp_path / "other"
    shutil.copytree(guard, other)
    strategy = json.loads((other / "strategy.json").read_text())
    strategy["inputs"][0]["name"] = "visitor"
    (other / "strategy.json").write_text(json.dumps(strategy))
    status, _, err = run("simulate", str(other), "--events", "5")
    assert status == 2
    assert "error[Q123]" in err


def test_an_unrealizable_mission_has_nothing_to_simulate(tmp_path: Path) -> None:
    """Its folder holds the mission and the counterstrategy but no strategy: simulate says
    so (Q123), with or without the reactive flags."""
    mission = tmp_path / "lost.yaml"
    mission.write_text(
        "version: 1\n"
        "workspace: {boundary: {rect: [0, 0, 3, 2]}}\n"
        "regions:\n  r0: {rect: [0, 0, 1, 2]}\n  r1: {rect: [2, 0, 3, 2]}\n"
        "sensors: {s: null}\n"
        "robot: {start: [1.5, 1]}\n"
        "task:\n  - visit r1 infinitely often\n  - never enter r1 while s\n"
    )
    out = tmp_path / "out"
    code, _, err = run("compile", str(mission), "-o", str(out))
    assert code == 1, err
    assert "error[Q110]" in err
    assert (out / "counterstrategy.json").is_file()
    for flags in (("--sensors", "random"), ("--events", "5"), ()):
        status, printed, err = run("simulate", str(out), *flags)
        assert status == 2, flags
        assert printed == ""
        assert f"{out}: error[Q123]" in err, (flags, err)
        assert "unrealizable reactive mission" in err
        assert "hint: tlmpc view" in err


def test_an_assumption_no_environment_can_keep_stops_the_run(tmp_path: Path) -> None:
    """ "G !r1" promises the robot is never in r1; the robot, asked to visit r1, wins the
    game vacuously (the environment cannot keep both that and the robot's arrival), but a
    real arrival in r1 leaves no reading that keeps the promise."""
    mission = tmp_path / "promise.yaml"
    mission.write_text(
        "version: 1\n"
        "workspace: {boundary: {rect: [0, 0, 3, 2]}}\n"
        "regions:\n  r0: {rect: [0, 0, 1, 2]}\n  r1: {rect: [2, 0, 3, 2]}\n"
        "sensors: {s: null}\n"
        'assumptions:\n  - "G !r1"\n'
        "robot: {start: [1.5, 1]}\n"
        "task:\n  - visit r1 infinitely often\n"
    )
    out = tmp_path / "out"
    code, _, err = run("compile", str(mission), "-o", str(out))
    assert code == 0, err
    status, _, err = run("simulate", str(out), "--events", "20")
    assert status == 1
    assert "error[Q121]" in err
    assert "G !r1" in err


def test_fairness_assumptions_are_met_within_the_bound(guard: Path, tmp_path: Path) -> None:
    from reactive_runs import word

    from tlmpc.runtime.environments import FAIRNESS_BOUND

    for kind in ("random", "adversarial"):
        trace_path = tmp_path / f"{kind}.json"
        code, _, err = run(
            "simulate", str(guard), "--sensors", kind, "--events", "80", "-o", str(trace_path)
        )
        assert code == 0, err
        letters = word(json.loads(trace_path.read_text()))
        longest = run_length = 0
        for letter in letters:  # G F !person: the longest stretch of letters with a person
            run_length = run_length + 1 if "person" in letter else 0
            longest = max(longest, run_length)
        assert 1 <= longest <= FAIRNESS_BOUND, kind


def test_a_strategy_on_other_faces_is_refused(guard: Path, tmp_path: Path) -> None:
    import shutil

    other = tmp_path / "other"
    shutil.copytree(guard, other)
    strategy = json.loads((other / "strategy.json").read_text())
    labels = strategy["faces"]["labels"]
    labels[1], labels[3] = labels[3], labels[1]  # home and post swapped
    (other / "strategy.json").write_text(json.dumps(strategy))
    status, _, err = run("simulate", str(other), "--events", "5")
    assert status == 2
    assert "error[Q123]" in err
    assert "faces" in err


FOUR_SENSORS = """version: 1
name: four-sensors
workspace:
  boundary: {rect: [0, 0, 10, 6]}
  holes: [{rect: [4, 2, 6, 4]}]
regions:
  home: {rect: [0.5, 0.5, 2, 2]}
  exit: {rect: [8, 4, 9.5, 5.5]}
  lab: {rect: [4, 4.5, 6, 6]}
  post: {rect: [8, 0.5, 9.5, 2]}
sensors: {person: null, alarm: null, door: null, smoke: null}
actions: {camera: null}
assumptions: ["G F !person", "G F !smoke"]
robot: {start: [1, 1], max_speed: 1.0}
task:
  - if you sense person then visit exit
  - visit post infinitely often unless alarm
  - visit home infinitely often unless smoke
  - never enter lab while alarm
  - never enter lab while door
  - if you sense smoke then visit exit
  - if you sense person then do camera
"""


@pytest.mark.parametrize("kind", ["random", "adversarial"])
def test_a_strategy_written_only_symbolically_runs(tmp_path: Path, kind: str) -> None:
    mission = tmp_path / "four.yaml"
    mission.write_text(FOUR_SENSORS)
    out = tmp_path / "out"
    code, _, err = run("compile", str(mission), "-o", str(out))
    assert code == 0, err
    strategy = json.loads((out / "strategy.json").read_text())
    assert "nodes" not in strategy  # too large to list: the executor steps the diagrams
    trace_path = tmp_path / "trace.json"
    code, _, err = run(
        "simulate", str(out), "--sensors", kind, "--events", "60", "-o", str(trace_path)
    )
    assert code == 0, err
    trace = json.loads(trace_path.read_text())
    assert validation_errors(trace, "trace") == []
    code, verified, _ = run("verify", str(trace_path), "--json")
    assert json.loads(verified)["result"]["verdict"] == "inconclusive"
    # the run changed sensors and moved the robot between faces
    assert any(len(points) > 1 for points in trace["signals"].values())
    assert len({(round(x, 6), round(y, 6)) for _, x, y in trace["points"]}) > 10


@pytest.mark.parametrize("fmt", ["promela", "smv", "dot"])
def test_export_of_a_reactive_output_says_why_a_model_cannot_be_written(
    guard: Path, fmt: str
) -> None:
    code, out, err = run("export", str(guard), "--format", fmt)
    if fmt == "dot":  # the transition system alone: no task in it
        assert code == 0, err
        assert out.startswith("graph")
        return
    assert code == 2
    assert err.startswith(f"{guard / 'mission.json'}: error[U078]"), err
    assert "alarm, camera, person" in err
    assert "different compiles" not in err
