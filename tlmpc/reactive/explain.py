"""An unrealizable mission's counterstrategy, told in the mission's words.

The environment's winning strategy is a graph; one play of it — the environment's moves
against the robot's first allowed answer at every step, up to the first node met again —
is a concrete sequence of sensor readings and arrivals that defeats the robot.  At each step
the robot is shown taking an answer that neither leaves it stuck nor stays put, where it has
one; steps that differ only in the task's memory are shown once.
"""

from __future__ import annotations

from tlmpc.reactive.game import FACE, GOAL, MOVED, MissionGame
from tlmpc.synth.counter import CounterStrategy

#: the longest play shown (steps)
MAX_STEPS = 12


def place(letters: tuple[str, ...]) -> str:
    """A face's label in words: its regions, or free space."""
    return " & ".join(letters) if letters else "free space"


def counter_play(counter: CounterStrategy, game: MissionGame) -> list[str]:
    """The lines of one play of the counterstrategy (empty when it has no start)."""
    if not counter.initial:
        return []
    sensors = [v.name for v in game.spec.owned("env") if v.is_bool and v.name != MOVED]
    letters = game.faces.letters

    def reading(state: dict[str, int | bool]) -> str:
        on = [s for s in sensors if state.get(s)]
        return ("sensing " + ", ".join(on)) if on else "sensing nothing"

    # nodes from which the robot can avoid getting stuck forever (a greatest fixpoint)
    safe = {n for n, answers in enumerate(counter.answers) if answers}
    while True:
        kept = {n for n in safe if any(a in safe for a in counter.answers[n])}
        if kept == safe:
            break
        safe = kept
    lines: list[str] = []
    seen: dict[int, int] = {}
    node = counter.initial[0]
    step = 0
    while node not in seen and step < MAX_STEPS:
        seen[node] = step
        state = counter.states[node]
        here, heading = int(state[FACE]), int(state[GOAL])
        line = (
            f"in {place(letters[here])}, {reading(state)}, heading for "
            f"{'its own place' if heading == here else place(letters[heading])}"
        )
        if not lines or not lines[-1].endswith(line):  # the same but for the task's memory
            lines.append(f"{step}: {line}")
        answers = counter.answers[node]
        if not answers:
            lines.append(f"{step + 1}: the robot has no allowed move left")
            return lines

        # the robot's best-looking answer: one from which it need never get stuck, and that
        # keeps it moving (a play where it idles or walks into a forbidden place shows
        # nothing of how the environment wins)
        def merit(n: int) -> tuple[bool, bool]:
            state = counter.states[n]
            return (n not in safe, int(state[GOAL]) == int(state[FACE]))

        node = min(answers, key=merit)
        step += 1
    if node in seen:
        lines.append(f"then again from step {seen[node]}, forever")
    return lines
