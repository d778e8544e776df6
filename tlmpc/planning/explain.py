"""Invariant pruning and "no plan" explanations in the user's terms."""

from __future__ import annotations

import dataclasses
import enum
import functools
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from tlmpc.abstraction.model import Abstraction
from tlmpc.automata.guards import holds
from tlmpc.automata.model import Automaton
from tlmpc.base.errors import Diagnostic, error
from tlmpc.ltl.ast import And, Formula, Globally, Not, Prop, conjoin, is_propositional
from tlmpc.ltl.printer import to_text
from tlmpc.ltl.transform import nnf
from tlmpc.mission.model import Options, TaskPart
from tlmpc.planning.boundary import StartCell
from tlmpc.planning.reach import passable_vertices, reachable_triangles

BoolArray = npt.NDArray[np.bool_]


def invariants(formula: Formula) -> list[Formula]:
    """The top-level conjuncts ``G p`` with ``p`` propositional (as their ``p``)."""
    normal = nnf(formula)
    parts = normal.args if isinstance(normal, And) else (normal,)
    found: list[Formula] = []
    for part in parts:
        match part:
            case Globally(And(args)) if is_propositional(part.arg):
                found.extend(args)
            case Globally(inner) if is_propositional(inner):
                found.append(inner)
            case _:
                pass  # not an invariant
    return found


def invariant_mask(abstraction: Abstraction, formula: Formula) -> BoolArray:
    """Triangles whose label satisfies every invariant ``G p`` of the formula."""
    required = invariants(formula)  # once, not once per letter (12k letters at 100k triangles)
    if not required:
        return np.ones(abstraction.num_triangles, dtype=bool)
    letter_ok = np.array(
        [all(holds(p, set(letter)) for p in required) for letter in abstraction.letters],
        dtype=bool,
    )
    return letter_ok[abstraction.letter_of]


def _positive_props(formula: Formula) -> list[str]:
    """Regions the formula mentions outside a negation (in negation normal form).

    Only these can be *needed*: a region that occurs only negated (``G !c``, ``!moat | goal``)
    is one the task forbids or allows, never one it asks the robot to reach.
    """
    positive: set[str] = set()
    stack = [nnf(formula)]
    while stack:
        match stack.pop():
            case Prop(name):
                positive.add(name)
            case Not():
                pass  # in NNF a negation holds a proposition only
            case node:
                stack.extend(node.children())
    names = [n.name for n in formula.walk() if isinstance(n, Prop)]
    return [p for p in dict.fromkeys(names) if p in positive]


def _no_free_space(name: str, **where: Any) -> Diagnostic:
    """P004: region ``name`` has no triangle the robot can be in."""
    return error(
        "P004",
        f"region {name!r} has no free space the robot can be in: it lies in holes, or within "
        "the body's radius of obstacles",
        hint="move or enlarge the region, or the holes (R003 says when the body is what keeps "
        "the robot out)",
        **where,
    )


@functools.lru_cache(maxsize=16)
def satisfiable_anywhere(formula: Formula) -> bool:
    """Whether some trajectory on some map satisfies ``formula`` (its automaton over every
    letter has an edge).  Kept for the formulas last asked: a planner that tries several
    meshes asks why each failed, about the same task each time."""
    from tlmpc.automata.translate import translate

    return bool(translate(formula).edges)


def explain_no_plan(
    abstraction: Abstraction,
    automaton: Automaton,
    formula: Formula,
    allowed: BoolArray,
    *,
    starts: Sequence[StartCell] | None = None,
    start_label: tuple[str, ...] | None = None,
) -> list[Diagnostic]:
    """Why no accepting lasso exists, most specific reason first.

    ``starts`` are the triangles holding the start point (default: the abstraction's start
    triangle); ``start_label`` is the start point's own label under the closed convention
    (None under the right-continuous one, where the start reads its first triangle's label).
    """
    from tlmpc.planning.boundary import POINT

    text = to_text(formula)
    if not satisfiable_anywhere(formula):
        return [
            error(
                "P001",
                f"the task is unsatisfiable on its own: no trajectory on any map "
                f"can satisfy `{text}`",
                hint="look for contradicting parts, such as `visit a` with `avoid a`",
            )
        ]
    if not automaton.edges:
        # a needed region with no triangle at all (in holes, or within the body's radius of
        # obstacles) empties the automaton too: that, not an overlap, is the reason
        held = {name for letter in abstraction.letters for name in letter}
        missing = [name for name in _positive_props(formula) if name not in held]
        if missing:
            return [_no_free_space(name) for name in sorted(missing)]
        return [
            error(
                "P006",
                "the task needs label combinations this map does not have "
                "(regions that would have to overlap)",
                hint="check which regions the task asks the robot to be in at the same time",
            )
        ]
    cells = [abstraction.start] if starts is None else [c.triangle for c in starts]
    # Every label the robot can have at t = 0: its first triangle's (any one holding the
    # start), and under the closed convention the start point's own label before it.
    firsts = sorted({abstraction.labels(t) for t in cells})
    where = " or ".join(f"in {', '.join(x)}" if x else "in free space" for x in firsts)
    required = invariants(formula)
    broken = [p for p in required if start_label is not None and not holds(p, set(start_label))]
    if broken or not any(allowed[t] for t in cells):
        if start_label is not None and broken:
            where = f"in {', '.join(start_label)}" if start_label else "in free space"
        else:
            broken = [p for p in required if not all(holds(p, set(x)) for x in firsts)]
        return [
            error(
                "P002",
                f"the robot starts {where}, but the task requires "
                f"`G {to_text(broken[0]) if broken else '...'}` from the start",
                hint="move the start or relax the task",
            )
        ]
    first_words = [[(*start_label, POINT), x] if start_label is not None else [x] for x in firsts]
    if not any(_can_start(automaton, word) for word in first_words):
        return [
            error(
                "P003",
                f"the task already fails where the robot starts ({where})",
                hint=f"`{text}` constrains the first instant; move the start or the task",
            )
        ]
    problems = _region_facts(abstraction, formula, {}, cells, closed=start_label is not None)
    if problems:
        return problems
    return [
        error(
            "P007",
            f"no trajectory on this map satisfies `{text}`",
            hint="check that the regions can be visited in the required order",
        )
    ]


class Undecided(enum.Enum):
    """A conjunction of task parts whose search the planner's budget stopped: not known to
    have a plan, nor to have none."""

    BEYOND_BUDGET = "beyond the planner's budget"


#: Codes of explanations that are exact facts about the whole task (kept as they are).
_EXACT = {"P001", "P002", "P003", "P006"}
#: A minimal blamed set of parts is sought only for tasks of at most this many parts.
MAX_CORE_PARTS = 12


def explain_infeasible(
    abstraction: Abstraction,
    automaton: Automaton,
    *,
    formula: Formula,
    options: Options,
    start_point: tuple[float, float],
    parts: Sequence[TaskPart],
    file: str | None,
    fallback: Sequence[Diagnostic],
    no_plan_reasons: Callable[[Formula], Sequence[Diagnostic] | Undecided | None],
) -> list[Diagnostic]:
    """Why no trajectory in the plane satisfies the task, blaming the parts that fail.

    Called only once planning *with U-turns* failed, which is exact (see docs/planning.md).
    The blamed parts are a minimal set of task parts (phrases, top-level LTL conjuncts) that
    already has no plan on this map: dropping any one of them makes the rest possible, or
    leaves a task the planner's budget could not decide (the hint then says so).
    ``no_plan_reasons(formula)`` is the planner's explanation why a conjunction of parts has
    no plan, None when it has one, or :attr:`Undecided.BEYOND_BUDGET` (the caller's planner:
    this module explains, it does not plan).  When the whole task's reason is exact
    (``fallback`` holds a P001, P002, P003 or P006), the blamed parts are a minimal set that
    still has that reason, and the reason is stated for them alone.
    """
    if not parts:
        return list(fallback)
    from tlmpc.planning.boundary import start_cells

    exact_codes = {d.code for d in fallback if d.code in _EXACT}

    def fails_alike(reasons: Sequence[Diagnostic] | Undecided | None) -> bool:
        # Parts that fail for another reason than the whole task's exact one cannot carry
        # that reason: a start in a forbidden region is not the fault of an unreachable goal.
        if reasons is None or isinstance(reasons, Undecided):
            return False
        return not exact_codes or any(d.code in exact_codes for d in reasons)

    core = list(parts)
    core_reasons: Sequence[Diagnostic] = fallback
    # Parts kept because the rest without them was beyond the budget, not shown possible.
    kept_undecided: set[int] = set()
    if 1 < len(parts) <= MAX_CORE_PARTS:
        for part in list(parts):
            rest = [p for p in core if p is not part]
            if not rest:
                continue
            reasons = no_plan_reasons(conjoin([p.formula for p in rest]))
            if isinstance(reasons, Undecided):
                kept_undecided.add(id(part))
            elif fails_alike(reasons):
                core, core_reasons = rest, reasons or ()
    blamed = conjoin([p.formula for p in core])
    first = core[0]
    where: dict[str, Any] = {"file": file, "line": first.line, "col": first.col}
    quoted = ", ".join(f"`{p.text}`" + _at(file, p) for p in core)
    exact = [d for d in core_reasons if d.code in exact_codes]
    if exact:
        # The reason is exact (e.g. the start violates an invariant) and worded for the
        # blamed parts; point it at them.
        involved = f"; the parts involved: {quoted}" if len(core) > 1 else ""
        return [dataclasses.replace(d, hint=(d.hint or "") + involved, **where) for d in exact]
    cells = [c.triangle for c in start_cells(abstraction, start_point)]
    closed = options.boundary == "closed"
    facts = "; ".join(
        d.message for d in _region_facts(abstraction, blamed, where, cells, closed=closed)
    )
    if len(core) == 1:
        headline = error(
            "P010",
            f"no trajectory on this map satisfies the task part `{first.text}`"
            + (f" ({to_text(first.formula)})" if to_text(first.formula) != first.text else ""),
            hint=facts
            or "no route through the map's regions (U-turns allowed) visits them as it asks",
            **where,
        )
    else:
        headline = error(
            "P011",
            f"these parts of the task cannot all hold on this map: {quoted}",
            hint=_without_each(core, kept_undecided)
            + (facts or "relax one of them or change the map"),
            **where,
        )
    return [headline]


def _without_each(core: Sequence[TaskPart], kept_undecided: set[int]) -> str:
    """What is known of the blamed parts without each one of them."""
    undecided = [f"`{p.text}`" for p in core if id(p) in kept_undecided]
    if not undecided:
        return "each is possible without the others; "
    return (
        "the others are possible without each of them but "
        + ", ".join(undecided)
        + ", without which the rest is beyond the planner's budget to decide (it may not be "
        "needed); "
    )


def _at(file: str | None, part: TaskPart) -> str:
    if part.line is None:
        return ""
    return f" ({file or '<input>'}:{part.line}:{part.col})"


def _can_start(automaton: Automaton, word: Sequence[Sequence[str]]) -> bool:
    """Whether ``automaton`` has a run over the finite ``word`` (the first instants)."""
    states = {automaton.initial}
    for letter in word:
        states = {e.dst for e in automaton.edges if e.src in states and holds(e.guard, set(letter))}
    return bool(states)


def _region_facts(
    abstraction: Abstraction,
    formula: Formula,
    where: dict[str, Any],
    cells: Sequence[int] | None = None,
    *,
    closed: bool = False,
) -> list[Diagnostic]:
    """Regions the blamed parts need that have no free space or cannot be reached (across
    edges or through mesh vertices, as vertex passages go; ``closed``: under the closed
    convention, not through a corner of a region the task forbids)."""
    allowed = invariant_mask(abstraction, formula)
    sources = [abstraction.start] if cells is None else list(cells)
    if not any(allowed[t] for t in sources):
        return []
    passable = passable_vertices(abstraction, invariants(formula), closed=closed)
    reachable_ok = reachable_triangles(abstraction, allowed, sources, passable)
    everywhere = np.ones(abstraction.num_triangles, dtype=bool)
    reachable_any = reachable_triangles(abstraction, everywhere, sources)
    facts: list[Diagnostic] = []
    for name in _positive_props(formula):
        with_region = np.array([name in letter for letter in abstraction.letters], dtype=bool)
        triangles = with_region[abstraction.letter_of]
        if not triangles.any():
            facts.append(_no_free_space(name, **where))
        elif not (triangles & reachable_ok).any():
            if (triangles & reachable_any).any():
                forbidden = ", ".join(f"`G {to_text(p)}`" for p in invariants(formula))
                facts.append(
                    error(
                        "P005",
                        f"region {name!r} can only be reached through "
                        f"regions the task forbids ({forbidden})",
                        hint="open a path that avoids the forbidden regions",
                        **where,
                    )
                )
            else:
                pieces = len(np.unique(abstraction.component))
                facts.append(
                    error(
                        "P005",
                        f"region {name!r} cannot be reached from the start: "
                        + (
                            f"it lies in another of the {pieces} separate pieces of free "
                            "space (holes separate it from the robot's piece, or it is a "
                            "separate workspace component)"
                            if pieces > 1
                            else "holes separate it from the robot"
                        ),
                        hint="open a passage through the holes or move the start",
                        **where,
                    )
                )
    return facts
