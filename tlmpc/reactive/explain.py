"""An unrealizable mission's counterstrategy, told in the mission's words.

The environment's winning strategy is a graph; one play of it — the environment's moves
against the robot's first allowed answer at every step, up to the first node met again —
is a concrete sequence of sensor readings and arrivals that defeats the robot.  At each step
the robot is shown taking an answer that neither leaves it stuck nor stays put, where it has
one; steps that differ only in the task's memory are shown once.
"""

from __future__ import annotations

from dataclasses import dataclass

from tlmpc.reactive.game import MissionGame
from tlmpc.reactive.nodes import FACE, GOAL, MOVED
from tlmpc.synth.counter import CounterStrategy

#: the longest play shown (steps)
MAX_STEPS = 12


def place(letters: tuple[str, ...]) -> str:
    """A face's label in words: its regions, or free space."""
    return " & ".join(letters) if letters else "free space"


@dataclass(frozen=True, slots=True)
class PlayStep:
    """One step of a play of the counterstrategy: where the robot is, what it senses, and the
    face it heads for (its own: it stays)."""

    step: int
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


def counter_play_steps(counter: CounterStrategy, game: MissionGame) -> Play:
    """One play of the counterstrategy (empty when it has no start)."""
    if not counter.initial:
        return Play((), False, None)
    sensors = [v.name for v in game.spec.owned("env") if v.is_bool and v.name != MOVED]
    # nodes from which the robot can avoid getting stuck forever (a greatest fixpoint)
    safe = {n for n, answers in enumerate(counter.answers) if answers}
    while True:
        kept = {n for n in safe if any(a in safe for a in counter.answers[n])}
        if kept == safe:
            break
        safe = kept
    steps: list[PlayStep] = []
    seen: dict[int, int] = {}
    node = counter.initial[0]
    step = 0
    while node not in seen and step < MAX_STEPS:
        seen[node] = step
        state = counter.states[node]
        steps.append(
            PlayStep(
                step=step,
                face=int(state[FACE]),
                heading=int(state[GOAL]),
                sensors=tuple((s, bool(state.get(s))) for s in sensors),
            )
        )
        answers = counter.answers[node]
        if not answers:
            return Play(tuple(steps), True, None)

        # the robot's best-looking answer: one from which it need never get stuck, and that
        # keeps it moving (a play where it idles or walks into a forbidden place shows
        # nothing of how the environment wins)
        def merit(n: int) -> tuple[bool, bool]:
            state = counter.states[n]
            return (n not in safe, int(state[GOAL]) == int(state[FACE]))

        node = min(answers, key=merit)
        step += 1
    return Play(tuple(steps), False, seen.get(node))


def counter_play(counter: CounterStrategy, game: MissionGame) -> list[str]:
    """The lines of one play of the counterstrategy (empty when it has no start)."""
    play = counter_play_steps(counter, game)
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
