"""docs/automata.md's highlights table quotes the sizes the translator gives today.

Each row names one formula of ``formulas.txt`` (or two, ``dac11 / dac13``), by its name or by
its formula in backquotes; its TGBA column holds ``states / sets`` for one formula and the
states of each for two, its BA column the degeneralized states, its spin column spin's
trimmed count from ``formulas.txt`` (``timeout`` where there is none).
"""

from __future__ import annotations

import re
from pathlib import Path

from test_automata_formats import benchmark

from tlmpc.automata import degeneralize, translate
from tlmpc.ltl import parse_ltl

DOC = Path(__file__).resolve().parents[2] / "docs" / "automata.md"
HEADER = "| formula | TGBA states / sets | BA | spin | time |"


def _rows() -> list[list[str]]:
    text = DOC.read_text(encoding="utf-8")
    table = text[text.index(HEADER) :].split("\n\n", 1)[0].splitlines()[2:]
    return [[cell.strip() for cell in line.strip("|").split("|")] for line in table]


def _names(cell: str) -> list[str]:
    by_name = {name: name for name, _, _ in benchmark()}
    by_text = {text: name for name, _, text in benchmark()}
    quoted = re.search(r"`([^`]*)`", cell)
    words = cell.split("`")[0].split(" / ")
    names = [by_name.get(word.strip()) for word in words]
    if None in names:
        assert quoted is not None, f"{cell!r}: no formula of formulas.txt by that name"
        names = [by_text[quoted.group(1)]]
    return [name for name in names if name is not None]


def test_the_highlights_quote_todays_sizes() -> None:
    rows = _rows()
    assert len(rows) >= 6
    formulas = {name: (spin, text) for name, spin, text in benchmark()}
    for formula_cell, tgba_cell, ba_cell, spin_cell, _time in rows:
        names = _names(formula_cell)
        tgbas = [translate(parse_ltl(formulas[name][1])) for name in names]
        bas = [degeneralize(tgba) for tgba in tgbas]
        if len(names) == 1:
            expected_tgba = f"{tgbas[0].num_states} / {tgbas[0].num_acc}"
        else:
            expected_tgba = " / ".join(str(tgba.num_states) for tgba in tgbas)
        assert tgba_cell == expected_tgba, formula_cell
        assert ba_cell == " / ".join(str(ba.num_states) for ba in bas), formula_cell
        spins = [formulas[name][0] for name in names]
        quoted = spin_cell.split(" (")[0]
        assert quoted == " / ".join("timeout" if s is None else str(s) for s in spins), formula_cell
