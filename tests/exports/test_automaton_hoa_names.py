"""`tlmpc automaton --format hoa` with odd AP names: Spot reads back exactly the formula's APs
and the same language, or the command refuses (U079) the names its printing would change."""

from __future__ import annotations

import io
import json
from typing import Any

import pytest
from ci_oracles import import_oracle

from tlmpc.automata import to_hoa, translate
from tlmpc.cli import main
from tlmpc.ltl import parse_ltl


def run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    return main(list(argv), out=out, err=err), out.getvalue(), err.getvalue()


def quoted(name: str) -> str:
    """``name`` as a quoted proposition of tlmpc's LTL (escapes ``\\"``, ``\\\\``, ``\\n``)."""
    escaped = name.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n")
    return f'"{escaped}"'


def formula(first: str, second: str) -> str:
    """``F first & G !second`` in tlmpc's LTL."""
    return f"F {quoted(first)} & G !{quoted(second)}"


#: Names an HOA string holds as they are (``"`` and ``\\`` escaped): printed unchanged.
PRINTABLE = ['say "hi"', "back\\slash", "two\nlines", "--BODY--", "AP:", "Inf(0)", "é ü"]
#: Names with characters tlmpc prints escaped (control and direction characters).
UNPRINTABLE = ["\u202e", "rtl\u202ex", "\x1b[1m", "bell\x07"]


def spot_reads(hoa: str, first: str, second: str) -> None:
    """Spot reads ``hoa`` with exactly the APs ``first`` and ``second`` and the language of
    ``F first & G !second`` (built with Spot's own constructors, no parsing)."""
    spot: Any = import_oracle("spot")
    automaton = spot.automaton(hoa)
    assert sorted(ap.ap_name() for ap in automaton.ap()) == sorted([first, second])
    ap = spot.formula.ap
    expected = spot.formula.And(
        [spot.formula.F(ap(first)), spot.formula.G(spot.formula.Not(ap(second)))]
    )
    assert spot.are_equivalent(automaton, expected)


@pytest.mark.parametrize("names", [PRINTABLE[i : i + 2] for i in range(0, 6)])
def test_printed_hoa_names_the_formula_s_aps(names: list[str]) -> None:
    first, second = names
    code, hoa, err = run("automaton", formula(first, second))
    assert code == 0, err
    spot_reads(hoa, first, second)


@pytest.mark.parametrize("name", UNPRINTABLE)
def test_hoa_of_an_unprintable_name_is_refused_and_json_keeps_it(name: str) -> None:
    text = formula(name, "u202e")
    code, out, err = run("automaton", text)
    assert code == 2
    assert out == ""
    assert "error[U079]" in err
    code, out, err = run("automaton", text, "--format", "json")
    assert code == 0, err
    assert name in json.loads(out)["aps"]


@pytest.mark.parametrize("name", UNPRINTABLE)
def test_the_hoa_writer_keeps_any_name(name: str) -> None:
    """The library's HOA (no terminal in between) holds the name as HOA defines strings."""
    spot_reads(to_hoa(translate(parse_ltl(formula(name, "u202e")))), name, "u202e")
