"""Counterstrategies: how the environment defeats every system strategy.

The environment wins exactly outside the system's winning region (GR(1) games are
determined).  Its strategy comes from the dual of the three-nested fixpoint::

    W = mu W. \\/_j nu V. /\\_i mu U. epre( (~J^s_j \\/ W') /\\ V' /\\ (J^e_i \\/ U') )

with ``epre(T) = exists x'. rho_e /\\ forall y'. (rho_s -> T)``: the environment picks one
system goal ``j`` to starve (it may let the system fulfil it only by dropping to a lower rank
of ``W``), stays in ``V`` and visits its own goals in turn through the ranks of ``U``.  The
explicit counterstrategy is a graph of nodes ``(state, j, i)``: in each node the environment
plays one input, and every answer the system's safety allows leads to a node (a node where the
system has no allowed answer ends the play: the system is stuck).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

from dd import cudd

from tlmpc.base.errors import UsageError, error
from tlmpc.synth.solver import Game, Solution
from tlmpc.synth.strategy import (
    Value,
    _key,
    all_assignments,
    bits_of,
    ordered_bits,
    restrict,
    smallest,
)
from tlmpc.synth.symbolic import Function

#: the largest counterstrategy written explicitly (nodes)
MAX_NODES = 20_000


@dataclass
class _Layers:
    """The dual fixpoint's values: per rank of W, per goal j, V and the U ranks per i."""

    ranks: list[Function] = field(default_factory=list)  # W_1, W_2, ... (W_0 is empty)
    v: list[list[Function]] = field(default_factory=list)
    u: list[list[list[list[Function]]]] = field(default_factory=list)


def _environment_layers(game: Game) -> _Layers:
    enc = game.enc
    bdd = enc.bdd
    next_inputs = enc.names("env", True)
    next_outputs = enc.names("sys", True)
    not_sys = ~game.sys_safety

    def epre(target: Function) -> Function:
        return cudd.and_exists(
            game.env_safety, cudd.or_forall(not_sys, target, next_outputs), next_inputs
        )

    layers = _Layers()
    w = bdd.false
    while True:
        v_of_goal: list[Function] = []
        u_of_goal: list[list[list[Function]]] = []
        for goal in game.sys_goals:
            starve = ~goal | enc.prime(w)
            v = bdd.true
            while True:
                keep = starve & enc.prime(v)
                new_v = bdd.true
                u_ranks: list[list[Function]] = []
                for env_goal in game.env_goals:
                    u = bdd.false
                    ranks: list[Function] = []
                    while True:
                        new_u = epre(keep & (env_goal | enc.prime(u)))
                        if new_u == u:
                            break
                        u = new_u
                        ranks.append(u)
                    u_ranks.append(ranks)
                    new_v &= u
                if new_v == v:
                    break
                v = new_v
            v_of_goal.append(v)
            u_of_goal.append(u_ranks)
        new_w = w
        for v in v_of_goal:
            new_w |= v
        if new_w == w:
            break
        w = new_w
        layers.ranks.append(w)
        layers.v.append(v_of_goal)
        layers.u.append(u_of_goal)
    return layers


@dataclass(frozen=True)
class CounterStrategy:
    """The environment's winning strategy, explicit.

    ``moves[n]`` is the input the environment plays in node ``n``, ``answers[n]`` the nodes
    that the system's allowed answers lead to (none: the system is stuck and loses);
    ``initial`` the nodes the play may start in, and ``initial_inputs`` the first inputs the
    environment picks when the system then chooses its first outputs.
    """

    states: tuple[dict[str, Value], ...]
    memory: tuple[tuple[int, int], ...]
    moves: tuple[dict[str, Value], ...]
    answers: tuple[tuple[int, ...], ...]
    initial: tuple[int, ...]
    initial_inputs: dict[str, Value] | None


def extract_counterstrategy(solution: Solution, *, max_nodes: int = MAX_NODES) -> CounterStrategy:
    """The explicit counterstrategy of an unrealizable game."""
    game = solution.game
    enc = game.enc
    bdd = enc.bdd
    layers = _environment_layers(game)
    outputs = enc.names("sys", False)
    next_outputs = enc.names("sys", True)
    domain = enc.domain(None, False)
    losing = ~solution.winning & domain

    def rank(values: dict[str, Value]) -> int:
        bits = bits_of(enc, values, False)
        for r, w in enumerate(layers.ranks):
            if restrict(enc, bits, w) == bdd.true:
                return r
        raise AssertionError("a state outside the environment's winning region")

    states: list[dict[str, Value]] = []
    memory: list[tuple[int, int]] = []
    index: dict[tuple[tuple[Value, ...], int, int], int] = {}
    queue: deque[int] = deque()

    def node(values: dict[str, Value], goal: int, env_goal: int) -> int:
        r = rank(values)
        bits = bits_of(enc, values, False)
        if restrict(enc, bits, layers.v[r][goal]) != bdd.true:
            goal = next(j for j, v in enumerate(layers.v[r]) if restrict(enc, bits, v) == bdd.true)
            env_goal = 0
        key = (_key(values), goal, env_goal)
        found = index.get(key)
        if found is None:
            if len(states) >= max_nodes:
                raise UsageError(
                    error(
                        "Q062",
                        f"the counterstrategy has more than {max_nodes} nodes to show",
                        hint="the core is still unrealizable; shrink the game to see a "
                        "counterstrategy",
                        file=game.spec.file,
                    )
                )
            found = len(states)
            index[key] = found
            states.append(values)
            memory.append((goal, env_goal))
            queue.append(found)
        return found

    initial_inputs: dict[str, Value] | None = None
    starts: list[dict[str, Value]] = []
    if game.start == "each_input":
        # an initial input from which every allowed initial output loses
        env_start = game.env_init & enc.domain("env", False)
        sys_start = game.sys_init & enc.domain("sys", False)
        bad = env_start & bdd.forall(outputs, ~sys_start | losing)
        x = smallest(enc, bdd.exist(outputs, bad), ordered_bits(enc, "env", False))
        assert x is not None, "unrealizable, yet every initial input has a winning answer"
        initial_inputs = enc.decode(x, "env", False)
        answers = restrict(enc, x, sys_start)
        for y in all_assignments(enc, answers, ordered_bits(enc, "sys", False)):
            starts.append(enc.decode({**x, **y}, None, False))
    else:
        # every_state: one losing state the play may start in; some_state: every start the
        # system may pick (all of them lose)
        first = game.first_states()
        start = first & losing if game.start == "every_state" else first
        for s in all_assignments(enc, start, ordered_bits(enc, None, False)):
            starts.append(enc.decode(s, None, False))
            if game.start == "every_state":
                break
    initial = tuple(node(s, 0, 0) for s in sorted(starts, key=_key))
    moves: list[dict[str, Value]] = []
    successors: list[tuple[int, ...]] = []
    not_sys = ~game.sys_safety
    while queue:
        current = queue.popleft()
        while len(moves) <= current:
            moves.append({})
            successors.append(())
        values = states[current]
        goal, env_goal = memory[current]
        r = rank(values)
        bits = bits_of(enc, values, False)
        u_ranks = layers.u[r][goal][env_goal]
        k = next(k for k, u in enumerate(u_ranks) if restrict(enc, bits, u) == bdd.true)
        lower = enc.prime(u_ranks[k - 1]) if k > 0 else bdd.false
        below = enc.prime(layers.ranks[r - 1]) if r > 0 else bdd.false
        target = (
            (~game.sys_goals[goal] | below)
            & enc.prime(layers.v[r][goal])
            & (game.env_goals[env_goal] | lower)
        )
        good = game.env_safety & cudd.or_forall(not_sys, target, next_outputs)
        x = smallest(
            enc,
            restrict(enc, bits, bdd.exist(next_outputs, good)),
            ordered_bits(enc, "env", True),
        )
        assert x is not None, "a losing state without a winning environment move"
        moves[current] = enc.decode(x, "env", True)
        allowed = restrict(enc, {**bits, **x}, game.sys_safety & enc.domain("sys", True))
        targets: list[int] = []
        done = restrict(enc, {**bits, **x}, game.env_goals[env_goal])
        for y in all_assignments(enc, allowed, ordered_bits(enc, "sys", True)):
            reached = restrict(enc, y, done) == bdd.true
            next_env_goal = (env_goal + 1) % len(game.env_goals) if reached else env_goal
            targets.append(node(enc.decode({**x, **y}, None, True), goal, next_env_goal))
        successors[current] = tuple(targets)
    return CounterStrategy(
        states=tuple(states),
        memory=tuple(memory),
        moves=tuple(moves),
        answers=tuple(successors),
        initial=initial,
        initial_inputs=initial_inputs,
    )
