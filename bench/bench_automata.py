"""Translator benchmark: TGBA/BA sizes and times beside spin's measured sizes.

Formulas and spin's reference numbers (trimmed state count and ``spin -f`` time, Debian spin
6.5.2, from ``research/spin-sizes.md``) live in ``tests/automata/formulas.txt`` so the tests use
the same set.  When ``spin`` is installed, a live ``spin -f`` time is measured too (5 s timeout).
"""

from __future__ import annotations

import shutil
import statistics
import subprocess
import time
from pathlib import Path
from typing import Any

FORMULAS = Path(__file__).resolve().parent.parent / "tests" / "automata" / "formulas.txt"


def load_formulas(path: Path = FORMULAS) -> list[tuple[str, int | None, str]]:
    """(name, spin trimmed states or None, formula) for every benchmark formula."""
    rows = []
    for line in path.read_text(encoding="utf-8").splitlines():
        if not line.strip() or line.startswith("#"):
            continue
        name, spin_states, _spin_ms, formula = line.split("\t")
        rows.append((name, int(spin_states) if spin_states.isdigit() else None, formula))
    return rows


def _spin_seconds(formula: str, timeout: float) -> float | None:
    from tlmpc.ltl import parse_ltl, to_spin

    text = to_spin(parse_ltl(formula))
    started = time.perf_counter()
    try:
        subprocess.run(["spin", "-f", text], capture_output=True, timeout=timeout, check=False)
    except subprocess.TimeoutExpired:
        return None
    return time.perf_counter() - started


def _clear_caches() -> None:
    # The translator memoizes expansions across calls; time cold translations.
    from tlmpc.automata import terms

    terms.expand.cache_clear()
    terms.implies.cache_clear()


def run(
    repeats: int = 3, *, live_spin: bool = True, spin_timeout: float = 5.0
) -> list[dict[str, Any]]:
    """One row per formula: sizes, median translation time, spin's reference numbers."""
    from tlmpc.automata import degeneralize, translate
    from tlmpc.ltl import parse_ltl

    have_spin = live_spin and shutil.which("spin") is not None
    rows: list[dict[str, Any]] = []
    for name, spin_states, text in load_formulas():
        formula = parse_ltl(text)
        times = []
        ba_times = []
        for _ in range(max(1, repeats)):
            _clear_caches()
            started = time.perf_counter()
            tgba = translate(formula)
            middle = time.perf_counter()
            ba = degeneralize(tgba)
            ba_times.append(time.perf_counter() - middle)
            times.append(middle - started)
        row: dict[str, Any] = {
            "name": name,
            "formula": text,
            "tgba_states": tgba.num_states,
            "tgba_edges": len(tgba.edges),
            "acc_sets": tgba.num_acc,
            "ba_states": ba.num_states,
            "seconds": statistics.median(times),
            "ba_seconds": statistics.median(ba_times),
            "spin_trim_states": spin_states,
        }
        if have_spin:
            row["spin_seconds"] = _spin_seconds(text, spin_timeout)
        rows.append(row)
    return rows


def _markdown(rows: list[dict[str, Any]]) -> str:
    live = any("spin_seconds" in r for r in rows)
    head = "| name | TGBA st | edges | acc | BA st | spin trim st | ms | BA ms |"
    sep = "|---|---:|---:|---:|---:|---:|---:|---:|"
    if live:
        head += " spin ms (live) |"
        sep += "---:|"
    lines = [head, sep]
    for r in rows:
        spin = "–" if r["spin_trim_states"] is None else str(r["spin_trim_states"])
        line = (
            f"| {r['name']} | {r['tgba_states']} | {r['tgba_edges']} | {r['acc_sets']} | "
            f"{r['ba_states']} | {spin} | {r['seconds'] * 1000:.1f} | "
            f"{r['ba_seconds'] * 1000:.1f} |"
        )
        if live:
            s = r.get("spin_seconds")
            line += " timeout |" if s is None else f" {s * 1000:.1f} |"
        lines.append(line)
    worse = [
        r["name"]
        for r in rows
        if r["spin_trim_states"] is not None and r["ba_states"] > r["spin_trim_states"]
    ]
    slow = [r["name"] for r in rows if r["seconds"] + r["ba_seconds"] > 0.1]
    lines.append("")
    lines.append(f"BA larger than spin's trimmed count: {', '.join(worse) or 'none'}")
    lines.append(f"over 100 ms (TGBA + BA): {', '.join(slow) or 'none'}")
    return "\n".join(lines)


if __name__ == "__main__":
    import sys

    print(_markdown(run(live_spin="--no-spin" not in sys.argv)))
