"""The winning strategy of a reactive mission as the executor steps it.

``strategy.json`` holds the Mealy machine explicitly: nodes (each a full valuation of the
game's variables), initial nodes and transitions.  A transition into a node reads that node's
environment inputs and answers with its system outputs.  The executor observes the
environment's *visible* inputs — the sensors, the robot's face and ``moved`` — and the
assumptions' monitor states follow from them (their automata are deterministic), so from a
node every visible input selects at most one transition.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

from tlmpc.base.errors import UsageError, error
from tlmpc.reactive.nodes import FACE, GOAL, MOVED, NodeBehaviour, Value


class Stepper(Protocol):
    """What the executor asks of a strategy: this explicit machine, or the symbolic one
    (``tlmpc.reactive.stepper``) for strategies too large to list node by node."""

    @property
    def sensors(self) -> Sequence[str]: ...
    @property
    def actions(self) -> Sequence[str]: ...
    @property
    def counters(self) -> Sequence[int]: ...
    @property
    def labels(self) -> Sequence[tuple[str, ...]]: ...
    @property
    def adjacent(self) -> Sequence[tuple[int, ...]]: ...
    @property
    def face_of(self) -> Sequence[int]: ...
    def start(self, sensors: Mapping[str, bool], face: int) -> int | None: ...
    def answer(
        self, node: int, sensors: Mapping[str, bool], face: int, moved: bool
    ) -> int | None: ...
    def goal(self, node: int) -> int: ...
    def action_values(self, node: int) -> dict[str, bool]: ...
    def behaviour(self, node: int) -> tuple[Value, ...]: ...


def strategy_stepper(
    document: Mapping[str, Any], sensors: Sequence[str], actions: Sequence[str], file: str
) -> Stepper:
    """The stepper of a reactive ``strategy.json``: its explicit machine when the file lists
    one (small strategies), else its symbolic form."""
    if "nodes" in document:
        return StrategyMachine.of_json(document, sensors, actions, file)
    from tlmpc.reactive.stepper import SymbolicMachine

    return SymbolicMachine.of_json(document, sensors, actions, file)


def _refuse_broken_graph(document: Mapping[str, Any], variables: Sequence[str], file: str) -> None:
    """Refuse (Q123) an explicit machine the executor could not step: a node without a value
    of every variable, a transition or initial node naming no node (an edited file)."""
    nodes = document["nodes"]

    def is_node(index: Any) -> bool:
        return type(index) is int and 0 <= index < len(nodes)

    for number, node in enumerate(nodes):
        missing = [name for name in variables if name not in node["state"]]
        if missing:
            problem = f"node {number} has no value of {', '.join(missing)}"
            break
    else:
        ends = [end for pair in document["transitions"] for end in pair]
        if all(map(is_node, [*ends, *document["initial"]])):
            return
        problem = "a transition or an initial node names no node"
    raise UsageError(
        error(
            "Q123",
            f"strategy.json is not a strategy tlmpc writes: {problem}",
            hint="the file was edited or damaged: compile the mission again",
            file=file,
        )
    )


@dataclass(frozen=True)
class StrategyMachine(NodeBehaviour):
    """The Mealy machine of ``strategy.json`` with its transitions indexed by visible input.

    ``visible`` are the environment inputs the executor reads (sensors, ``face``, ``moved``);
    ``nodes[n]`` is node n's valuation; ``answers[n]`` maps a visible input (values in the
    order of ``visible``) to the node the strategy moves to.
    """

    visible: tuple[str, ...]
    sensors: tuple[str, ...]
    actions: tuple[str, ...]
    nodes: tuple[Mapping[str, Value], ...]
    #: the system goal each node pursues (the strategy's memory of its recurrence goals)
    counters: tuple[int, ...]
    initial: tuple[int, ...]
    answers: tuple[Mapping[tuple[Value, ...], int], ...]
    labels: tuple[tuple[str, ...], ...]
    adjacent: tuple[tuple[int, ...], ...]
    face_of: tuple[int, ...]

    @classmethod
    def of_json(
        cls, document: Mapping[str, Any], sensors: Sequence[str], actions: Sequence[str], file: str
    ) -> StrategyMachine:
        """The machine of a reactive ``strategy.json`` (Q123 when it is not one)."""
        inputs = [v["name"] for v in document["inputs"]]
        outputs = [v["name"] for v in document["outputs"]]
        faces = document.get("faces")
        # mission.json keeps sensors by name; the game declares them in the file's order
        count = len(sensors)
        if (
            faces is None
            or sorted(inputs[:count]) != sorted(sensors)
            or inputs[count : count + 2] != [FACE, MOVED]
            or outputs[:1] != [GOAL]
            or sorted(outputs[1 : 1 + len(actions)]) != sorted(actions)
        ):
            raise UsageError(
                error(
                    "Q123",
                    "strategy.json is not the strategy of this reactive mission (its inputs "
                    f"{inputs} and outputs {outputs} do not match the mission's sensors "
                    f"{list(sensors)} and actions {list(actions)}, or it has no faces)",
                    hint="the output folder mixes two compilations: compile the mission again",
                    file=file,
                )
            )
        _refuse_broken_graph(document, [*inputs, *outputs], file)
        sensors, actions = inputs[:count], outputs[1 : 1 + len(actions)]
        visible = (*sensors, FACE, MOVED)
        nodes = tuple(dict(node["state"]) for node in document["nodes"])
        answers: list[dict[tuple[Value, ...], int]] = [{} for _ in nodes]
        for source, target in document["transitions"]:
            key = tuple(nodes[target][name] for name in visible)
            found = answers[source].setdefault(key, target)
            if found != target:
                raise UsageError(
                    error(
                        "Q123",
                        f"strategy.json: node {source} answers one reading two ways "
                        f"(nodes {found} and {target})",
                        hint="a strategy of tlmpc is deterministic: compile the mission again",
                        file=file,
                    )
                )
        return cls(
            visible=visible,
            sensors=tuple(sensors),
            actions=tuple(actions),
            nodes=nodes,
            counters=tuple(int(node["goal"]) for node in document["nodes"]),
            initial=tuple(document["initial"]),
            answers=tuple(answers),
            labels=tuple(tuple(letter) for letter in faces["labels"]),
            adjacent=tuple(tuple(a) for a in faces["adjacent"]),
            face_of=tuple(faces["face_of"]),
        )

    def key(self, sensors: Mapping[str, bool], face: int, moved: bool) -> tuple[Value, ...]:
        """The visible input as the index reads it."""
        return (*(bool(sensors[s]) for s in self.sensors), face, moved)

    def start(self, sensors: Mapping[str, bool], face: int) -> int | None:
        """The initial node for the first reading (None: the strategy serves no such start)."""
        key = self.key(sensors, face, False)
        for node in self.initial:
            if tuple(self.nodes[node][name] for name in self.visible) == key:
                return node
        return None

    def answer(self, node: int, sensors: Mapping[str, bool], face: int, moved: bool) -> int | None:
        """The node the strategy moves to from ``node`` on this reading (None: no move —
        the reading breaks an assumption or a rule of the motion)."""
        return self.answers[node].get(self.key(sensors, face, moved))


__all__ = ["Stepper", "StrategyMachine", "strategy_stepper"]
