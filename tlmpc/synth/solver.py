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
from typing import Literal

from dd import cudd

from tlmpc.synth.spec import GameSpec
from tlmpc.synth.symbolic import Encoding, Function

#: Who picks the first state, the one reading of the initial conditions that the verdict, the
#: strategies and the counterstrategy share (:func:`start_rule` decides it): ``each_input``,
#: for every first input the environment's initial condition allows the system answers with
#: first outputs its own allows; ``every_state``, any state both allow may be the first;
#: ``some_state``, the system picks one first state its initial condition allows.
StartRule = Literal["each_input", "every_state", "some_state"]


def start_rule(spec: GameSpec) -> StartRule:
    """How ``spec``'s initial conditions are read under its initial-state quantification.

    gr1c's ONE_SIDE_INIT takes at most one non-empty initial condition (the readers refuse
    both): the system's alone is ``some_state``; the environment's alone, or none (which is
    ``ENVINIT: True``), is ``every_state``.  Raises ValueError for both under ONE_SIDE_INIT.
    """
    if spec.init_mode == "forall_env_exists_sys":
        return "each_input"
    if spec.init_mode == "all_init":
        return "every_state"
    has_env, has_sys = bool(spec.select("env", "init")), bool(spec.select("sys", "init"))
    if has_env and has_sys:
        raise ValueError("gr1c's ONE_SIDE_INIT takes at most one non-empty initial condition")
    return "some_state" if has_sys else "every_state"


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
    #: who picks the first state (:func:`start_rule` of the spec, unless given)
    start: StartRule

    @classmethod
    def build(
        cls, spec: GameSpec, enc: Encoding | None = None, *, start: StartRule | None = None
    ) -> Game:
        """Translate ``spec`` (reusing ``enc``'s BDDs of parts when given).  ``start``
        overrides the spec's own :func:`start_rule` (an unrealizability core keeps the rule of
        the whole specification while it drops parts)."""
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
            start=start or start_rule(spec),
        )

    def first_states(self) -> Function:
        """The states both initial conditions allow (within the variables' domains): under
        ``every_state`` each may be the first, under ``some_state`` the system picks one."""
        return self.env_init & self.sys_init & self.enc.domain(None, False)


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
        realizable=initially_winning(game, z),
        layers=layers,
        cpre_count=cpre.count,
    )


def initially_winning(game: Game, winning: Function) -> bool:
    """Whether the initial condition is met from ``winning`` under the game's start rule."""
    enc = game.enc
    bdd = enc.bdd
    inputs = enc.names("env", False)
    outputs = enc.names("sys", False)
    if game.start == "each_input":
        answer = bdd.exist(outputs, winning & game.first_states())
        result = bdd.forall(inputs, ~game.env_init | answer)
    elif game.start == "every_state":
        result = bdd.forall(inputs | outputs, ~game.first_states() | winning)
    else:
        result = bdd.exist(inputs | outputs, game.first_states() & winning)
    return bool(result == bdd.true)
