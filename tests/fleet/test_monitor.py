"""Live monitoring against the offline verifier: every log replayed through both gives the
same final verdict for every conjunct, the task and the workspace; the monitor's memory does
not grow with the log."""

from __future__ import annotations

import io
import itertools
import json
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from strategies import formulas
from test_stream_equivalence import document, walks

from tlmpc.base.errors import UsageError
from tlmpc.cli import main
from tlmpc.fleet.monitor import Monitor
from tlmpc.fleet.progression import residue, value
from tlmpc.ltl.ast import Prop, Until
from tlmpc.ltl.parser import parse_ltl
from tlmpc.ltl.printer import to_text
from tlmpc.verify import verify_document
from tlmpc.verify.evaluate import truth_atoms
from tlmpc.verify.semantics import evaluate, three_valued

ROOT = Path(__file__).resolve().parents[2]


def replay(base: dict[str, Any], samples: np.ndarray) -> Monitor:
    monitor = Monitor(base)
    for t, x, y in samples.tolist():
        monitor.add(t, x, y)
    monitor.finish()
    return monitor


@pytest.mark.slow
@settings(max_examples=100, deadline=None)
@given(
    samples=walks(),
    formula=formulas(max_leaves=6),
    convention=st.sampled_from(["right", "closed"]),
    radius=st.sampled_from([0.0, 0.0, 0.3]),
)
def test_monitor_ends_where_the_offline_verifier_does(
    samples: np.ndarray, formula: Any, convention: str, radius: float
) -> None:
    base = document(to_text(formula), convention, radius)
    try:
        offline = verify_document({**base, "points": samples.tolist()})
    except UsageError:
        with pytest.raises(UsageError):
            replay(base, samples)
        return
    monitor = replay(base, samples)
    for report in offline.conjuncts:
        assert monitor.verdicts[report.conjunct] == report.outcome, report.conjunct
    assert monitor.outcome == offline.outcome
    assert (monitor.excursion is not None) == (offline.workspace_violation is not None)
    if offline.workspace_violation is not None and radius == 0.0:
        # (with a body, the offline verifier reports excursions in preference to earlier
        # contacts, the monitor the first it meets; both say the workspace is violated)
        assert monitor.excursion is not None
        assert monitor.excursion.time == offline.workspace_violation.time


@settings(max_examples=300, deadline=None)
@example(  # a point piece in a whose successor leaves a for b: the closed point rule
    formula=Until(Prop("a"), Prop("b")),
    word=[frozenset("a"), frozenset("b"), frozenset()],
    points=[True, False] * 4,
)
@given(
    formula=formulas(props=("a", "b"), max_leaves=6),
    word=st.lists(st.frozensets(st.sampled_from("ab")), min_size=1, max_size=8),
    points=st.lists(st.booleans(), min_size=8, max_size=8),
)
def test_progression_is_the_evaluator_on_words(
    formula: Any, word: list[frozenset[str]], points: list[bool]
) -> None:
    """Progress through all letters but the last, evaluate the last: the offline evaluator's
    three-valued truth of the whole word (with and without the closed point rule)."""
    from tlmpc.fleet.progression import Piece, progress

    names = ["a", "b", "c", "d"]
    labels = np.array([[n in letter for n in names] for letter in word], dtype=bool)
    for closed in (False, True):
        is_point = np.array(points[: len(word)]) if closed else None
        evaluated = evaluate(
            formula, truth_atoms(labels, names), labels.shape[0], "open", is_point=is_point
        )
        expected = int(three_valued(evaluated)[0])
        pieces = [
            Piece(letter, point_rule=closed and bool(points[k])) for k, letter in enumerate(word)
        ]
        r = residue(formula)
        for piece in pieces[:-1]:
            r = progress(r, piece)
        assert value(r, pieces[-1:]) == expected


@pytest.mark.slow
def test_memory_does_not_grow_with_the_log() -> None:
    base = document("G F a & G F d & G !c & (!d U a)", "right", 0.0)
    monitor = Monitor(base)
    loop = np.array([[2.0, 2.0], [7.0, 6.0], [2.0, 2.0]])
    sizes = []
    t = 0.0
    for _lap in range(30):
        for start, end in itertools.pairwise(loop):
            for k in range(200):
                t += 0.05
                x, y = start + (end - start) * k / 200
                monitor.add(t, float(x), float(y))
        sizes.append(len(repr(monitor.residues)) + len(repr(monitor.task)))
        assert monitor.reducer.kept == []
    assert max(sizes[2:]) == sizes[2]
    assert monitor.verdicts["G !c"] == "violated"  # the diagonal crosses c


def run_cli(*argv: str, stdin: str | None = None) -> tuple[int, str, str]:
    import sys

    out, err = io.StringIO(), io.StringIO()
    saved = sys.stdin
    if stdin is not None:
        sys.stdin = io.TextIOWrapper(io.BytesIO(stdin.encode("utf-8")), encoding="utf-8")
    try:
        code = main(list(argv), out=out, err=err)
    finally:
        sys.stdin = saved
    return code, out.getvalue(), err.getvalue()


def test_json_lines_on_stdin() -> None:
    mission = str(ROOT / "specs" / "reach-avoid.yaml")
    poses = [(0, 1, 1), (10, 4, 2), (20, 8.5, 2), (30, 10.8, 6.8)]
    text = "".join(json.dumps({"t": t, "x": x, "y": y}) + "\n" for t, x, y in poses)
    code, out, _ = run_cli("monitor", "--mission", mission, "--jsonl", stdin=text)
    assert code == 1
    events = [json.loads(line) for line in out.splitlines()]
    broken = [e for e in events if e["subject"] == "G !hazard" and e["verdict"] == "violated"]
    assert broken[0]["t"] == 20


def test_following_a_growing_log(tmp_path: Path) -> None:
    mission = str(ROOT / "specs" / "reach-avoid.yaml")
    log = tmp_path / "live.csv"
    log.write_text("t,x,y\n0,1,1\n", encoding="utf-8")

    def robot() -> None:
        for t, x, y in [(10, 4, 2), (20, 8.5, 2), (30, 10.8, 6.8), (40, 9, 2)]:
            time.sleep(0.1)
            with open(log, "a", encoding="utf-8") as stream:
                stream.write(f"{t},{x},{y}\n")

    writer = threading.Thread(target=robot)
    writer.start()
    code, out, _ = run_cli("monitor", str(log), "--mission", mission, "--follow", "--idle", "1")
    writer.join()
    assert code == 1
    assert "t=20 s  G !hazard: violated" in out
    assert "after 5 poses" in out


def test_bad_poses_exit_2(tmp_path: Path) -> None:
    mission = str(ROOT / "specs" / "reach-avoid.yaml")
    code, _, err = run_cli("monitor", "--mission", mission, stdin="t,x,y\n1,1,1\n0,1,1\n")
    assert code == 2
    assert "V005" in err
    code, _, err = run_cli("monitor", "--mission", mission, stdin='{"t": 1}\n')
    assert code == 2
    assert "M053" in err


def test_parse_ltl_residue_of_every_operator() -> None:
    formula = parse_ltl("(a W b) & (a M b) & (a R b) & (a <-> b) & (a -> F b)")
    assert value(residue(formula), []) == 0


def test_a_time_bound_is_refused_with_f010(tmp_path: Path) -> None:
    mission = tmp_path / "timed.yaml"
    text = (ROOT / "specs" / "reach-avoid.yaml").read_text(encoding="utf-8")
    mission.write_text(text.replace("- avoid hazard", "- visit dock within 60 s"), encoding="utf-8")
    code, _, err = run_cli("monitor", "--mission", str(mission), stdin="t,x,y\n0,1,1\n")
    assert code == 2
    assert err.startswith(f"{mission}:"), err  # placed in the mission
    assert "error[F010]" in err


@pytest.mark.parametrize(
    "rows",
    [
        "0,1,1\n1,nan,1\n",  # V003
        "0,1,1\n1e13,1,1\n",  # V024: a time beyond any log
        "0,1,1\n1,5e12,1\n",  # V024: a coordinate
        "0,1,1\n2,1,1\n1,1,1\n",  # V005
        "0,1,1\n1,1,1\n1,2,1\n",  # V020
    ],
)
def test_a_pose_the_verifier_refuses_is_refused_alike(tmp_path: Path, rows: str) -> None:
    mission = str(ROOT / "specs" / "reach-avoid.yaml")
    log = tmp_path / "log.csv"
    log.write_text("t,x,y\n" + rows, encoding="utf-8")
    verified, _, offline = run_cli("verify", str(log), "--mission", mission)
    monitored, _, live = run_cli("monitor", str(log), "--mission", mission)
    codes = [part.split("]")[0] for part in offline.split("error[")[1:]]
    assert verified == monitored == 2
    assert codes
    assert f"error[{codes[0]}]" in live, live


@pytest.mark.parametrize("pose", ['{"t": 0, "x": "5", "y": 1}', '{"t": true, "x": 1, "y": 1}'])
def test_a_json_pose_of_text_or_truth_values_is_refused(pose: str) -> None:
    mission = str(ROOT / "specs" / "reach-avoid.yaml")
    code, _, err = run_cli("monitor", "--mission", mission, stdin=pose + "\n")
    assert code == 2
    assert "M053" in err
