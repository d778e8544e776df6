"""An unrealizable mission's counterstrategy, told in the mission's words.

The environment's winning strategy is a graph; one play of it — the environment's moves
against one answer of the robot at every step, up to the first point the play repeats — is a
concrete sequence of sensor readings and arrivals that defeats the robot.  Every answer of the
robot loses, so the play shows the answers of a robot that tries its best: like a GR(1)
strategy it pursues the goals of the core one at a time (the next one once the pursued one
holds), and at each step it takes, in this order of preference, an answer from which it need
never get stuck, one that fulfils the pursued goal, one heading for a face nearest to a face
where that goal can hold, and one that does not stay put.  Steps that differ only in the
task's memory are shown once.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Collection, Sequence
from collections.abc import Set as AbstractSet
from dataclasses import dataclass

from tlmpc.mission.model import TaskPart
from tlmpc.reactive.game import MissionGame
from tlmpc.reactive.nodes import FACE, GOAL, MOVED
from tlmpc.synth.counter import CounterStrategy
from tlmpc.synth.spec import Part, support
from tlmpc.synth.strategy import Value, bits_of, restrict
from tlmpc.synth.symbolic import Encoding, Function

#: the longest play shown (steps)
MAX_STEPS = 12


def place(letters: tuple[str, ...]) -> str:
    """A face's label in words: its regions, or free space."""
    return " & ".join(letters) if letters else "free space"


@dataclass(frozen=True, slots=True)
class PlayStep:
    """One step of a play of the counterstrategy: its node in the counterstrategy, where the
    robot is, what it senses, and the face it heads for (its own: it stays)."""

    step: int
    node: int
    face: int
    heading: int
    sensors: tuple[tuple[str, bool], ...]


@dataclass(frozen=True, slots=True)
class Play:
    """A play: its steps; ``stuck`` when the robot is left without an allowed move after the
    last one; ``again_from`` the step the play repeats from forever (None: it ends there)."""

    steps: tuple[PlayStep, ...]
    stuck: bool
    again_from: int | None


def face_distances(
    adjacent: Sequence[Sequence[int]], targets: Collection[int], open_faces: Collection[int]
) -> list[int | None]:
    """Per face, the fewest crossings from it into a face of ``targets``, through faces of
    ``open_faces`` only (None: there is no such way, as from any face not in ``open_faces``)."""
    distance: list[int | None] = [None] * len(adjacent)
    queue: deque[tuple[int, int]] = deque()
    for face in sorted(set(targets) & set(open_faces)):
        distance[face] = 0
        queue.append((face, 0))
    while queue:
        face, steps = queue.popleft()
        for other in adjacent[face]:
            if distance[other] is None and other in open_faces:
                distance[other] = steps + 1
                queue.append((other, steps + 1))
    return distance


class Pursuit:
    """The goals a robot that tries its best pursues in a play, and each face's distance to
    where each of them can hold.

    ``goals`` are the game's system goals that come from the parts of ``core`` (all of them
    when ``core`` is None).  A goal's faces are those where the robot can make it hold whatever
    the sensors read, or, when there are none, those where it can hold at all (the face of the
    step's next state for a goal that reads it: a monitor moves on the letter it reads next).
    Distances count crossings through the faces the robot may be in: those that every safety
    guarantee of the game allows it in, for some values of the other variables."""

    def __init__(self, game: MissionGame, core: Collection[TaskPart] | None) -> None:
        spec = game.spec
        wanted = None if core is None else {id(part) for part in core}
        self.goals: tuple[Part, ...] = tuple(
            p
            for p in spec.select("sys", "liveness")
            if wanted is None or id(game.sources.get(id(p))) in wanted
        )
        self.enc = Encoding(spec)
        self.face_count = game.faces.count
        self.domain = self.enc.domain(None, False) & self.enc.domain(None, True)
        open_faces = set(range(self.face_count))
        for part in spec.select("sys", "safety"):
            open_faces &= self._faces_where(self.enc.part(part), primed=True)
        self.bdds: tuple[Function, ...] = tuple(self.enc.part(p) for p in self.goals)
        self.reads_next = tuple(any(primed for _, primed in support(p.formula)) for p in self.goals)
        self.distances: tuple[list[int | None], ...] = tuple(
            face_distances(
                game.faces.adjacent,
                self._goal_faces(bdd, primed=(FACE, True) in support(goal.formula)),
                open_faces,
            )
            for goal, bdd in zip(self.goals, self.bdds, strict=True)
        )

    def _faces_where(self, u: Function, *, primed: bool) -> set[int]:
        """The faces of the current state (of the next one when ``primed``) in which ``u`` can
        hold."""
        return self._faces(self._on_face(u, primed), primed)

    def _goal_faces(self, u: Function, *, primed: bool) -> set[int]:
        """The faces where the robot can make the goal ``u`` hold whatever the sensors read
        (of the state whose face the goal reads); failing any, those where it can hold."""
        enc = self.enc
        sensors = {
            bit
            for v in enc.spec.owned("env")
            if v.is_bool and v.name != MOVED
            for bit in (enc.next_bits if primed else enc.bits)[v.name]
        }
        forced = self._faces(
            enc.bdd.forall(sensors, self._on_face(u, primed, keep=sensors)), primed
        )
        return forced or self._faces_where(u, primed=primed)

    def _on_face(self, u: Function, primed: bool, keep: AbstractSet[str] = frozenset()) -> Function:
        """``u`` (within the variables' ranges) with every bit but the face's (current, or next
        when ``primed``) and those of ``keep`` quantified existentially."""
        enc = self.enc
        face_bits = set((enc.next_bits if primed else enc.bits)[FACE])
        others = (enc.names(None, False) | enc.names(None, True)) - face_bits - keep
        return enc.bdd.exist(others, u & self.domain)

    def _faces(self, where: Function, primed: bool) -> set[int]:
        """The faces (current, or next when ``primed``) that ``where`` allows."""
        enc = self.enc
        face = enc.spec.variable(FACE)
        return {
            f
            for f in range(self.face_count)
            if where & enc.value_cube(face, f, primed) != enc.bdd.false
        }

    def secured(self, goal: int, state: dict[str, Value] | None, after: dict[str, Value]) -> bool:
        """Whether the step from ``state`` to ``after`` (None to the first state) secures goal
        number ``goal``: it holds on that step, for a goal that reads the next state; else it
        holds in ``after``, so on every step from there."""
        if self.reads_next[goal]:
            if state is None:
                return False
            bits = {**bits_of(self.enc, state, False), **bits_of(self.enc, after, True)}
        else:
            bits = bits_of(self.enc, after, False)
        return bool(restrict(self.enc, bits, self.bdds[goal]) == self.enc.bdd.true)

    def pursued_next(
        self, pursued: int, state: dict[str, Value] | None, after: dict[str, Value]
    ) -> int:
        """The goal pursued after the step from ``state`` to ``after``: the next one in turn
        once that step secures goal number ``pursued``."""
        if self.goals and self.secured(pursued, state, after):
            return self._following(pursued)
        return pursued

    def _following(self, pursued: int) -> int:
        """The goal pursued once goal number ``pursued`` is secured."""
        return (pursued + 1) % len(self.goals)

    def merit(
        self, pursued: int, state: dict[str, Value] | None, after: dict[str, Value], safe: bool
    ) -> tuple[bool, bool, int, bool]:
        """How an answer leading to ``after`` ranks for a robot in ``state`` that pursues goal
        number ``pursued`` (smallest first); ``safe``: the robot need never get stuck after it.

        A play where the robot idles, walks into a trap or wanders shows nothing of how the
        environment wins: the robot never gets stuck if it can help it, fulfils the goal when
        it can, heads for the goal it then pursues, and moves rather than stays."""
        if not self.goals:
            return (not safe, True, 0, int(after[GOAL]) == int(after[FACE]))
        heading = int(after[GOAL])
        fulfils = self.secured(pursued, state, after)
        aim = self._following(pursued) if fulfils else pursued
        return (not safe, not fulfils, self.distance(aim, heading), heading == int(after[FACE]))

    def distance(self, goal: int, face: int) -> int:
        """Crossings from ``face`` to a face where goal number ``goal`` can hold (more than
        any real distance when there is no way)."""
        found = self.distances[goal][face]
        return self.face_count if found is None else found


def never_stuck(counter: CounterStrategy) -> set[int]:
    """The nodes from which the robot has answers forever (a greatest fixpoint: the largest
    set of nodes each with an answer inside it)."""
    kept = {n for n, answers in enumerate(counter.answers) if answers}
    while True:
        smaller = {n for n in kept if any(a in kept for a in counter.answers[n])}
        if smaller == kept:
            return kept
        kept = smaller


def _best(
    pursuit: Pursuit,
    pursued: int,
    state: dict[str, Value] | None,
    options: Sequence[int],
    counter: CounterStrategy,
    safe: Collection[int],
) -> int:
    """The robot's choice among the nodes ``options`` (from ``state``; None: the first
    state): the first of those that rank best (:meth:`Pursuit.merit`)."""
    scores = [pursuit.merit(pursued, state, counter.states[n], n in safe) for n in options]
    return options[scores.index(min(scores))]


def counter_play_steps(
    counter: CounterStrategy, game: MissionGame, core: Collection[TaskPart] | None = None
) -> Play:
    """One play of the counterstrategy (empty when it has no start), against a robot that
    pursues the goals of the task parts ``core`` (None: every goal of the game)."""
    if not counter.initial:
        return Play((), False, None)
    sensors = [v.name for v in game.spec.owned("env") if v.is_bool and v.name != MOVED]
    safe = never_stuck(counter)
    pursuit = Pursuit(game, core)
    steps: list[PlayStep] = []
    # a point of the play: the node and the goal the robot pursues (its own memory)
    seen: dict[tuple[int, int], int] = {}
    node = _best(pursuit, 0, None, counter.initial, counter, safe)
    pursued = pursuit.pursued_next(0, None, counter.states[node])
    step = 0
    while (node, pursued) not in seen and step < MAX_STEPS:
        seen[node, pursued] = step
        state = counter.states[node]
        steps.append(
            PlayStep(
                step=step,
                node=node,
                face=int(state[FACE]),
                heading=int(state[GOAL]),
                sensors=tuple((s, bool(state.get(s))) for s in sensors),
            )
        )
        answers = counter.answers[node]
        if not answers:
            return Play(tuple(steps), True, None)

        answer = _best(pursuit, pursued, state, answers, counter, safe)
        pursued = pursuit.pursued_next(pursued, state, counter.states[answer])
        node = answer
        step += 1
    return Play(tuple(steps), False, seen.get((node, pursued)))


def counter_play(
    counter: CounterStrategy, game: MissionGame, core: Collection[TaskPart] | None = None
) -> list[str]:
    """The lines of one play of the counterstrategy (empty when it has no start), against a
    robot that pursues the goals of the task parts ``core`` (None: every goal of the game)."""
    play = counter_play_steps(counter, game, core)
    letters = game.faces.letters
    lines: list[str] = []
    for entry in play.steps:
        on = [name for name, value in entry.sensors if value]
        reading = ("sensing " + ", ".join(on)) if on else "sensing nothing"
        heading = entry.heading
        line = (
            f"in {place(letters[entry.face])}, {reading}, heading for "
            f"{'its own place' if heading == entry.face else place(letters[heading])}"
        )
        if not lines or not lines[-1].endswith(line):  # the same but for the task's memory
            lines.append(f"{entry.step}: {line}")
    if play.stuck:
        lines.append(f"{play.steps[-1].step + 1}: the robot has no allowed move left")
    elif play.again_from is not None:
        lines.append(f"then again from step {play.again_from}, forever")
    return lines
