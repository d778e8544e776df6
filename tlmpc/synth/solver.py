"""The GR(1) game solver: the three-nested fixpoint on BDDs.

The winning region of the system is (Bloem, Jobstmann, Piterman, Pnueli, Sa'ar, "Synthesis of
Reactive(1) designs", JCSS 2012; Piterman, Pnueli, Sa'ar, VMCAI 2006)::

    Z = nu Z. /\\_j mu Y. \\/_i nu X. cpre( (J^s_j /\\ Z') \\/ Y' \\/ (~J^e_i /\\ X') )

with the controllable predecessor ``cpre(T) = forall x'. exists y'. (rho_e -> rho_s /\\ T)``:
whatever the environment does next within its safety assumption, the system has an answer
within its own safety guarantee that takes a transition in ``T``.  Goals may mention the next
step (slugs allows it), so they are read on transitions; a goal over the current state is the
special case.  The relational products use CUDD's ``and_exists`` / ``or_forall``.

Besides the winning region, the last pass of the outer fixpoint leaves, for each system goal,
the ordered list of transition sets that make a positional strategy per goal (the rank of the
middle fixpoint and the index of the environment goal being waited for, lowest first); the
Mealy machine in :mod:`tlmpc.synth.strategy` is built from them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from dd import cudd

from tlmpc.synth.spec import GameSpec, InitMode
from tlmpc.synth.symbolic import Encoding, Function


@dataclass
class Game:
    """The symbolic game of a specification: the encoding and the conjoined parts."""

    spec: GameSpec
    enc: Encoding
    env_init: Function
    sys_init: Function
    env_safety: Function
    sys_safety: Function
    env_goals: list[Function]
    sys_goals: list[Function]

    @classmethod
    def build(cls, spec: GameSpec, enc: Encoding | None = None) -> Game:
        """Translate ``spec`` (reusing ``enc``'s BDDs of parts when given)."""
        if enc is None:
            enc = Encoding(spec)
        else:
            enc.spec = spec
        bdd = enc.bdd
        env_goals = [enc.part(p) for p in spec.select("env", "liveness")] or [bdd.true]
        sys_goals = [enc.part(p) for p in spec.select("sys", "liveness")] or [bdd.true]
        return cls(
            spec=spec,
            enc=enc,
            env_init=enc.conjoin(spec.select("env", "init")) & enc.domain("env", False),
            sys_init=enc.conjoin(spec.select("sys", "init")) & enc.domain("sys", False),
            env_safety=enc.conjoin(spec.select("env", "safety")) & enc.domain("env", True),
            sys_safety=enc.conjoin(spec.select("sys", "safety")) & enc.domain("sys", True),
            env_goals=env_goals,
            sys_goals=sys_goals,
        )


@dataclass
class Solution:
    """The outcome of :func:`solve`."""

    game: Game
    winning: Function
    realizable: bool
    #: per system goal, the transition sets (over current, next inputs, next outputs) in the
    #: order of the middle and inner fixpoints, lowest rank first
    layers: list[list[Function]] = field(default_factory=list)
    #: how many times ``cpre`` was applied (the solver's work, machine-independent)
    cpre_count: int = 0


class _Cpre:
    """``cpre`` with the quantified variable sets and the environment's safety prepared."""

    def __init__(self, game: Game) -> None:
        enc = game.enc
        self.bdd = enc.bdd
        self.next_inputs = enc.names("env", True)
        self.next_outputs = enc.names("sys", True)
        self.not_env = ~game.env_safety
        self.sys_safety = game.sys_safety
        # slugs lets the environment's safety mention next outputs; then the quantifiers cannot
        # be split around it
        self.mixed = bool(set(enc.bdd.support(game.env_safety)) & self.next_outputs)
        self.count = 0

    def moves(self, target: Function) -> Function:
        """``exists y'. rho_s /\\ target`` (over current and next inputs)."""
        return cudd.and_exists(self.sys_safety, target, self.next_outputs)

    def of_moves(self, moves: Function) -> Function:
        """``forall x'. (rho_e -> moves)``, ``moves`` from :meth:`moves`."""
        self.count += 1
        return cudd.or_forall(self.not_env, moves, self.next_inputs)

    def __call__(self, target: Function) -> Function:
        if self.mixed:
            self.count += 1
            inner = self.not_env | (self.sys_safety & target)
            return self.bdd.forall(self.next_inputs, self.bdd.exist(self.next_outputs, inner))
        return self.of_moves(self.moves(target))


def solve(game: Game, *, keep_layers: bool = True) -> Solution:
    """Solve the game: the system's winning region and realizability under the spec's
    initial-state quantification."""
    enc = game.enc
    bdd = enc.bdd
    cpre = _Cpre(game)
    not_env_goals = [~g for g in game.env_goals]
    z = bdd.true
    layers: list[list[Function]] = []
    # The X of each (goal, rank, assumption) from the previous pass of Z: Z only shrinks, so
    # every X does too and the old value is a sound start for the new greatest fixpoint
    # (fixpoint recycling), which saves most of the inner iterations.
    previous: dict[tuple[int, int, int], Function] = {}
    next_bits = enc.names(None, True)
    # A goal over the current state only commutes with the quantifiers over next values:
    # exists y'. rho_s /\ (J /\ T) = J /\ exists y'. rho_s /\ T, which keeps the relational
    # products small and shares exists y'. rho_s /\ Z' among all system goals.
    sys_on_state = [not (set(bdd.support(g)) & next_bits) for g in game.sys_goals]
    env_on_state = [not (set(bdd.support(g)) & next_bits) for g in game.env_goals]
    # Gauss-Seidel order: each goal's Y shrinks Z at once, and the goals after it in the same
    # pass already use the smaller Z (any Z above the fixpoint is a sound start); a pass in
    # which no goal shrinks Z ends the outer fixpoint, and its layers are the strategy's.
    while True:
        layers = [[] for _ in game.sys_goals]
        changed = False
        current: dict[tuple[int, int, int], Function] = {}
        for j, goal in enumerate(game.sys_goals):
            z_next = enc.prime(z)
            reach_goal = goal & z_next
            reach_moves = None
            if not cpre.mixed:
                reach_moves = (
                    goal & cpre.moves(z_next) if sys_on_state[j] else cpre.moves(reach_goal)
                )
            y = bdd.false
            rank = 0
            while True:
                y_next = enc.prime(y)
                live = reach_goal | y_next
                live_moves = None
                if reach_moves is not None:
                    live_moves = reach_moves | cpre.moves(y_next)
                new_y = y
                for i, not_goal in enumerate(not_env_goals):
                    x = previous.get((j, rank, i), bdd.true)
                    while True:
                        x_next = enc.prime(x)
                        if live_moves is None:
                            new_x = cpre(live | (x_next & not_goal))
                        elif env_on_state[i]:
                            new_x = cpre.of_moves(live_moves | (not_goal & cpre.moves(x_next)))
                        else:
                            new_x = cpre.of_moves(live_moves | cpre.moves(x_next & not_goal))
                        if new_x == x:
                            break
                        x = new_x
                    current[(j, rank, i)] = x
                    new_y |= x
                    if keep_layers:
                        layers[j].append(live | (x_next & not_goal))
                if new_y == y:
                    break
                y = new_y
                rank += 1
            shrunk = z & y
            if shrunk != z:
                z = shrunk
                changed = True
            if z == bdd.false:
                break
        if not changed or z == bdd.false:
            break
        previous = current
    return Solution(
        game=game,
        winning=z,
        realizable=initially_winning(game, z, game.spec.init_mode),
        layers=layers,
        cpre_count=cpre.count,
    )


def initially_winning(game: Game, winning: Function, mode: InitMode) -> bool:
    """Whether the initial condition is met from ``winning`` under ``mode``."""
    enc = game.enc
    bdd = enc.bdd
    inputs = enc.names("env", False)
    outputs = enc.names("sys", False)
    domain = enc.domain(None, False)
    if mode == "forall_env_exists_sys":
        answer = bdd.exist(outputs, winning & game.sys_init & domain)
        result = bdd.forall(inputs, ~game.env_init | answer)
    elif mode == "all_init":
        result = bdd.forall(inputs | outputs, ~(game.env_init & game.sys_init & domain) | winning)
    else:  # gr1c's ONE_SIDE_INIT
        has_sys = bool(game.spec.select("sys", "init"))
        has_env = bool(game.spec.select("env", "init"))
        if has_sys and not has_env:
            result = bdd.exist(inputs | outputs, game.sys_init & domain & winning)
        else:
            result = bdd.forall(inputs | outputs, ~(game.env_init & domain) | winning)
    return bool(result == bdd.true)
