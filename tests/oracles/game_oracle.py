"""Definition-level checks of GR(1) games, independent of the BDD solver.

Formulas are evaluated on explicit valuations; a strategy (Mealy machine) is checked by
enumerating every input valuation at every node, and its liveness by SCCs: a cycle that keeps
every environment goal and misses a system goal exists exactly when, with the edges that fulfil
that system goal removed, some strongly connected component still fulfils every environment
goal on its inner edges.
"""

from __future__ import annotations

import itertools
from collections import deque
from collections.abc import Iterator, Mapping

from tlmpc.base.graphs import csr, strong_components
from tlmpc.synth.counter import CounterStrategy
from tlmpc.synth.spec import (
    Atom,
    Binary,
    Compare,
    Const,
    Expr,
    GameSpec,
    Linear,
    Nary,
    Not,
    Part,
    Variable,
)
from tlmpc.synth.strategy import MealyMachine, _key
from tlmpc.synth.symbolic_strategy import SymbolicStrategy

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
    if isinstance(expr, Linear):
        total = 0
        for coef, name, primed in expr.terms:
            source = nxt if primed else now
            assert source is not None, "a next value outside a transition"
            total += coef * int(source[name])
        return {
            "=": total == expr.value,
            "!=": total != expr.value,
            "<": total < expr.value,
            "<=": total <= expr.value,
            ">": total > expr.value,
            ">=": total >= expr.value,
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


def mentioned(expr: Expr) -> set[tuple[str, bool]]:
    """The variables ``expr`` reads, each with whether it reads its next value: its truth
    depends on no other (:func:`evaluate` reads these and only these)."""
    if isinstance(expr, Const):
        return set()
    if isinstance(expr, Atom | Compare):
        return {(expr.name, expr.primed)}
    if isinstance(expr, Linear):
        return {(name, primed) for _, name, primed in expr.terms}
    if isinstance(expr, Not):
        return mentioned(expr.arg)
    if isinstance(expr, Nary):
        return set().union(*(mentioned(a) for a in expr.args))
    assert isinstance(expr, Binary)
    return mentioned(expr.left) | mentioned(expr.right)


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
    elif spec.init_mode == "one_side" and sys_init:
        # gr1c: "If SYSINIT: f; then the strategy need only choose one initial state
        # satisfying f"
        assert starts, "no initial node"
        assert all(holds(sys_init, s) for s in starts), "an initial node breaks SYSINIT"
    else:
        # ALL_INIT: any state satisfying ENVINIT and SYSINIT; ONE_SIDE_INIT with ENVINIT: f
        # (or neither, "equivalent to ENVINIT: True"): any state satisfying f
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
        component = strong_components(*csr(succ))
        inner: dict[int, list[tuple[int, int]]] = {}
        for src, dst in kept:
            if component[src] == component[dst] and component[src] != -1:
                inner.setdefault(component[src], []).append((src, dst))
        for scc_edges in inner.values():
            assert not all(any(fulfils(g, e) for e in scc_edges) for g in env_goals), (
                f"a cycle keeps the assumptions but never fulfils {goal.text!r}"
            )


def check_counterstrategy(
    spec: GameSpec, counter: CounterStrategy, held: Mapping[str, Value] | None = None
) -> None:
    """Assert that the environment's counterstrategy defeats every system strategy.

    ``held``: outputs that no part of ``spec`` reads, which the counterstrategy keeps at one
    value; only the system's answers with those values must be covered."""
    held = held or {}

    def kept(y: Mapping[str, Value]) -> bool:
        return all(y[name] == value for name, value in held.items())

    outputs = spec.owned("sys")
    env_init, sys_init = spec.select("env", "init"), spec.select("sys", "init")
    env_safety, sys_safety = spec.select("env", "safety"), spec.select("sys", "safety")
    env_goals = spec.select("env", "liveness") or ()
    sys_goals = spec.select("sys", "liveness") or ()
    states = counter.states
    starts = [states[i] for i in counter.initial]
    if spec.init_mode == "forall_env_exists_sys":
        x0 = counter.initial_inputs
        assert x0 is not None
        assert holds(env_init, x0)
        for y in valuations(outputs):
            s = {**x0, **y}
            if kept(y) and holds(sys_init, s):
                assert any(dict(t) == s for t in starts), f"initial answer {y} not covered"
    else:
        assert starts
        for s in starts:
            assert holds(env_init, s)
            assert holds(sys_init, s)
        if spec.init_mode == "one_side" and sys_init:
            # the system picks its start: the environment must defeat every one it may pick
            for s in valuations(spec.owned("env") + outputs):
                if holds(sys_init, s):
                    assert any(dict(t) == s for t in starts), f"start {s} not covered"
    # the environment's moves keep its safety; every allowed system answer is covered
    edges: list[tuple[int, int]] = []
    for node, state in enumerate(states):
        x = counter.moves[node]
        assert holds(env_safety, state, {**state, **x})
        for y in valuations(outputs):
            nxt = {**x, **y}
            if kept(y) and holds(sys_safety, state, nxt):
                targets = [t for t in counter.answers[node] if dict(states[t]) == nxt]
                assert targets, f"node {node}: the answer {y} is not covered"
                edges.extend((node, t) for t in targets)

    def fulfils(goal: Part, edge: tuple[int, int]) -> bool:
        return evaluate(goal.formula, states[edge[0]], states[edge[1]])

    def inner_edges(kept: list[tuple[int, int]]) -> list[list[tuple[int, int]]]:
        succ: list[list[int]] = [[] for _ in states]
        for src, dst in kept:
            succ[src].append(dst)
        component = strong_components(*csr(succ))
        inner: dict[int, list[tuple[int, int]]] = {}
        for src, dst in kept:
            if component[src] == component[dst] and component[src] != -1:
                inner.setdefault(component[src], []).append((src, dst))
        return list(inner.values())

    # no cycle misses an environment goal ...
    for goal in env_goals:
        assert not inner_edges([e for e in edges if not fulfils(goal, e)]), (
            f"a cycle of the counterstrategy never fulfils the assumption {goal.text!r}"
        )
    # ... and no cycle fulfils every system goal
    for scc in inner_edges(edges):
        assert not all(any(fulfils(g, e) for e in scc) for g in sys_goals), (
            "a cycle of the counterstrategy lets the system fulfil every goal"
        )


def ltl(expr: Expr) -> str:
    """``expr`` as a Spot LTL formula (Boolean variables only; primes become X)."""
    if isinstance(expr, Const):
        return "1" if expr.value else "0"
    if isinstance(expr, Atom):
        return f"X({expr.name})" if expr.primed else expr.name
    if isinstance(expr, Compare | Linear):
        raise ValueError("integer variables have no Spot form here")
    if isinstance(expr, Not):
        return f"!({ltl(expr.arg)})"
    if isinstance(expr, Nary):
        op = {"and": " & ", "or": " | ", "xor": " xor "}[expr.op]
        return "(" + op.join(f"({ltl(a)})" for a in expr.args) + ")"
    assert isinstance(expr, Binary)
    return f"(({ltl(expr.left)}) {expr.op} ({ltl(expr.right)}))"


def _conj(parts: tuple[Part, ...]) -> str:
    return " & ".join(f"({ltl(p.formula)})" for p in parts) or "1"


def strict_body(spec: GameSpec) -> str:
    r"""The strict reading after the first state: ``(rho_s W ~rho_e) /\ ((G rho_e /\ GF J^e)
    -> GF J^s)``."""
    env_safety = _conj(spec.select("env", "safety"))
    sys_safety = _conj(spec.select("sys", "safety"))
    env_goals = [f"G F({ltl(p.formula)})" for p in spec.select("env", "liveness")]
    sys_goals = [f"G F({ltl(p.formula)})" for p in spec.select("sys", "liveness")]
    assumption = " & ".join([f"G({env_safety})", *env_goals])
    guarantee = " & ".join(sys_goals) or "1"
    return f"(({sys_safety}) W !({env_safety})) & (({assumption}) -> ({guarantee}))"


def strict_ltl_of(spec: GameSpec) -> str:
    r"""The LTL formula the GR(1) game decides (strict reading, Mealy, gr1c's default initial
    quantification): ``theta_e -> (theta_s /\ (rho_s W ~rho_e) /\ ((G rho_e /\ GF J^e) ->
    GF J^s))``."""
    return (
        f"({_conj(spec.select('env', 'init'))}) -> (({_conj(spec.select('sys', 'init'))}) & "
        f"{strict_body(spec)})"
    )


def spot_realizable(formula: str, outputs: list[str]) -> bool:
    """Spot's verdict on ``formula`` (Mealy: the outputs answer the inputs of the same step)."""
    import spot

    arena = spot.ltl_to_game(spot.formula(formula), outputs, spot.synthesis_info())
    return bool(spot.solve_game(arena))


def spot_verdict(spec: GameSpec) -> bool:
    r"""Whether the game is realizable under its initial quantification, decided by Spot (only
    Boolean variables), the quantification read from gr1c's documentation, not from tlmpc:

    * ALL_ENV_EXIST_SYS_INIT: the strict formula with both initial conditions;
    * ALL_INIT: the system wins from every state satisfying ENVINIT and SYSINIT;
    * ONE_SIDE_INIT: with SYSINIT (and no ENVINIT), from some state satisfying it; else from
      every state satisfying ENVINIT (none: ``ENVINIT: True``).

    The system wins from a state when it wins ``(inputs = v) -> (outputs = v /\ body)``: the
    environment's first inputs are the state's, and the system must answer with its outputs.
    """
    outputs = [v.name for v in spec.owned("sys")]
    if spec.init_mode == "forall_env_exists_sys":
        return spot_realizable(strict_ltl_of(spec), outputs)
    env_init, sys_init = spec.select("env", "init"), spec.select("sys", "init")
    body = strict_body(spec)

    def wins_from(state: dict[str, Value]) -> bool:
        def literals(variables: tuple[Variable, ...]) -> str:
            return " & ".join(f"{'' if state[v.name] else '!'}{v.name}" for v in variables) or "1"

        formula = f"({literals(spec.owned('env'))}) -> (({literals(spec.owned('sys'))}) & {body})"
        return spot_realizable(formula, outputs)

    states = list(valuations(spec.owned("env") + spec.owned("sys")))
    if spec.init_mode == "one_side" and sys_init:
        assert not env_init, "ONE_SIDE_INIT takes at most one initial condition"
        return any(wins_from(s) for s in states if holds(sys_init, s))
    return all(wins_from(s) for s in states if holds(env_init + sys_init, s))


def explore(spec: GameSpec, strategy: SymbolicStrategy) -> MealyMachine:
    """The explicit machine the symbolic strategy induces: from its first states, every input
    allowed by the environment's safety (the oracle's evaluator decides) is stepped."""
    inputs, outputs = spec.owned("env"), spec.owned("sys")
    env_init = spec.select("env", "init")
    env_safety = spec.select("env", "safety")
    index: dict[tuple[tuple[Value, ...], int], int] = {}
    states: list[dict[str, Value]] = []
    goals: list[int] = []
    transitions: list[tuple[int, int]] = []
    queue: deque[int] = deque()

    def node(state: dict[str, Value], goal: int) -> int:
        key = (_key(state), goal)
        if key not in index:
            index[key] = len(states)
            states.append(state)
            goals.append(goal)
            queue.append(index[key])
        return index[key]

    initial: list[int] = []
    for x in valuations(inputs):
        if holds(env_init, x):
            first = strategy.start(x)
            if first is not None:
                initial.append(node(first, 0))
    while queue:
        source = queue.popleft()
        for x in valuations(inputs):
            if not holds(env_safety, states[source], {**states[source], **x}):
                continue
            stepped = strategy.step(states[source], goals[source], x)
            assert stepped is not None, (states[source], x)
            transitions.append((source, node(*stepped)))
    return MealyMachine(
        inputs=inputs,
        outputs=outputs,
        goals=strategy.goals,
        init_mode=spec.init_mode,
        states=tuple(states),
        node_goals=tuple(goals),
        initial=tuple(initial),
        transitions=tuple(transitions),
        source_file=spec.file,
        source_format=spec.source_format,
    )
