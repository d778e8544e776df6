"""Language equivalence with ``spin -f`` (the ltlcross method) on the X-free benchmark formulas.

Both products A_f × spin(¬f) and spin(f) × A_¬f must be empty.  Spin's never claims are read by
a small parser here (labels, ``if``/``do`` options, ``goto``, ``skip``, ``false``,
``atomic{… assert …}`` = an edge to ``accept_all``).
"""

from __future__ import annotations

import itertools
import re
import shutil
import subprocess

import pytest
from automata_oracles import accepting_cycle
from ci_oracles import oracle_required
from test_automata_formats import benchmark

from tlmpc.automata import guard_holds, translate
from tlmpc.automata.model import Automaton
from tlmpc.ltl import parse_ltl, to_spin
from tlmpc.ltl.ast import Formula, Not, is_temporal

pytestmark = oracle_required(shutil.which("spin") is not None, "spin")

Claim = tuple[int, list[list[tuple[str, int]]], set[int]]  # initial, edges per state, accepting


def parse_never_claim(text: str) -> Claim:
    names: dict[str, int] = {}
    edges: list[list[tuple[str, int]]] = []
    accepting: set[int] = set()
    pending: list[str] = []
    current = -1

    def state(label: str) -> int:
        if label not in names:
            names[label] = len(edges)
            edges.append([])
        return names[label]

    raw: list[tuple[int, str, str]] = []
    for line in text.splitlines():
        line = line.strip()
        if re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*:", line):
            pending.append(line[:-1])
            continue
        if pending:
            current = state(pending[0])
            for alias in pending[1:]:
                names[alias] = current
            if any(p.startswith("accept") for p in pending):
                accepting.add(current)
            pending = []
        if line.startswith("::"):
            body = line[2:].strip()
            atomic = re.fullmatch(r"atomic\s*\{\s*(.*?)\s*->\s*assert.*\}", body)
            if atomic:
                raw.append((current, atomic.group(1), "accept_all"))
                continue
            guard, target = re.fullmatch(r"(.*?)\s*->\s*goto\s+(\w+)", body).groups()  # type: ignore[union-attr]
            raw.append((current, guard, target))
        elif line.startswith("skip"):
            raw.append((current, "1", "__self__"))
    for src, guard, target in raw:
        if target == "accept_all":
            dst = state("accept_all")
            accepting.add(dst)
            if not any(t == dst for _, t in edges[dst]):
                edges[dst].append(("1", dst))
        else:
            dst = src if target == "__self__" else state(target)
        edges[src].append((guard, dst))
    return names.get("T0_init", 0), edges, accepting


def spin_guard(guard: str, letter: frozenset[str]) -> bool:
    expr = guard.replace("&&", " and ").replace("||", " or ").replace("!", " not ")
    expr = re.sub(r"\btrue\b", "True", re.sub(r"\bfalse\b", "False", expr))
    expr = re.sub(r"\b1\b", "True", re.sub(r"\b0\b", "False", expr))
    env: dict[str, bool | None] = {
        name: (name in letter) for name in re.findall(r"[A-Za-z_]\w*", expr)
    }
    env.update({"True": True, "False": False, "and": None, "or": None, "not": None})
    return bool(eval(expr, {"__builtins__": {}}, {k: v for k, v in env.items() if v is not None}))


def spin_claim(text: str) -> Claim:
    done = subprocess.run(["spin", "-f", text], capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr
    return parse_never_claim(done.stdout)


def intersection_empty(aut: Automaton, claim: Claim, props: list[str]) -> bool:
    letters = [
        frozenset(p for p, bit in zip(props, bits, strict=True) if bit)
        for bits in itertools.product((False, True), repeat=len(props))
    ]
    initial, claim_edges, accepting = claim
    k = aut.num_acc
    out: dict[int, list[tuple[int, int, object]]] = {}
    for e in aut.edges:
        out.setdefault(e.src, []).append((e.dst, sum(1 << m for m in e.marks), e.guard))

    def graph_of(node: tuple[int, int]) -> list[tuple[tuple[int, int], int]]:
        q, s = node
        bit = (1 << k) if s in accepting else 0
        result = []
        for letter in letters:
            for dst, mask, guard in out.get(q, []):
                if not guard_holds(guard, letter):  # type: ignore[arg-type]
                    continue
                for g, t in claim_edges[s]:
                    if spin_guard(g, letter):
                        result.append(((dst, t), mask | bit))
        return result

    return not accepting_cycle((aut.initial, initial), graph_of, (1 << (k + 1)) - 1)


FAST = [row for row in benchmark() if row[1] is not None and row[1] <= 16]


def test_claim_parser_sanity() -> None:
    claim = spin_claim("[] <> a")
    aut = translate(parse_ltl("G F a"))
    assert not intersection_empty(aut, claim, ["a"])  # same language: non-empty product
    assert intersection_empty(aut, spin_claim("<> [] !a"), ["a"])


def temporal_depth(formula: Formula) -> int:
    """How deeply temporal operators nest in ``formula``."""
    below = max((temporal_depth(child) for child in formula.children()), default=0)
    return below + (1 if is_temporal(formula) else 0)


# The explicit product enumerates every letter: formulas over more than 5 propositions are
# left to the Spot comparison (tests/automata/test_automata_spot.py), which also holds the
# benchmark's formulas nesting temporal operators five deep (Dwyer's patterns, the sequences):
# SPIN's tableau for their negations takes 11 and 25 s alone, against 2 s for the rest.
SMALL = [
    (r[0], r[2])
    for r in FAST
    if len(parse_ltl(r[2]).props()) <= 5 and temporal_depth(parse_ltl(r[2])) <= 4
]


@pytest.mark.slow
@pytest.mark.parametrize(("name", "text"), SMALL)
def test_same_language_as_spin(name: str, text: str) -> None:
    formula = parse_ltl(text)
    props = sorted(formula.props())
    negated_claim = spin_claim(to_spin(Not(formula)))
    claim = spin_claim(to_spin(formula))
    assert intersection_empty(translate(formula), negated_claim, props), name
    assert intersection_empty(translate(Not(formula)), claim, props), name
