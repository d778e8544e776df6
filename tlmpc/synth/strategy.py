"""A winning strategy as an explicit Mealy machine, ``strategy.json`` and DOT.

From the solver's layers, each system goal ``j`` gets a positional strategy: for a state and an
environment move, the moves of the lowest (rank, assumption) layer that has any (slugs' and
Bloem et al.'s construction); taking a transition that fulfils goal ``j`` switches the memory to
goal ``j + 1``.  The machine is built from the initial states by breadth-first search over the
environment's moves, so only reachable nodes are kept, and a (state, goal) pair met again is
the same node; then nodes that behave alike are merged.  A node's state holds every variable's
value; the transition into a node reads the environment's inputs and answers with the system's
outputs of that node's state.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Mapping
from dataclasses import dataclass
from functools import cached_property
from typing import Any

from tlmpc.base.errors import UsageError, error
from tlmpc.synth.solver import Solution
from tlmpc.synth.spec import Owner, Variable
from tlmpc.synth.symbolic import Encoding, Function

#: the largest machine written explicitly (a budget of nodes, not of time)
MAX_NODES = 200_000

Value = int | bool


@dataclass(frozen=True)
class MealyMachine:
    """Nodes ``(state, goal)``, initial nodes, and transitions ``(source, target)``."""

    inputs: tuple[Variable, ...]
    outputs: tuple[Variable, ...]
    goals: int
    init_mode: str
    states: tuple[dict[str, Value], ...]
    node_goals: tuple[int, ...]
    initial: tuple[int, ...]
    transitions: tuple[tuple[int, int], ...]
    source_file: str
    source_format: str

    @cached_property
    def _successors(self) -> dict[int, dict[tuple[Value, ...], int]]:
        inputs = [v.name for v in self.inputs]
        table: dict[int, dict[tuple[Value, ...], int]] = {}
        for source, target in self.transitions:
            key = tuple(self.states[target][name] for name in inputs)
            table.setdefault(source, {})[key] = target
        return table

    def start(self, inputs: Mapping[str, Value]) -> int | None:
        """The initial node whose inputs are ``inputs`` (None: no initial node has them)."""
        for node in self.initial:
            if all(self.states[node][v.name] == inputs[v.name] for v in self.inputs):
                return node
        return None

    def successor(self, node: int, inputs: Mapping[str, Value]) -> int | None:
        """The node the machine moves to from ``node`` when the environment plays ``inputs``
        (None: the environment's safety assumption does not allow them there)."""
        key = tuple(inputs[v.name] for v in self.inputs)
        return self._successors.get(node, {}).get(key)


def goal_strategies(solution: Solution) -> list[Function]:
    """Per system goal, the transitions (current state, next inputs, next outputs) that the
    strategy may take: lowest layer first for each (state, next inputs)."""
    game = solution.game
    enc = game.enc
    bdd = enc.bdd
    next_outputs = enc.names("sys", True)
    winning_next = enc.prime(solution.winning)
    result = []
    for layers in solution.layers:
        covered = bdd.false
        strategy = bdd.false
        for paths in layers:
            moves = game.sys_safety & paths & winning_next
            cases = bdd.exist(next_outputs, moves) & ~covered
            strategy |= cases & moves
            covered |= cases
        result.append(strategy & solution.winning)
    return result


def bits_of(enc: Encoding, values: dict[str, Value], primed: bool) -> dict[str, bool]:
    """The BDD bits of a state's ``values`` (the next state's bits when ``primed``)."""
    bits: dict[str, bool] = {}
    table = enc.next_bits if primed else enc.bits
    for variable in enc.spec.variables:
        value = values[variable.name]
        names = table[variable.name]
        if variable.is_bool:
            bits[names[0]] = bool(value)
        else:
            assert variable.low is not None
            offset = int(value) - variable.low
            for k, name in enumerate(names):
                bits[name] = bool((offset >> k) & 1)
    return bits


def restrict(enc: Encoding, assignment: dict[str, bool], u: Function) -> Function:
    """``u`` with the assigned bits fixed (``u`` itself when nothing is assigned)."""
    return enc.bdd.let(assignment, u) if assignment else u


def smallest(enc: Encoding, u: Function, bits: list[str]) -> dict[str, bool] | None:
    """The assignment of ``bits`` (in the given order, False before True) that comes first
    lexicographically among those satisfying ``u``; None when ``u`` is false.  Unlike
    ``pick``, the choice does not depend on the BDD's current variable order (CUDD reorders
    dynamically), so the same input always gives the same strategy."""
    bdd = enc.bdd
    if u == bdd.false:
        return None
    chosen: dict[str, bool] = {}
    for bit in bits:
        low = bdd.let({bit: False}, u)
        if low != bdd.false:
            chosen[bit], u = False, low
        else:
            chosen[bit], u = True, bdd.let({bit: True}, u)
    return chosen


def ordered_bits(enc: Encoding, owner: str | None, primed: bool) -> list[str]:
    """Bit names of one player's variables in declaration order."""
    table = enc.next_bits if primed else enc.bits
    return [b for v in enc.spec.variables if owner in (None, v.owner) for b in table[v.name]]


def all_assignments(enc: Encoding, u: Function, bits: list[str]) -> list[dict[str, bool]]:
    """Every assignment of ``bits`` satisfying ``u``, in a fixed (variable-order-free) order."""
    found = list(enc.bdd.pick_iter(u, care_vars=set(bits))) if bits else []
    if not bits and u != enc.bdd.false:
        found = [{}]
    return sorted(found, key=lambda a: tuple(a[b] for b in bits))


def _key(values: dict[str, Value]) -> tuple[Value, ...]:
    return tuple(values[k] for k in sorted(values))


def picked_start(solution: Solution) -> dict[str, bool]:
    """The first state the system picks where it picks one (``some_state``): the
    lexicographically first winning state its initial condition allows, as bits."""
    game = solution.game
    enc = game.enc
    bits = ordered_bits(enc, "env", False) + ordered_bits(enc, "sys", False)
    start = smallest(enc, game.first_states() & solution.winning, bits)
    assert start is not None, "realizable, yet no first state is winning"
    return start


def initial_states(solution: Solution) -> list[dict[str, Value]]:
    """The initial states the machine must serve, under the game's start rule: the first
    winning answer to each first input (``each_input``), every state both initial conditions
    allow (``every_state``: the verdict asked them all to be winning), or the first winning
    one the system picks (``some_state``)."""
    game = solution.game
    enc = game.enc
    bdd = enc.bdd
    outputs = enc.names("sys", False)
    states: list[dict[str, Value]] = []
    input_bits = ordered_bits(enc, "env", False)
    output_bits = ordered_bits(enc, "sys", False)
    if game.start == "each_input":
        env_start = game.env_init & enc.domain("env", False)
        for x in all_assignments(enc, bdd.exist(outputs, env_start), input_bits):
            answer = restrict(enc, x, game.first_states() & solution.winning)
            y = smallest(enc, answer, output_bits)
            assert y is not None, "realizable, yet an initial input has no winning answer"
            states.append(enc.decode({**x, **y}, None, False))
    elif game.start == "some_state":
        states.append(enc.decode(picked_start(solution), None, False))
    else:
        for s in all_assignments(enc, game.first_states(), input_bits + output_bits):
            states.append(enc.decode(s, None, False))
    return sorted(states, key=_key)


def extract(
    solution: Solution, *, max_nodes: int = MAX_NODES, minimal: bool = True
) -> MealyMachine:
    """The explicit Mealy machine of a realizable game's winning strategy (with ``minimal``,
    nodes that behave alike merged: :func:`minimize`)."""
    game = solution.game
    enc = game.enc
    bdd = enc.bdd
    strategies = goal_strategies(solution)
    next_inputs = ordered_bits(enc, "env", True)
    next_outputs = ordered_bits(enc, "sys", True)
    goals_done = [g & enc.prime(solution.winning) for g in game.sys_goals]
    env_moves_all = game.env_safety & enc.domain("env", True)
    index: dict[tuple[tuple[Value, ...], int], int] = {}
    states: list[dict[str, Value]] = []
    node_goals: list[int] = []
    transitions: list[tuple[int, int]] = []
    queue: deque[int] = deque()

    def node(values: dict[str, Value], goal: int) -> int:
        key = (_key(values), goal)
        found = index.get(key)
        if found is None:
            if len(states) >= max_nodes:
                raise UsageError(
                    error(
                        "Q060",
                        f"the strategy has more than {max_nodes} nodes to write explicitly",
                        hint="the specification is realizable; drop -o, or shrink the game",
                        file=game.spec.file,
                    )
                )
            found = len(states)
            index[key] = found
            states.append(values)
            node_goals.append(goal)
            queue.append(found)
        return found

    initial = tuple(node(values, 0) for values in initial_states(solution))
    while queue:
        source = queue.popleft()
        values, goal = states[source], node_goals[source]
        current = bits_of(enc, values, False)
        strategy = restrict(enc, current, strategies[goal])
        env_moves = restrict(enc, current, env_moves_all)
        done = restrict(enc, current, goals_done[goal])
        for x in all_assignments(enc, env_moves, next_inputs):
            answers = restrict(enc, x, strategy)
            y = smallest(enc, answers, next_outputs)
            if y is None:
                raise AssertionError("a winning state has no strategy move for an input")
            move = {**x, **y}
            reached = restrict(enc, move, done) == bdd.true
            next_goal = (goal + 1) % len(game.sys_goals) if reached else goal
            target = node(enc.decode(move, None, True), next_goal)
            transitions.append((source, target))
    machine = MealyMachine(
        inputs=game.spec.owned("env"),
        outputs=game.spec.owned("sys"),
        goals=len(game.sys_goals),
        init_mode=game.spec.init_mode,
        states=tuple(states),
        node_goals=tuple(node_goals),
        initial=initial,
        transitions=tuple(transitions),
        source_file=game.spec.file,
        source_format=game.spec.source_format,
    )
    return minimize(machine) if minimal else machine


def minimize(machine: MealyMachine) -> MealyMachine:
    """Merge nodes that behave alike: the same state, and for every input the same answer into
    merged nodes again (partition refinement, as for a Mealy machine).  The answers the machine
    gives to every input sequence are unchanged, so it wins exactly where it did; a merged
    node keeps the goal of its first member."""
    count = len(machine.states)
    successors: list[list[int]] = [[] for _ in range(count)]
    for source, target in machine.transitions:
        successors[source].append(target)
    keys = [_key(state) for state in machine.states]
    classes: dict[tuple[object, ...], int] = {}
    block = [classes.setdefault((keys[n],), len(classes)) for n in range(count)]
    while True:
        signatures: dict[tuple[object, ...], int] = {}
        refined = [
            signatures.setdefault(
                (block[n], tuple(sorted({block[t] for t in successors[n]}))), len(signatures)
            )
            for n in range(count)
        ]
        if len(signatures) == len(set(block)):
            break
        block = refined
    # number the blocks by their first node, so the result is as deterministic as the input
    first: dict[int, int] = {}
    for n in range(count):
        first.setdefault(block[n], len(first))
    members = [0] * len(first)
    for n in range(count - 1, -1, -1):
        members[first[block[n]]] = n
    new = [first[block[n]] for n in range(count)]
    transitions = sorted({(new[s], new[t]) for s, t in machine.transitions})
    initial = tuple(dict.fromkeys(new[i] for i in machine.initial))
    return MealyMachine(
        inputs=machine.inputs,
        outputs=machine.outputs,
        goals=machine.goals,
        init_mode=machine.init_mode,
        states=tuple(machine.states[m] for m in members),
        node_goals=tuple(machine.node_goals[m] for m in members),
        initial=initial,
        transitions=tuple(transitions),
        source_file=machine.source_file,
        source_format=machine.source_format,
    )


def variable_json(variable: Variable) -> dict[str, Any]:
    """A variable as ``strategy.json`` lists it."""
    if variable.is_bool:
        return {"name": variable.name, "type": "bool"}
    return {"name": variable.name, "type": "int", "low": variable.low, "high": variable.high}


def variable_from_json(document: Mapping[str, Any], owner: Owner) -> Variable:
    """A variable of ``strategy.json``'s ``inputs`` (``env``) or ``outputs`` (``sys``)."""
    if document["type"] == "bool":
        return Variable(str(document["name"]), owner)
    return Variable(str(document["name"]), owner, int(document["low"]), int(document["high"]))


def machine_from_json(document: Mapping[str, Any]) -> MealyMachine:
    """The explicit machine of a ``strategy.json`` that lists its nodes."""
    nodes = sorted(document["nodes"], key=lambda n: int(n["id"]))
    return MealyMachine(
        inputs=tuple(variable_from_json(v, "env") for v in document["inputs"]),
        outputs=tuple(variable_from_json(v, "sys") for v in document["outputs"]),
        goals=int(document["goals"]),
        init_mode=str(document["initial_quantification"]),
        states=tuple(dict(n["state"]) for n in nodes),
        node_goals=tuple(int(n["goal"]) for n in nodes),
        initial=tuple(int(i) for i in document["initial"]),
        transitions=tuple((int(a), int(b)) for a, b in document["transitions"]),
        source_file=str(document["source"]["file"]),
        source_format=str(document["source"]["format"]),
    )


def to_json(machine: MealyMachine) -> dict[str, Any]:
    """The ``strategy.json`` document (schemas/strategy.schema.json)."""
    return {
        "format": "tlmpc.strategy/1",
        "source": {"file": machine.source_file, "format": machine.source_format},
        "initial_quantification": machine.init_mode,
        "inputs": [variable_json(v) for v in machine.inputs],
        "outputs": [variable_json(v) for v in machine.outputs],
        "goals": machine.goals,
        "nodes": [
            {"id": i, "goal": g, "state": state}
            for i, (state, g) in enumerate(zip(machine.states, machine.node_goals, strict=True))
        ],
        "initial": list(machine.initial),
        "transitions": [list(t) for t in machine.transitions],
    }


def _label(state: dict[str, Value], variables: tuple[Variable, ...]) -> str:
    words = []
    for v in variables:
        value = state[v.name]
        if v.is_bool:
            if value:
                words.append(v.name)
        else:
            words.append(f"{v.name}={value}")
    return " ".join(words) or "-"


def to_dot(machine: MealyMachine) -> str:
    """Graphviz DOT: a node shows its inputs / outputs and goal; edges go to the node whose
    inputs the environment chose and whose outputs the strategy answers."""
    lines = ["digraph strategy {", "  rankdir=LR;", '  node [shape=box, fontname="monospace"];']
    lines.append('  start [shape=point, label=""];')
    for i, (state, goal) in enumerate(zip(machine.states, machine.node_goals, strict=True)):
        label = (
            f"{i}: {_label(state, machine.inputs)} / {_label(state, machine.outputs)}\\ngoal {goal}"
        )
        label = label.replace('"', '\\"')
        lines.append(f'  n{i} [label="{label}"];')
    for i in machine.initial:
        lines.append(f"  start -> n{i};")
    for source, target in machine.transitions:
        lines.append(f"  n{source} -> n{target};")
    lines.append("}")
    return "\n".join(lines) + "\n"


__all__ = [
    "MealyMachine",
    "extract",
    "goal_strategies",
    "machine_from_json",
    "minimize",
    "to_dot",
    "to_json",
    "variable_from_json",
    "variable_json",
]
