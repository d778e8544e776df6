"""The task split into the parts the user wrote, with their positions (for explanations).

Computed on demand (only when no plan exists), so loading a mission pays nothing for it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from tlmpc.ltl.ast import And, Formula, Or, Prop
from tlmpc.ltl.printer import to_text
from tlmpc.ltl.transform import substitute
from tlmpc.mission.model import Mission, TaskPart
from tlmpc.tasks.compiler import compile_phrases


def group_expansion(groups: Mapping[str, Sequence[str]]) -> dict[str, Formula]:
    """Each group name as the formula it stands for: "in any of its regions"."""
    return {
        g: Or(tuple(Prop(m) for m in members)) if len(members) > 1 else Prop(members[0])
        for g, members in groups.items()
    }


def task_parts(mission: Mission) -> tuple[TaskPart, ...]:
    """Each task phrase, and each top-level conjunct of ``ltl``, with where it starts.

    Group names are expanded as in :attr:`Mission.formula`.  The mission loaded, so its task
    compiles and nothing here can fail.  A mission read back from ``mission.json`` has no
    positions: its parts have none either (no line rather than a made-up one).
    """
    expand = group_expansion(mission.groups)
    groups = {g: list(members) for g, members in mission.groups.items()}
    positions = list(mission.task_positions)
    places = list(mission.task_places)
    parts: list[TaskPart] = []
    for index, phrase in enumerate(mission.task):
        known = index < len(positions)
        line, col = positions[index] if known else (1, 1)
        formula = compile_phrases(
            [phrase],
            groups=groups,
            file=mission.source,
            positions=[(line, col)],
            places=[places[index] if index < len(places) else None],
        )
        parts.append(
            TaskPart(
                text=phrase,
                formula=substitute(formula, expand),
                line=line if known else None,
                col=col if known else None,
            )
        )
    if mission.ltl and mission.ltl.strip():
        from tlmpc.ltl.parser import parse_ltl  # lark: only for missions with `ltl`

        index = len(mission.task)
        known = index < len(positions)
        line, col = positions[index] if known else (1, 1)
        place = places[index] if index < len(places) else None
        whole = parse_ltl(mission.ltl, file=mission.source, line=line, col=col, place=place)
        for conjunct in whole.args if isinstance(whole, And) else (whole,):
            span = getattr(conjunct, "span", None) if known else None
            parts.append(
                TaskPart(
                    text=to_text(conjunct),
                    formula=substitute(conjunct, expand),
                    line=span.line if span else (line if known else None),
                    col=span.col if span else (col if known else None),
                )
            )
    return tuple(parts)
