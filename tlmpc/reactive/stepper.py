"""A reactive mission's symbolic strategy, stepped as an executor steps the explicit machine.

``strategy.json`` of a reactive mission always holds the symbolic form (decision diagrams per
output bit, :mod:`tlmpc.synth.symbolic_strategy`) and lists the explicit machine only while it
is small.  :class:`SymbolicMachine` offers the explicit machine's stepping interface (``start``,
``answer``, ``goal``, ``action_values``, ``behaviour``, ``counters``, the faces) on the symbolic
form: nodes are numbered as they are met.  The executor reads the *visible* inputs (sensors,
``face``, ``moved``); the assumptions' monitor states are the environment's too, and since
their automata are deterministic exactly one value of them keeps the environment's safety:
that one is taken.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from tlmpc.base.errors import UsageError, error
from tlmpc.reactive.nodes import FACE, GOAL, MOVED, NodeBehaviour, Value
from tlmpc.synth.spec import Variable
from tlmpc.synth.symbolic_strategy import SymbolicStrategy, symbolic_from_json


def _values(variable: Variable) -> list[Value]:
    if variable.is_bool:
        return [False, True]
    assert variable.low is not None
    assert variable.high is not None
    return list(range(variable.low, variable.high + 1))


@dataclass
class SymbolicMachine(NodeBehaviour):
    """The symbolic strategy with the explicit machine's interface (nodes met so far)."""

    strategy: SymbolicStrategy
    visible: tuple[str, ...]
    sensors: tuple[str, ...]
    actions: tuple[str, ...]
    labels: tuple[tuple[str, ...], ...]
    adjacent: tuple[tuple[int, ...], ...]
    face_of: tuple[int, ...]
    nodes: list[dict[str, Value]] = field(default_factory=list)
    counters: list[int] = field(default_factory=list)
    initial: list[int] = field(default_factory=list)
    _index: dict[tuple[tuple[Value, ...], int], int] = field(default_factory=dict)
    _answers: dict[tuple[int, tuple[Value, ...]], int | None] = field(default_factory=dict)

    @classmethod
    def of_json(
        cls, document: Mapping[str, Any], sensors: Sequence[str], actions: Sequence[str], file: str
    ) -> SymbolicMachine:
        """The machine of a reactive ``strategy.json``'s symbolic form (Q137 when it has none
        or is not this mission's)."""
        faces = document.get("faces")
        inputs = [v["name"] for v in document.get("inputs", [])]
        outputs = [v["name"] for v in document.get("outputs", [])]
        count = len(sensors)
        if (
            "symbolic" not in document
            or faces is None
            or sorted(inputs[:count]) != sorted(sensors)
            or inputs[count : count + 2] != [FACE, MOVED]
            or outputs[:1] != [GOAL]
            or sorted(outputs[1 : 1 + len(actions)]) != sorted(actions)
        ):
            raise UsageError(
                error(
                    "Q137",
                    "strategy.json has no symbolic strategy of this reactive mission",
                    hint="the output folder mixes two compilations, or an older tlmpc wrote "
                    "it: compile the mission again",
                    file=file,
                )
            )
        strategy = symbolic_from_json(document)
        return cls(
            strategy=strategy,
            visible=(*inputs[:count], FACE, MOVED),
            sensors=tuple(inputs[:count]),
            actions=tuple(outputs[1 : 1 + len(actions)]),
            labels=tuple(tuple(letter) for letter in faces["labels"]),
            adjacent=tuple(tuple(a) for a in faces["adjacent"]),
            face_of=tuple(faces["face_of"]),
        )

    def key(self, sensors: Mapping[str, bool], face: int, moved: bool) -> tuple[Value, ...]:
        """The visible input, in the order of ``visible``."""
        return (*(bool(sensors[s]) for s in self.sensors), face, moved)

    def _hidden(self) -> list[Variable]:
        return [v for v in self.strategy.inputs if v.name not in self.visible]

    def _inputs(self, key: tuple[Value, ...]) -> list[dict[str, Value]]:
        """Every full input with these visible values (the hidden ones enumerated)."""
        shown = dict(zip(self.visible, key, strict=True))
        hidden = self._hidden()
        return [
            {**shown, **dict(zip((v.name for v in hidden), combo, strict=True))}
            for combo in itertools.product(*(_values(v) for v in hidden))
        ]

    def _node(self, state: dict[str, Value], goal: int) -> int:
        names = [v.name for v in self.strategy.variables]
        key = (tuple(state[n] for n in names), goal)
        found = self._index.get(key)
        if found is None:
            found = len(self.nodes)
            self._index[key] = found
            self.nodes.append(state)
            self.counters.append(goal)
        return found

    def start(self, sensors: Mapping[str, bool], face: int) -> int | None:
        """The first node for the first reading (None: the strategy serves no such start)."""
        for inputs in self._inputs(self.key(sensors, face, False)):
            state = self.strategy.start(inputs)
            if state is not None:
                node = self._node(state, 0)
                if node not in self.initial:
                    self.initial.append(node)
                return node
        return None

    def answer(self, node: int, sensors: Mapping[str, bool], face: int, moved: bool) -> int | None:
        """The node the strategy moves to from ``node`` on this reading (None: the reading
        breaks an assumption or a rule of the motion)."""
        key = self.key(sensors, face, moved)
        if (node, key) not in self._answers:
            found: int | None = None
            for inputs in self._inputs(key):
                stepped = self.strategy.step(self.nodes[node], self.counters[node], inputs)
                if stepped is not None:
                    found = self._node(*stepped)
                    break
            self._answers[(node, key)] = found
        return self._answers[(node, key)]


__all__ = ["SymbolicMachine"]
