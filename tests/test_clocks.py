"""No stage decides anything by the clock: the same input gives the same bytes on any machine.

Every file of ``tlmpc/`` is read.  No module may read CPU time (``process_time``,
``thread_time``); a wall clock (``perf_counter``, ``monotonic``, ``time.time``, ``datetime.now``)
only in the modules of :data:`TIMING_FIELDS`, whose readings go into fields that report time
(``seconds`` in summary.json and the stage artifacts' stats, the progress line), and there never
into a comparison (a deadline).  Budgets count operations instead (``tlmpc.automata.work``).
"""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "tlmpc"

CPU_CLOCKS = {"process_time", "process_time_ns", "thread_time", "thread_time_ns"}
WALL_CLOCKS = {"perf_counter", "perf_counter_ns", "monotonic", "monotonic_ns", "time", "time_ns"}
DATETIME_CLOCKS = {"now", "utcnow", "today"}

#: The modules that may read a wall clock, and what for.
TIMING_FIELDS = {
    "tlmpc/pipeline/stages.py": "each stage's seconds in summary.json",
    "tlmpc/abstraction/build.py": "the abstraction's build seconds",
    "tlmpc/planning/plan.py": "the witness's planning seconds",
    "tlmpc/control/synthesize.py": "the controllers' prepare and solve seconds",
    "tlmpc/base/progress.py": "the elapsed time on the progress line",
    "tlmpc/commands/automaton.py": "the seconds of `tlmpc automaton --stats`",
}


def _imported_clocks(tree: ast.AST) -> set[str]:
    """The names a module imports from ``time`` (``from time import monotonic as tick``)."""
    return {
        alias.asname or alias.name
        for node in ast.walk(tree)
        if isinstance(node, ast.ImportFrom) and node.module == "time"
        for alias in node.names
    }


def _clock_calls(node: ast.AST, imported: set[str]) -> list[tuple[int, str]]:
    """``(line, name)`` of every call of a clock under ``node`` (``time.X()``, a name
    ``imported`` from time, ``datetime.now()`` and the like), in source order."""
    calls = []
    for call in ast.walk(node):
        if not isinstance(call, ast.Call):
            continue
        func = call.func
        if isinstance(func, ast.Attribute) and isinstance(func.value, ast.Name):
            if (func.value.id == "time" and func.attr in CPU_CLOCKS | WALL_CLOCKS) or (
                func.value.id in {"datetime", "date"} and func.attr in DATETIME_CLOCKS
            ):
                calls.append((call.lineno, func.attr))
        elif isinstance(func, ast.Name) and func.id in imported:
            calls.append((call.lineno, func.id))
    return sorted(calls)


def _compared_clocks(tree: ast.AST) -> list[int]:
    """Lines where a clock reading (a call, or a name assigned one) is compared: a deadline."""
    imported = _imported_clocks(tree)
    readings: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Assign) and _clock_calls(node.value, imported):
            readings.update(t.id for t in node.targets if isinstance(t, ast.Name))
    lines = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Compare):
            names = {n.id for n in ast.walk(node) if isinstance(n, ast.Name)}
            if _clock_calls(node, imported) or names & readings:
                lines.append(node.lineno)
    return sorted(lines)


def _sources() -> dict[str, ast.AST]:
    return {
        str(path.relative_to(ROOT)): ast.parse(path.read_text(encoding="utf-8"))
        for path in sorted(PACKAGE.rglob("*.py"))
    }


def test_no_module_reads_cpu_time() -> None:
    found = [
        f"{name}:{line} {clock}"
        for name, tree in _sources().items()
        for line, clock in _clock_calls(tree, _imported_clocks(tree))
        if clock in CPU_CLOCKS
    ]
    assert found == []


def test_wall_clocks_only_for_the_timing_fields() -> None:
    found = [
        f"{name}:{line} {clock}"
        for name, tree in _sources().items()
        for line, clock in _clock_calls(tree, _imported_clocks(tree))
        if name not in TIMING_FIELDS
    ]
    assert found == []


def test_no_clock_reading_is_compared() -> None:
    found = [
        f"{name}:{line}" for name, tree in _sources().items() for line in _compared_clocks(tree)
    ]
    assert found == []


def test_the_checks_see_a_deadline() -> None:
    deadline = ast.parse(
        "import time\nfrom time import monotonic as tick\n"
        "limit = time.process_time() + 1\nstart = tick()\n"
        "while time.perf_counter() < limit: pass\nok = start > 3\n"
    )
    calls = _clock_calls(deadline, _imported_clocks(deadline))
    assert calls == [(3, "process_time"), (4, "tick"), (5, "perf_counter")]
    assert _compared_clocks(deadline) == [5, 6]
    harmless = ast.parse("import time\nstarted = time.perf_counter()\nx = 1 < 2\n")
    assert _compared_clocks(harmless) == []
