"""An edited strategy.json whose explicit machine the executor could not step is Q123 (exit 2
from `tlmpc simulate`, a UsageError from `tlmpc.reactive_executor`), never a KeyError or an
IndexError from inside the stepping."""

from __future__ import annotations

import io
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

import tlmpc
from tlmpc.cli import main
from tlmpc.io.outdir import write_artifacts
from tlmpc.pipeline.stages import compile_mission

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def guard(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("guard")
    write_artifacts(folder, compile_mission(ROOT / "specs" / "reactive" / "guard.yaml").artifacts)
    return folder


def _without_a_value(strategy: dict[str, Any]) -> None:
    del strategy["nodes"][-1]["state"]["alarm"]


def _transition_past_the_nodes(strategy: dict[str, Any]) -> None:
    strategy["transitions"][0][1] = len(strategy["nodes"])


def _initial_past_the_nodes(strategy: dict[str, Any]) -> None:
    strategy["initial"][0] = len(strategy["nodes"]) + 3


def _fewer_nodes(strategy: dict[str, Any]) -> None:
    strategy["nodes"] = strategy["nodes"][:-1]


EDITS = [_without_a_value, _transition_past_the_nodes, _initial_past_the_nodes, _fewer_nodes]


def _edited(guard: Path, into: Path, edit: Callable[[dict[str, Any]], None]) -> Path:
    into.mkdir()
    for entry in guard.iterdir():
        (into / entry.name).write_bytes(entry.read_bytes())
    strategy = json.loads((into / "strategy.json").read_text())
    assert "nodes" in strategy  # the explicit machine (small strategies)
    edit(strategy)
    (into / "strategy.json").write_text(json.dumps(strategy))
    return into


@pytest.mark.parametrize("edit", EDITS)
def test_simulate_refuses_the_machine(guard: Path, tmp_path: Path, edit: Any) -> None:
    folder = _edited(guard, tmp_path / "out", edit)
    err = io.StringIO()
    argv = ["simulate", str(folder), "--events", "20", "-o", str(tmp_path / "trace.json")]
    code = main(argv, io.StringIO(), err)
    assert code == 2, err.getvalue()
    assert f"{folder / 'strategy.json'}: error[Q123]" in err.getvalue()


@pytest.mark.parametrize("edit", EDITS)
def test_the_executor_refuses_the_machine(guard: Path, tmp_path: Path, edit: Any) -> None:
    folder = _edited(guard, tmp_path / "out", edit)

    def step_once() -> None:
        executor = tlmpc.reactive_executor(folder)
        executor.command((1.0, 1.0), 0.0, {"person": False, "alarm": False})

    with pytest.raises(tlmpc.UsageError) as refused:
        step_once()
    assert refused.value.diagnostics[0].code == "Q123"


def test_the_compiled_machine_is_stepped(guard: Path) -> None:
    executor = tlmpc.reactive_executor(guard)
    executor.command((1.0, 1.0), 0.0, {"person": False, "alarm": False})
    assert executor.status == "following"
