"""Benchmark families of Next-free formulas, and Spot as the oracle (tests and bench only).

Families: the Dwyer–Avrunin–Corbett patterns, Etessami–Holzmann and Somenzi–Bloem (Spot's
``genltl`` numbering, X-free members and their negations), robotics families (cover, sequence,
patrol, response conjunctions, nested avoid-until sequences, reach-avoid, many ``G F``), and
random Next-free formulas drawn by ``spot.randltl``.  Formulas are handed to tlmpc as text in
its own syntax (:func:`to_tlmpc`), never through tlmpc's printer, so the printer is not part of
the oracle.

The comparison is apples to apples: tlmpc's :func:`translate` without ``letters`` (every one of
the 2^|AP| valuations is a letter) against ``spot.translate(f, "TGBA", "Small", "High")``, both
transition-based generalized Büchi automata; the number of states is compared.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import spot
import spot.gen as spot_gen

_BINARY = {
    spot.op_U: "U",
    spot.op_R: "R",
    spot.op_W: "W",
    spot.op_M: "M",
    spot.op_Implies: "->",
    spot.op_Equiv: "<->",
}


def to_tlmpc(f: Any) -> str:
    """A Spot formula (no X) in tlmpc's syntax, fully parenthesised."""
    kind = f.kind()
    if kind == spot.op_tt:
        return "true"
    if kind == spot.op_ff:
        return "false"
    if kind == spot.op_ap:
        name = str(f.ap_name())
        return name if name.isascii() and name.isidentifier() else '"' + name + '"'
    if kind == spot.op_Not:
        return "!(" + to_tlmpc(f[0]) + ")"
    if kind == spot.op_F:
        return "F(" + to_tlmpc(f[0]) + ")"
    if kind == spot.op_G:
        return "G(" + to_tlmpc(f[0]) + ")"
    if kind in (spot.op_And, spot.op_Or):
        joiner = " & " if kind == spot.op_And else " | "
        return "(" + joiner.join("(" + to_tlmpc(child) + ")" for child in f) + ")"
    if kind in _BINARY:
        return f"(({to_tlmpc(f[0])}) {_BINARY[kind]} ({to_tlmpc(f[1])}))"
    if kind == spot.op_Xor:
        return f"!(({to_tlmpc(f[0])}) <-> ({to_tlmpc(f[1])}))"
    raise ValueError(f"not a Next-free LTL formula: {f}")


def _has_next(f: Any) -> bool:
    return any(g.kind() == spot.op_X for g in _subformulas(f))


def _subformulas(f: Any) -> Iterator[Any]:
    yield f
    for child in f:
        yield from _subformulas(child)


def _literature(pattern: Any) -> list[str]:
    out = []
    for f in spot_gen.ltl_patterns(pattern):
        if _has_next(f):
            continue
        out.append(str(f))
        out.append(str(spot.formula_Not(f)))
    return out


def _conj(parts: list[str]) -> str:
    return " & ".join(f"({p})" for p in parts)


def robotics() -> list[str]:
    """Mission-shaped families: cover, sequence, patrol, response, avoid-until, reach-avoid."""
    out: list[str] = []
    for n in range(1, 7):
        out.append(_conj([f"F p{i}" for i in range(1, n + 1)]))  # cover-n
    for n in range(1, 8):  # seq-n
        text = f"p{n}"
        for i in range(n - 1, 0, -1):
            text = f"p{i} & F({text})"
        out.append(f"F({text})")
    for n in range(1, 9):
        out.append(_conj([f"G F p{i}" for i in range(1, n + 1)]))  # patrol-n
    out.append(_conj([f"G F p{i}" for i in range(1, 13)]))  # twelve recurrences
    for n in range(1, 6):  # response conjunctions
        out.append(_conj([f"G(s{i} -> F p{i})" for i in range(1, n + 1)]))
    for n in range(1, 6):  # nested avoid-until sequences
        text = f"!o{n} U p{n}"
        for i in range(n - 1, 0, -1):
            text = f"!o{i} U (p{i} & ({text}))"
        out.append(text)
    for n in range(1, 5):  # reach-avoid: visit all, avoid obstacles, stay at the end
        parts = [f"F p{i}" for i in range(1, n + 1)] + ["G !o"]
        out.append(_conj(parts))
        out.append(_conj([f"!o U p{i}" for i in range(1, n + 1)]))
        out.append(_conj([*parts, "F G home"]))
        out.append(_conj([f"G F p{i}" for i in range(1, n + 1)] + ["G !o"]))
    out.append("F(p2 & F(p3 & F(p4 & ((!p2 & !p3) U p1))))")
    out.append("F(p1 & F(p2 & F p3)) & F(q1 & F(q2 & F q3))")
    out.append("G(req -> (!o U goal)) & G F base")
    out.append("(!p2 U p1) & F p2 & G(p3 -> F p1)")
    return out


def random_formulas(count: int, seed: int, *, aps: int = 4, tree_size: int = 20) -> list[str]:
    """``count`` distinct random Next-free formulas (``spot.randltl``, X and xor excluded).

    Call it once per process: Spot 2.13 fails to parse the priority string on a second
    ``randltl`` call ("failed to parse LTL priorities").
    """
    generator = spot.randltl(
        aps,
        count,
        seed=seed,
        tree_size=tree_size,
        ltl_priorities="X=0,xor=0",
    )
    return [str(f) for f in generator]


def families(
    *, random_count: int = 200, random_seed: int = 0, held_out: int = 0
) -> dict[str, list[str]]:
    """The benchmark families, in Spot's syntax (convert with :func:`to_tlmpc`).

    ``held-out`` (when asked for) continues the random stream after ``random``: formulas never
    used while tuning the translator.
    """
    drawn = random_formulas(random_count + held_out, random_seed)
    groups = {
        "dac": _literature(spot_gen.LTL_DAC_PATTERNS),
        "eh": _literature(spot_gen.LTL_EH_PATTERNS),
        "sb": _literature(spot_gen.LTL_SB_PATTERNS),
        "robotics": [str(spot.formula(f)) for f in robotics()],
        "random": drawn[:random_count],
    }
    if held_out:
        groups["held-out"] = drawn[random_count:]
    return groups


def spot_automaton(text: str) -> Any:
    """Spot's default TGBA (transition-based generalized Büchi, small, high effort)."""
    return spot.translate(spot.formula(text), "TGBA", "Small", "High")
