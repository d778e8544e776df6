"""Definition-level checks of GR(1) games, independent of the BDD solver.

Formulas are evaluated on explicit valuations; a strategy (Mealy machine) is checked by
enumerating every input valuation at every node, and its liveness by SCCs: a cycle that keeps
every environment goal and misses a system goal exists exactly when, with the edges that fulfil
that system goal removed, some strongly connected component still fulfils every environment
goal on its inner edges.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator, Mapping

from tlmpc.automata.simplify import strongly_connected
from tlmpc.synth.spec import (
    Atom,
    Binary,
    Compare,
    Const,
    Expr,
    GameSpec,
    Nary,
    Not,
    Part,
    Variable,
)
from tlmpc.synth.strategy import MealyMachine

Value = int | bool
State = Mapping[str, Value]


def evaluate(expr: Expr, now: State, nxt: State | None = None) -> bool:
    """The truth of ``expr`` with current values ``now`` and next values ``nxt``."""
    if isinstance(expr, Const):
        return expr.value
    if isinstance(expr, Atom | Compare):
        source = nxt if expr.primed else now
        assert source is not None, "a next value outside a transition"
        value = source[expr.name]
        if isinstance(expr, Atom):
            return bool(value)
        number = int(value)
        return {
            "=": number == expr.value,
            "!=": number != expr.value,
            "<": number < expr.value,
            "<=": number <= expr.value,
            ">": number > expr.value,
            ">=": number >= expr.value,
        }[expr.op]
    if isinstance(expr, Not):
        return not evaluate(expr.arg, now, nxt)
    if isinstance(expr, Nary):
        values = [evaluate(a, now, nxt) for a in expr.args]
        if expr.op == "and":
            return all(values)
        if expr.op == "or":
            return any(values)
        return sum(values) % 2 == 1
    assert isinstance(expr, Binary)
    left, right = evaluate(expr.left, now, nxt), evaluate(expr.right, now, nxt)
    return (not left or right) if expr.op == "->" else left == right


def valuations(variables: tuple[Variable, ...]) -> Iterator[dict[str, Value]]:
    """Every valuation of ``variables`` within their domains."""
    domains: list[list[Value]] = []
    for v in variables:
        if v.is_bool:
            domains.append([False, True])
        else:
            assert v.low is not None
            assert v.high is not None
            domains.append(list(range(v.low, v.high + 1)))
    for combo in itertools.product(*domains):
        yield dict(zip((v.name for v in variables), combo, strict=True))


def holds(parts: tuple[Part, ...], now: State, nxt: State | None = None) -> bool:
    """Whether every part holds."""
    return all(evaluate(p.formula, now, nxt) for p in parts)


def check_strategy(spec: GameSpec, machine: MealyMachine) -> None:
    """Assert that ``machine`` wins ``spec`` (GR(1) game reading), by explicit enumeration."""
    inputs, outputs = spec.owned("env"), spec.owned("sys")
    env_init, sys_init = spec.select("env", "init"), spec.select("sys", "init")
    env_safety, sys_safety = spec.select("env", "safety"), spec.select("sys", "safety")
    env_goals = spec.select("env", "liveness")
    sys_goals = spec.select("sys", "liveness")
    states = machine.states
    starts = [states[i] for i in machine.initial]
    # initial states, per quantification
    if spec.init_mode == "forall_env_exists_sys":
        for x in valuations(inputs):
            if holds(env_init, x):
                match = [s for s in starts if all(s[k] == x[k] for k in x)]
                assert match, f"no initial node for inputs {x}"
                assert all(holds(sys_init, s) for s in match)
    elif spec.init_mode == "all_init":
        for s in valuations(inputs + outputs):
            if holds(env_init, s) and holds(sys_init, s):
                assert any(dict(t) == s for t in starts), f"initial state {s} not served"
    # every node answers every allowed input within the system's safety
    successors: list[list[int]] = [[] for _ in states]
    for source, target in machine.transitions:
        successors[source].append(target)
    for node, state in enumerate(states):
        for x in valuations(inputs):
            # the environment's safety never reads next outputs (the readers refuse it)
            allowed = holds(env_safety, state, {**state, **x})
            targets = [t for t in successors[node] if all(states[t][k] == x[k] for k in x)]
            if not allowed:
                continue
            assert targets, f"node {node} has no answer to inputs {x}"
            for t in targets:
                assert holds(sys_safety, state, states[t]), f"move {node}->{t} breaks safety"
    # liveness: no reachable cycle keeps every environment goal and misses a system goal
    edges = [(s, t) for s, t in machine.transitions]

    def fulfils(goal: Part, edge: tuple[int, int]) -> bool:
        return evaluate(goal.formula, states[edge[0]], states[edge[1]])

    for goal in sys_goals or ():
        kept = [e for e in edges if not fulfils(goal, e)]
        succ: list[list[int]] = [[] for _ in states]
        for src, dst in kept:
            succ[src].append(dst)
        component = strongly_connected(succ, range(len(states)))
        inner: dict[int, list[tuple[int, int]]] = {}
        for src, dst in kept:
            if component[src] == component[dst] and component[src] != -1:
                inner.setdefault(component[src], []).append((src, dst))
        for scc_edges in inner.values():
            assert not all(any(fulfils(g, e) for e in scc_edges) for g in env_goals), (
                f"a cycle keeps the assumptions but never fulfils {goal.text!r}"
            )
