"""The executor behind its line protocol, in a real subprocess.

The closed loop runs through the pipe: the test plays the robot (it integrates the commands
it gets, a point robot exactly, a unicycle with its exact flow) and the trajectory it drove is
checked by the verifier, which shares no code with the executor.  The protocol's errors are
checked line by line; the ROS 2 node that uses the bridge is tested only where rclpy exists.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

import tlmpc
from tlmpc.runtime.unicycle import unicycle_flow
from tlmpc.verify import verify_document

ROOT = Path(__file__).resolve().parents[2]


def _mission(**robot: Any) -> dict[str, Any]:
    return {
        "version": 1,
        "name": "corridor",
        "workspace": {"boundary": {"rect": [0, 0, 10, 4]}},
        "regions": {"a": {"rect": [4, 3, 6, 4]}, "b": {"rect": [8.5, 0, 10, 1]}},
        "robot": {"start": [1, 1], "max_speed": 1.0, **robot},
        "task": ["visit a then b"],
    }


def _bridge(out: Path) -> subprocess.Popen[str]:
    return subprocess.Popen(
        [sys.executable, "-m", "tlmpc.runtime.bridge", str(out)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )


def _finish(bridge: subprocess.Popen[str]) -> int:
    """End the input; the bridge must exit at its end (the pipes closed here)."""
    bridge.communicate(timeout=30)
    return bridge.returncode


def _ask(bridge: subprocess.Popen[str], line: str) -> dict[str, Any]:
    assert bridge.stdin is not None
    assert bridge.stdout is not None
    bridge.stdin.write(line + "\n")
    bridge.stdin.flush()
    reply: dict[str, Any] = json.loads(bridge.stdout.readline())
    return reply


@pytest.mark.parametrize("model", ["point", "unicycle"])
def test_a_robot_driven_through_the_bridge_satisfies_its_task(tmp_path: Path, model: str) -> None:
    robot = {"model": "unicycle", "offset": 0.1} if model == "unicycle" else {}
    tlmpc.compile(_mission(**robot)).write(tmp_path / "out")
    bridge = _bridge(tmp_path / "out")
    assert bridge.stdout is not None
    first = json.loads(bridge.stdout.readline())
    assert first["format"] == "tlmpc.bridge/1"
    assert first["model"] == model
    pose = [1.0, 1.0, 0.0] if model == "unicycle" else [1.0, 1.0]
    dt, t, points = 0.02, 0.0, []
    reply: dict[str, Any] = {}
    for _ in range(6000):
        reply = _ask(bridge, json.dumps({"t": t, "pose": pose}))
        points.append([t, pose[0], pose[1]])
        if reply["phase"] == "stay" and math.hypot(*reply["command"]) < 1e-3:
            break
        a, b = reply["command"]
        if model == "unicycle":
            pose = list(unicycle_flow((pose[0], pose[1], pose[2]), a, b, dt))
        else:
            pose = [pose[0] + a * dt, pose[1] + b * dt]
        t += dt
    assert _finish(bridge) == 0
    assert reply["phase"] == "stay"
    assert reply["visits"]["a"] >= 1
    assert reply["visits"]["b"] >= 1
    # the verifier's view of the driven path (the body point; a unicycle's axle is close by)
    if model == "point":
        mission = json.loads((tmp_path / "out" / "trace.json").read_text())
        trace = {**mission, "points": points}
        trace.pop("loop_start", None)
        assert verify_document(trace).satisfied


def test_bad_lines_get_errors_and_the_bridge_reads_on(tmp_path: Path) -> None:
    tlmpc.compile(_mission()).write(tmp_path / "out")
    bridge = _bridge(tmp_path / "out")
    assert bridge.stdout is not None
    bridge.stdout.readline()
    assert _ask(bridge, "not json")["error"]["code"] == "U120"
    assert _ask(bridge, '{"t": 0, "pose": "1,1"}')["error"]["code"] == "U120"
    assert _ask(bridge, '{"t": true, "pose": [1, 1]}')["error"]["code"] == "U120"
    assert _ask(bridge, '{"t": 0, "pose": [1, 1, 0]}')["error"]["code"] == "R023"
    assert _ask(bridge, '{"t": 0, "pose": [NaN, 1]}')["error"]["code"] == "R023"
    assert _ask(bridge, "x" * 70_000)["error"]["code"] == "U121"
    good = _ask(bridge, '{"t": 0, "pose": [1, 1]}')
    assert good["status"] == "following"
    assert len(good["command"]) == 2
    assert _finish(bridge) == 0


def test_an_output_that_cannot_be_loaded_is_a_diagnostic_and_exit_2(tmp_path: Path) -> None:
    done = subprocess.run(
        [sys.executable, "-m", "tlmpc.runtime.bridge", str(tmp_path / "missing")],
        capture_output=True,
        text=True,
        input="",
    )
    assert done.returncode == 2
    assert done.stdout == ""
    assert "error[" in done.stderr
    assert "Traceback" not in done.stderr


def test_the_ros2_node_loads_where_rclpy_exists() -> None:
    pytest.importorskip("rclpy")
    import importlib.util

    spec = importlib.util.spec_from_file_location(
        "tlmpc_bridge_node", ROOT / "tools" / "ros2" / "tlmpc_bridge_node.py"
    )
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert hasattr(module, "TlmpcBridgeNode")
