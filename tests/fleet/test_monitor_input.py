"""``tlmpc monitor``'s input and output: times counted as ``tlmpc verify`` counts them, the
same bytes read alike from a file or a pipe, refusals with codes and places instead of
tracebacks or hangs, a followed log read line by complete line, and verdicts never taken back.
"""

from __future__ import annotations

import json
import os
import re
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fleet_cli import run_cli
from hypothesis import given, settings
from hypothesis import strategies as st
from strategies import formulas
from test_stream_equivalence import document, walks

from tlmpc.base.errors import UsageError
from tlmpc.fleet.monitor import Monitor
from tlmpc.ltl.printer import to_text

ROOT = Path(__file__).resolve().parents[2]
MISSION = str(ROOT / "specs" / "reach-avoid.yaml")
#: Poses of specs/reach-avoid.yaml: home, then through the hazard (violated at the third).
POSES = [(0.0, 1.0, 1.0), (10.0, 4.0, 2.0), (20.0, 8.5, 2.0), (30.0, 10.8, 6.8)]


def csv_of(poses: list[tuple[float, float, float]], epoch: float = 0.0) -> str:
    return "t,x,y\n" + "".join(f"{t + epoch!r},{x},{y}\n" for t, x, y in poses)


def test_times_count_from_the_first_pose_with_the_stamp_beside(tmp_path: Path) -> None:
    epoch = 1_700_000_000.0
    log = tmp_path / "stamped.csv"
    log.write_text(csv_of(POSES, epoch), encoding="utf-8")
    code, out, _ = run_cli("monitor", "--mission", MISSION, str(log))
    assert code == 1
    # the hazard is entered at the third pose: 20 s into the log, stamped epoch + 20
    assert "t=20 s (stamp 1700000020)  G !hazard: violated" in out, out
    assert "t=0 s (stamp 1700000000)  task: inconclusive" in out
    assert "e+09" not in out
    code, out, _ = run_cli("monitor", "--mission", MISSION, str(log), "--jsonl")
    events = [json.loads(line) for line in out.splitlines()]
    broken = next(e for e in events if e["subject"] == "G !hazard" and e["verdict"] == "violated")
    assert (broken["t"], broken["stamp"]) == (20.0, epoch + 20.0)
    # a log from 0 reads as before, without a stamp
    log.write_text(csv_of(POSES), encoding="utf-8")
    assert "t=20 s  G !hazard: violated" in run_cli("monitor", "--mission", MISSION, str(log))[1]


def test_the_same_bytes_give_the_same_answer_from_a_file_or_a_pipe(tmp_path: Path) -> None:
    body = b"\xef\xbb\xbf" + csv_of(POSES).replace("\n", "\r\n").encode()
    log = tmp_path / "bom.csv"
    log.write_bytes(body)
    named = run_cli("monitor", "--mission", MISSION, str(log))
    piped = run_cli("monitor", "--mission", MISSION, stdin=body)
    assert named[0] == piped[0] == 1
    assert named[1].replace(str(log), "<stdin>") == piped[1]


def test_a_log_that_is_not_utf8_is_refused_with_its_line(tmp_path: Path) -> None:
    body = b"t,x,y\n0,1,1\n# caf\xe9\n10,4,2\n"
    log = tmp_path / "latin1.csv"
    log.write_bytes(body)
    for argv, stdin, name in (([str(log)], None, str(log)), ([], body, "<stdin>")):
        code, _, err = run_cli("monitor", "--mission", MISSION, *argv, stdin=stdin)
        assert code == 2
        assert err.startswith(f"{name}:3:6: error[M050]"), err
        assert "hint:" in err
    garbage = tmp_path / "garbage.csv"
    garbage.write_bytes(bytes(np.random.default_rng(0).integers(0, 256, 3000, dtype=np.uint8)))
    code, _, err = run_cli("monitor", "--mission", MISSION, str(garbage))
    assert code == 2
    assert "Traceback" not in err


def test_a_fifo_or_a_device_is_refused_at_once(tmp_path: Path) -> None:
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    zero = tmp_path / "zero.csv"
    zero.symlink_to("/dev/zero")
    for path in (fifo, zero):
        code, _, err = run_cli("monitor", "--mission", MISSION, str(path))  # never waits
        assert code == 2
        assert err.startswith(f"{path}: error[M050]"), err


def test_an_endless_line_on_standard_input_stops_at_the_line_limit() -> None:
    code, _, err = run_cli("monitor", "--mission", MISSION, stdin=b"\0" * (5 << 20))
    assert code == 2
    assert err.startswith("<stdin>:1: error[M053]"), err


def test_following_waits_while_a_line_is_written_slowly(tmp_path: Path) -> None:
    log = tmp_path / "live.csv"
    log.write_text("t,x,y\n0,1,1\n10,4,2\n", encoding="utf-8")

    def logger() -> None:  # the file grows every 0.3 s; its last line takes 2.7 s to write
        for piece in "20,8.5,2\n":
            time.sleep(0.3)
            with open(log, "a", encoding="utf-8") as stream:
                stream.write(piece)

    writer = threading.Thread(target=logger)
    writer.start()
    code, out, err = run_cli("monitor", str(log), "--mission", MISSION, "--follow", "--idle", "2")
    writer.join()
    assert code == 1, err
    assert "t=20 s  G !hazard: violated" in out
    assert "after 4 poses" not in out
    assert "after 3 poses" in out


def test_a_line_unfinished_when_following_stops_is_left_out(tmp_path: Path) -> None:
    log = tmp_path / "live.csv"
    log.write_text(csv_of(POSES[:3]) + "30,10.", encoding="utf-8")
    code, out, err = run_cli("monitor", str(log), "--mission", MISSION, "--follow", "--idle", "0")
    assert code == 1  # the verdict of the complete poses
    assert "after 3 poses" in out
    assert "line 5 unfinished" in err
    # read to its end without --follow, the same text is a last line without its break
    assert run_cli("monitor", str(log), "--mission", MISSION)[0] == 2


@pytest.mark.parametrize("idle", ["nan", "-5", "-inf"])
def test_idle_must_be_a_number_of_seconds(tmp_path: Path, idle: str) -> None:
    log = tmp_path / "log.csv"
    log.write_text(csv_of(POSES), encoding="utf-8")
    code, _, err = run_cli("monitor", str(log), "--mission", MISSION, "--follow", f"--idle={idle}")
    assert code == 2
    assert err.startswith("<command line>: error[F011]"), err


def test_a_json_number_too_large_for_a_float_is_refused_as_in_csv(tmp_path: Path) -> None:
    huge = "1" + "0" * 400
    jsonl = '{"t": 0, "x": 1, "y": 1}\n{"t": 1, "x": ' + huge + ', "y": 1}\n'
    csv = f"t,x,y\n0,1,1\n1,{huge},1\n"
    codes = []
    for text in (jsonl, csv):
        code, _, err = run_cli("monitor", "--mission", MISSION, stdin=text.encode())
        assert code == 2
        codes.append(re.findall(r"error\[(\w+)\]", err))
    assert codes[0] == codes[1] == ["V003"]


def test_malformed_lines_are_placed_at_their_column() -> None:
    code, _, err = run_cli("monitor", "--mission", MISSION, stdin=b"t,x,y\n0, abc,1\n")
    assert code == 2
    assert err.startswith("<stdin>:2:4: error[M053]: not a number: 'abc'"), err
    assert "hint:" in err
    code, _, err = run_cli("monitor", "--mission", MISSION, stdin=b"t x y\n0  1 abc\n")
    assert err.startswith("<stdin>:2:6: error[M053]: not a number: 'abc'"), err
    code, _, err = run_cli("monitor", "--mission", MISSION, stdin=b'  {"t": 0, "x" 1}\n')
    assert code == 2
    assert err.startswith("<stdin>:1:16: error[M053]"), err  # where the colon is missing
    code, _, err = run_cli("monitor", "--mission", MISSION, stdin=b"t,x,y\n# only a header\n")
    assert code == 2
    assert err.startswith("<stdin>: error[V002]")
    assert "hint:" in err


def test_a_time_bound_is_refused_at_the_phrase_that_carries_it(tmp_path: Path) -> None:
    mission = tmp_path / "timed.yaml"
    text = Path(MISSION).read_text(encoding="utf-8")
    text = text.replace("- avoid hazard", "- visit dock within 60 s")
    mission.write_text(text, encoding="utf-8")
    line = text.splitlines().index("  - visit dock within 60 s") + 1
    code, _, err = run_cli("monitor", "--mission", str(mission), stdin=b"t,x,y\n0,1,1\n")
    assert code == 2
    assert err.startswith(f"{mission}:{line}:5: error[F010]"), err


def test_a_verdict_once_final_is_never_taken_back(tmp_path: Path) -> None:
    """The task reached, then a hole entered: the task stays satisfied, the workspace line
    says violated, and the run (last line, exit code) is violated, as `tlmpc verify`."""
    mission = tmp_path / "m.yaml"
    mission.write_text(
        "version: 1\nname: m\nworkspace:\n  boundary: {rect: [0, 0, 10, 10]}\n"
        "  holes:\n    - {rect: [4.5, 7, 5.5, 9]}\nregions:\n  a: {rect: [6, 6, 8, 8]}\n"
        "  o: {rect: [2, 2, 4, 4]}\n  b: {rect: [7, 1, 9, 3]}\n"
        "robot: {start: [1, 1], max_speed: 1.0}\nltl: '(!o U a) & F b'\n",
        encoding="utf-8",
    )
    log = tmp_path / "log.csv"
    log.write_text(
        "t,x,y\n2.083,6.577,6.246\n6.882,5.854,8.287\n10.099,7.405,1.286\n"
        "13.692,1.05,9.313\n18.278,5.629,8.316\n",
        encoding="utf-8",
    )
    code, out, _ = run_cli("monitor", "--mission", str(mission), str(log), "--jsonl")
    events = [json.loads(line) for line in out.splitlines()]
    assert [e["verdict"] for e in events if e["subject"] == "task"] == [
        "inconclusive",
        "satisfied",
    ]
    assert [e["verdict"] for e in events if e["subject"] == "workspace"] == ["violated"]
    assert code == 1
    verified = run_cli("verify", str(log), "--mission", str(mission))
    assert verified[0] == 1


def replay_changes(base: dict[str, Any], samples: np.ndarray) -> list[tuple[str, str]]:
    monitor = Monitor(base)
    seen: list[tuple[str, str]] = []
    for t, x, y in samples.tolist():
        monitor.add(t, x, y)
        seen += [(c.subject, c.verdict) for c in monitor.changes()]
    seen += [(c.subject, c.verdict) for c in monitor.finish()]
    return seen


@pytest.mark.slow
@settings(max_examples=60, deadline=None)
@given(samples=walks(), formula=formulas(max_leaves=6), radius=st.sampled_from([0.0, 0.3]))
def test_no_subject_changes_after_a_final_verdict(
    samples: np.ndarray, formula: Any, radius: float
) -> None:
    """LTL3: a good or bad prefix stays one; what the monitor announced as satisfied or
    violated is never changed by a later pose."""
    base = document(to_text(formula), "right", radius)
    try:
        seen = replay_changes(base, samples)
    except UsageError:
        return
    final: dict[str, str] = {}
    for subject, verdict in seen:
        assert subject not in final, (subject, final[subject], verdict)
        if verdict in ("satisfied", "violated"):
            final[subject] = verdict


def test_a_transformed_log_gets_the_verdicts_verify_gives_it(tmp_path: Path) -> None:
    """--transform: the monitor's poses are the offline verifier's (the oracle)."""
    yaw, dx, dy = 0.5, -100.0, 50.0
    c, s = np.cos(yaw), np.sin(yaw)
    # the poses of POSES in a frame turned by yaw and shifted far away: read untransformed,
    # they would never meet the hazard
    logged = [(t, c * (x - dx) + s * (y - dy), -s * (x - dx) + c * (y - dy)) for t, x, y in POSES]
    log = tmp_path / "odom.csv"
    log.write_text(csv_of(logged), encoding="utf-8")
    flags = ["--mission", MISSION, f"--transform={dx},{dy},{yaw}"]
    verified = run_cli("verify", str(log), *flags, "--json")
    monitored = run_cli("monitor", str(log), *flags, "--jsonl")
    assert verified[0] == monitored[0] == 1
    offline = json.loads(verified[1])["result"]
    live = {e["subject"]: e["verdict"] for e in map(json.loads, monitored[1].splitlines())}
    assert {r["conjunct"]: r["verdict"] for r in offline["conjuncts"]} == {
        k: v for k, v in live.items() if k not in ("task", "workspace")
    }
    assert live["G !hazard"] == "violated"
