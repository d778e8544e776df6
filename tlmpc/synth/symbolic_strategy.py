"""A winning strategy as decision diagrams: one Boolean function per output bit.

The explicit Mealy machine (:mod:`tlmpc.synth.strategy`) lists every reachable node with one
transition per environment move, so it grows with the number of input combinations (2^k for
k sensors) times the reachable states.  The same strategy is written here as *functions*:
for each system goal ``j`` and each bit of the next outputs, in declaration order, a binary
decision diagram over the current state, the next inputs and the next output bits chosen
before it.  Stepping the strategy evaluates those diagrams on the values at hand; nothing is
enumerated.

The choice is the explicit machine's, bit for bit: among the moves of the lowest layer of the
goal's positional strategy (:func:`tlmpc.synth.strategy.goal_strategies`), the lexicographically
first assignment of the next output bits (declaration order, least significant bit first,
False before True).  Bit ``k`` is therefore ``not exists later bits. S_k[bit_k := False]``
with ``S_k`` the moves that agree with the bits chosen before it.  The goal memory switches to
``j + 1`` after a step that fulfils goal ``j``, as in the explicit machine, so both machines
visit the same (state, goal) pairs: :func:`reachable_size` counts them symbolically.

The diagrams are copied into a fresh manager with a fixed variable order (every variable's
bits in declaration order, each current bit beside its next copy) and without dynamic
reordering, so the same specification gives the same bytes.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from dd import cudd

from tlmpc.synth.solver import Solution
from tlmpc.synth.spec import Variable
from tlmpc.synth.strategy import (
    Value,
    goal_strategies,
    ordered_bits,
    picked_start,
    variable_from_json,
    variable_json,
)
from tlmpc.synth.symbolic import Encoding, Function

#: the diagrams' terminal node ids
FALSE, TRUE = 0, 1


@dataclass(frozen=True)
class Bit:
    """One bit of the encoding: bit ``index`` (least significant first) of ``variable``'s
    offset from its range's low end (a Boolean has the one bit 0), now or (``next``) after
    the step."""

    variable: str
    index: int
    next: bool


@dataclass(frozen=True)
class Diagram:
    """Shared decision-diagram nodes: node ``n >= 2`` is ``nodes[n - 2] = (bit, low, high)``
    (``bits[bit]`` False: go to ``low``, True: go to ``high``); 0 is false, 1 is true."""

    bits: tuple[Bit, ...]
    nodes: tuple[tuple[int, int, int], ...]

    def evaluate(self, root: int, values: Mapping[int, bool]) -> bool:
        """The function at ``root`` on ``values`` (bit position -> value)."""
        node = root
        while node > TRUE:
            bit, low, high = self.nodes[node - 2]
            node = high if values[bit] else low
        return node == TRUE


@dataclass(frozen=True)
class SymbolicStrategy:
    """A winning strategy as functions (see the module's docstring).

    ``choices[j][k]`` decides bit ``output_bits[k]`` (a next output bit) while pursuing goal
    ``j``; ``done[j]`` says whether a step fulfils goal ``j``; ``assumption`` is the
    environment's safety (a step whose inputs break it leaves the game); ``initial`` is the set
    of first states the strategy serves and ``initial_choices[k]`` decides the current output
    bit ``initial_bits[k]`` from the first inputs.
    """

    inputs: tuple[Variable, ...]
    outputs: tuple[Variable, ...]
    goals: int
    init_mode: str
    diagram: Diagram
    output_bits: tuple[int, ...]
    choices: tuple[tuple[int, ...], ...]
    done: tuple[int, ...]
    assumption: int
    initial: int
    initial_bits: tuple[int, ...]
    initial_choices: tuple[int, ...]
    source_file: str
    source_format: str

    @property
    def variables(self) -> tuple[Variable, ...]:
        """Inputs, then outputs."""
        return self.inputs + self.outputs

    def _bit_values(
        self, current: Mapping[str, Value], inputs: Mapping[str, Value] | None
    ) -> dict[int, bool]:
        values: dict[int, bool] = {}
        by_name = {v.name: v for v in self.variables}
        for position, bit in enumerate(self.diagram.bits):
            source = inputs if bit.next else current
            if source is None or bit.variable not in source:
                continue
            variable = by_name[bit.variable]
            values[position] = _bit_of(variable, source[bit.variable], bit.index)
        return values

    def _decode(self, values: Mapping[int, bool], positions: tuple[int, ...]) -> dict[str, Value]:
        offsets: dict[str, int] = {}
        for position in positions:
            bit = self.diagram.bits[position]
            offsets.setdefault(bit.variable, 0)
            if values[position]:
                offsets[bit.variable] |= 1 << bit.index
        result: dict[str, Value] = {}
        for variable in self.outputs:
            offset = offsets.get(variable.name, 0)
            result[variable.name] = bool(offset) if variable.is_bool else _low(variable) + offset
        return result

    def start(self, inputs: Mapping[str, Value]) -> dict[str, Value] | None:
        """The first state (every variable) when the environment starts with ``inputs``;
        None when no first state the strategy serves has these inputs."""
        _check_values(self.inputs, inputs)
        values = self._bit_values(inputs, None)
        for position, root in zip(self.initial_bits, self.initial_choices, strict=True):
            values[position] = self.diagram.evaluate(root, values)
        state = {**dict(inputs), **self._decode(values, self.initial_bits)}
        if not self.diagram.evaluate(self.initial, self._bit_values(state, None)):
            return None
        return {v.name: state[v.name] for v in self.variables}

    def step(
        self, state: Mapping[str, Value], goal: int, inputs: Mapping[str, Value]
    ) -> tuple[dict[str, Value], int] | None:
        """The next state and goal when the environment plays ``inputs`` in ``state`` while
        the strategy pursues ``goal``; None when ``inputs`` break the environment's safety
        assumption (the strategy owes nothing then)."""
        _check_values(self.variables, state)
        _check_values(self.inputs, inputs)
        values = self._bit_values(state, inputs)
        if not self.diagram.evaluate(self.assumption, values):
            return None
        for position, root in zip(self.output_bits, self.choices[goal], strict=True):
            values[position] = self.diagram.evaluate(root, values)
        answer = self._decode(values, self.output_bits)
        reached = self.diagram.evaluate(self.done[goal], values)
        following = (goal + 1) % self.goals if reached else goal
        after = {**dict(inputs), **answer}
        return {v.name: after[v.name] for v in self.variables}, following


def _low(variable: Variable) -> int:
    assert variable.low is not None
    return variable.low


def _bit_of(variable: Variable, value: Value, index: int) -> bool:
    if variable.is_bool:
        return bool(value)
    return bool(((int(value) - _low(variable)) >> index) & 1)


def _check_values(variables: tuple[Variable, ...], values: Mapping[str, Value]) -> None:
    for variable in variables:
        if variable.name not in values:
            raise ValueError(f"no value for {variable.name}")
        value = values[variable.name]
        if variable.is_bool:
            if not isinstance(value, bool):
                raise ValueError(f"{variable.name} is Boolean, not {value!r}")
        elif isinstance(value, bool) or not _low(variable) <= value <= (variable.high or 0):
            raise ValueError(
                f"{variable.name} ranges over {variable.low}..{variable.high}, not {value!r}"
            )


# --- construction ---------------------------------------------------------------------------


def determinize(
    enc: Encoding, moves: Function, bits: list[str], counted: list[int] | None = None
) -> list[Function]:
    """One function per bit of ``bits`` (in order) that picks the lexicographically first
    assignment of ``bits`` (False before True) among those ``moves`` allows; each function
    may read the bits before it."""
    bdd = enc.bdd
    functions: list[Function] = []
    rest = moves
    for k, bit in enumerate(bits):
        later = set(bits[k + 1 :])
        low = bdd.let({bit: False}, rest)
        choose = ~bdd.exist(later, low) if later else ~low
        functions.append(choose)
        rest = rest & bdd.apply("equiv", bdd.var(bit), choose)
        if counted is not None:
            counted[0] += 1
    return functions


def _starting_set(solution: Solution) -> Function:
    """The first states the strategy serves (the explicit machine's initial states)."""
    game = solution.game
    enc = game.enc
    if game.start == "each_input":
        return game.first_states() & solution.winning
    if game.start == "some_state":
        return enc.bdd.cube(picked_start(solution))
    return game.first_states()


def symbolic_strategy(solution: Solution) -> SymbolicStrategy:
    """The winning strategy of a realizable game as decision diagrams."""
    game = solution.game
    enc = game.enc
    bdd = enc.bdd
    next_outputs = ordered_bits(enc, "sys", True)
    current_outputs = ordered_bits(enc, "sys", False)
    roots: list[Function] = []
    choices: list[list[int]] = []
    for strategy in goal_strategies(solution):
        functions = determinize(enc, strategy, next_outputs)
        choices.append([len(roots) + k for k in range(len(functions))])
        roots += functions
    done_at = len(roots)
    roots += list(game.sys_goals)
    assumption_at = len(roots)
    # slugs lets the environment's safety read the next outputs: the check before the answer
    # asks whether some answer keeps it
    roots.append(bdd.exist(enc.names("sys", True), game.env_safety & enc.domain("env", True)))
    starting = _starting_set(solution)
    initial_at = len(roots)
    roots.append(starting)
    initial_choice_at = len(roots)
    roots += determinize(enc, starting, current_outputs)
    diagram, exported = _export(enc, roots)
    position = {name: k for k, name in enumerate(_bit_names(enc))}
    return SymbolicStrategy(
        inputs=game.spec.owned("env"),
        outputs=game.spec.owned("sys"),
        goals=len(game.sys_goals),
        init_mode=game.spec.init_mode,
        diagram=diagram,
        output_bits=tuple(position[b] for b in next_outputs),
        choices=tuple(tuple(exported[k] for k in row) for row in choices),
        done=tuple(exported[done_at + j] for j in range(len(game.sys_goals))),
        assumption=exported[assumption_at],
        initial=exported[initial_at],
        initial_bits=tuple(position[b] for b in current_outputs),
        initial_choices=tuple(exported[initial_choice_at:]),
        source_file=game.spec.file,
        source_format=game.spec.source_format,
    )


def _bit_names(enc: Encoding) -> list[str]:
    """Every bit name in the fixed order: each variable's bits, current beside next."""
    names: list[str] = []
    for variable in enc.spec.variables:
        for now, after in zip(enc.bits[variable.name], enc.next_bits[variable.name], strict=True):
            names += [now, after]
    return names


def _export(enc: Encoding, roots: list[Function]) -> tuple[Diagram, list[int]]:
    """The diagrams of ``roots`` in the fixed order, as a shared node table."""
    names = _bit_names(enc)
    fixed = cudd.BDD()
    fixed.configure(reordering=False)
    fixed.declare(*names)
    position = {name: k for k, name in enumerate(names)}
    bits: list[Bit] = []
    for variable in enc.spec.variables:
        for k in range(len(enc.bits[variable.name])):
            bits += [Bit(variable.name, k, False), Bit(variable.name, k, True)]
    nodes: list[tuple[int, int, int]] = []
    ids: dict[int, int] = {}
    # ``int(u)`` is the node's address: every numbered node is kept referenced until the end,
    # so that no address is freed and reused by another node meanwhile
    alive: list[Function] = []

    def number(u: Function) -> int:
        # iterative post-order: every node after its children, numbered once
        stack: list[tuple[Function, bool]] = [(u, False)]
        while stack:
            w, ready = stack.pop()
            key = int(w)
            if key in ids:
                continue
            alive.append(w)
            if w == fixed.false:
                ids[key] = FALSE
                continue
            if w == fixed.true:
                ids[key] = TRUE
                continue
            low = fixed.let({w.var: False}, w)
            high = fixed.let({w.var: True}, w)
            if not ready:
                stack.append((w, True))
                stack += [(c, False) for c in (high, low) if int(c) not in ids]
                continue
            nodes.append((position[w.var], ids[int(low)], ids[int(high)]))
            ids[key] = len(nodes) + 1
        return ids[int(u)]

    exported = [number(enc.bdd.copy(root, fixed)) for root in roots]
    return Diagram(bits=tuple(bits), nodes=tuple(nodes)), exported


# --- size of the closed loop ----------------------------------------------------------------


@dataclass(frozen=True)
class LoopSize:
    """The explicit machine's size without building it: (state, goal) pairs reachable from
    the initial states under the strategy, and their transitions (one per allowed input)."""

    nodes: int
    transitions: int


def reachable_size(solution: Solution, strategy: SymbolicStrategy | None = None) -> LoopSize:
    """Count the nodes and transitions of the explicit machine (before merging) by symbolic
    reachability over the determinized strategy."""
    game = solution.game
    enc = game.enc
    bdd = enc.bdd
    next_outputs = ordered_bits(enc, "sys", True)
    current = enc.names(None, False)
    env_moves = game.env_safety & enc.domain("env", True)
    allowed_inputs = bdd.exist(enc.names("sys", True), env_moves)
    relations = []
    for strategy_j in goal_strategies(solution):
        relation = env_moves
        for bit, choose in zip(
            next_outputs, determinize(enc, strategy_j, next_outputs), strict=True
        ):
            relation &= bdd.apply("equiv", bdd.var(bit), choose)
        relations.append(relation)
    goals = len(game.sys_goals)
    reached = [bdd.false] * goals
    reached[0] = _starting_set(solution)
    if game.start == "each_input":
        # the explicit machine serves each first input with the first winning answer
        outputs = ordered_bits(enc, "sys", False)
        pick = bdd.true
        for bit, choose in zip(outputs, determinize(enc, reached[0], outputs), strict=True):
            pick &= bdd.apply("equiv", bdd.var(bit), choose)
        reached[0] &= pick
    frontier = list(reached)
    while any(f != bdd.false for f in frontier):
        found = [bdd.false] * goals
        for j in range(goals):
            if frontier[j] == bdd.false:
                continue
            steps = frontier[j] & relations[j]
            fulfilled = game.sys_goals[j]
            stay = enc.unprime(bdd.exist(current, steps & ~fulfilled))
            move = enc.unprime(bdd.exist(current, steps & fulfilled))
            found[j] |= stay
            found[(j + 1) % goals] |= move
        frontier = [f & ~r for f, r in zip(found, reached, strict=True)]
        reached = [r | f for r, f in zip(reached, frontier, strict=True)]
    width = len(current)
    nodes = sum(int(bdd.count(r, nvars=width)) for r in reached if r != bdd.false)
    moves = sum(
        int(bdd.count(r & allowed_inputs, nvars=width + len(enc.names("env", True))))
        for r in reached
        if r != bdd.false
    )
    return LoopSize(nodes=nodes, transitions=moves)


# --- strategy.json ----------------------------------------------------------------------------


def symbolic_json(strategy: SymbolicStrategy) -> dict[str, Any]:
    """The ``symbolic`` member of ``strategy.json`` (schemas/strategy.schema.json)."""
    return {
        "bits": [
            {"variable": b.variable, "bit": b.index, "next": b.next} for b in strategy.diagram.bits
        ],
        "nodes": [list(n) for n in strategy.diagram.nodes],
        "output_bits": list(strategy.output_bits),
        "choices": [list(row) for row in strategy.choices],
        "done": list(strategy.done),
        "assumption": strategy.assumption,
        "initial": strategy.initial,
        "initial_bits": list(strategy.initial_bits),
        "initial_choices": list(strategy.initial_choices),
    }


def symbolic_document(strategy: SymbolicStrategy, size: LoopSize | None = None) -> dict[str, Any]:
    """A ``strategy.json`` holding the symbolic form alone (no explicit nodes)."""
    document: dict[str, Any] = {
        "format": "tlmpc.strategy/1",
        "source": {"file": strategy.source_file, "format": strategy.source_format},
        "initial_quantification": strategy.init_mode,
        "inputs": [variable_json(v) for v in strategy.inputs],
        "outputs": [variable_json(v) for v in strategy.outputs],
        "goals": strategy.goals,
        "symbolic": symbolic_json(strategy),
    }
    if size is not None:
        document["reachable"] = {"nodes": size.nodes, "transitions": size.transitions}
    return document


def symbolic_from_json(document: Mapping[str, Any]) -> SymbolicStrategy:
    """The symbolic strategy of a ``strategy.json`` (its ``symbolic`` member)."""
    part = document["symbolic"]
    return SymbolicStrategy(
        inputs=tuple(variable_from_json(v, "env") for v in document["inputs"]),
        outputs=tuple(variable_from_json(v, "sys") for v in document["outputs"]),
        goals=int(document["goals"]),
        init_mode=str(document["initial_quantification"]),
        diagram=Diagram(
            bits=tuple(
                Bit(str(b["variable"]), int(b["bit"]), bool(b["next"])) for b in part["bits"]
            ),
            nodes=tuple((int(n[0]), int(n[1]), int(n[2])) for n in part["nodes"]),
        ),
        output_bits=tuple(int(k) for k in part["output_bits"]),
        choices=tuple(tuple(int(r) for r in row) for row in part["choices"]),
        done=tuple(int(r) for r in part["done"]),
        assumption=int(part["assumption"]),
        initial=int(part["initial"]),
        initial_bits=tuple(int(k) for k in part["initial_bits"]),
        initial_choices=tuple(int(r) for r in part["initial_choices"]),
        source_file=str(document["source"]["file"]),
        source_format=str(document["source"]["format"]),
    )


__all__ = [
    "Bit",
    "Diagram",
    "LoopSize",
    "SymbolicStrategy",
    "determinize",
    "reachable_size",
    "symbolic_document",
    "symbolic_from_json",
    "symbolic_json",
    "symbolic_strategy",
]
