"""Invariant pruning and "no plan" explanations in the user's terms."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import breadth_first_order

from tlmpc.abstraction.model import Abstraction
from tlmpc.automata.guards import holds
from tlmpc.automata.model import Automaton
from tlmpc.errors import Diagnostic, error
from tlmpc.ltl.ast import And, Formula, Globally, Not, Prop, is_propositional
from tlmpc.ltl.printer import to_text
from tlmpc.ltl.transform import nnf

BoolArray = npt.NDArray[np.bool_]


def invariants(formula: Formula) -> list[Formula]:
    """The top-level conjuncts ``G p`` with ``p`` propositional (as their ``p``)."""
    normal = nnf(formula)
    parts = normal.args if isinstance(normal, And) else (normal,)
    found: list[Formula] = []
    for part in parts:
        if isinstance(part, Globally) and is_propositional(part.arg):
            inner = part.arg
            found.extend(inner.args if isinstance(inner, And) else (inner,))
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


def _reachable(abstraction: Abstraction, allowed: BoolArray) -> BoolArray:
    m = abstraction.num_triangles
    rows = np.repeat(np.arange(m), 3)
    cols = abstraction.neighbors.reshape(-1)
    keep = (cols >= 0) & allowed[rows] & allowed[np.maximum(cols, 0)]
    graph = coo_matrix((np.ones(int(keep.sum())), (rows[keep], cols[keep])), shape=(m, m))
    seen = np.zeros(m, dtype=bool)
    if allowed[abstraction.start]:
        order = breadth_first_order(graph.tocsr(), abstraction.start, return_predecessors=False)
        seen[order] = True
    return seen


def _positive_props(formula: Formula) -> list[str]:
    negated = {
        n.arg.name for n in nnf(formula).walk() if isinstance(n, Not) and isinstance(n.arg, Prop)
    }
    positive = {n.name for n in nnf(formula).walk() if isinstance(n, Prop)}
    names = [n.name for n in formula.walk() if isinstance(n, Prop)]
    return [
        p
        for p in dict.fromkeys(names)
        if (p in positive and p not in negated) or (p in positive and p in negated)
    ]


def explain_no_plan(
    abstraction: Abstraction, automaton: Automaton, formula: Formula, allowed: BoolArray
) -> list[Diagnostic]:
    """Why no accepting lasso exists, most specific reason first."""
    from tlmpc.automata.translate import translate

    text = to_text(formula)
    if not translate(formula).edges:
        return [
            error(
                "P001",
                f"the task is unsatisfiable on its own: no trajectory on any map "
                f"can satisfy `{text}`",
                hint="look for contradicting parts, such as `visit a` with `avoid a`",
            )
        ]
    if not automaton.edges:
        return [
            error(
                "P006",
                "the task needs label combinations this map does not have "
                "(regions that would have to overlap)",
                hint="check which regions the task asks the robot to be in at the same time",
            )
        ]
    start_labels = abstraction.labels(abstraction.start)
    where = f"in {', '.join(start_labels)}" if start_labels else "in free space"
    if not allowed[abstraction.start]:
        broken = [p for p in invariants(formula) if not holds(p, set(start_labels))]
        return [
            error(
                "P002",
                f"the robot starts {where}, but the task requires "
                f"`G {to_text(broken[0]) if broken else '...'}` from the start",
                hint="move the start or relax the task",
            )
        ]
    if not any(
        e.src == automaton.initial and holds(e.guard, set(start_labels)) for e in automaton.edges
    ):
        return [
            error(
                "P003",
                f"the task already fails where the robot starts ({where})",
                hint=f"`{text}` constrains the first instant; move the start or the task",
            )
        ]
    reachable_ok = _reachable(abstraction, allowed)
    reachable_any = _reachable(abstraction, np.ones(abstraction.num_triangles, dtype=bool))
    problems = []
    for name in _positive_props(formula):
        with_region = np.array([name in letter for letter in abstraction.letters], dtype=bool)
        triangles = with_region[abstraction.letter_of]
        if not triangles.any():
            problems.append(
                error(
                    "P004",
                    f"region {name!r} has no free space: it lies in holes",
                    hint="move the region or the holes",
                )
            )
        elif not (triangles & reachable_ok).any():
            if (triangles & reachable_any).any():
                forbidden = ", ".join(f"`G {to_text(p)}`" for p in invariants(formula))
                problems.append(
                    error(
                        "P005",
                        f"region {name!r} can only be reached through "
                        f"regions the task forbids ({forbidden})",
                        hint="open a path that avoids the forbidden regions",
                    )
                )
            else:
                problems.append(
                    error(
                        "P005",
                        f"region {name!r} cannot be reached from the "
                        "start: holes separate it from the robot",
                        hint="open a passage through the holes or move the start",
                    )
                )
    if problems:
        return problems
    return [
        error(
            "P007",
            f"no trajectory on this map satisfies `{text}`: the parts of the "
            "task that must hold forever cannot be reached",
            hint="a patrol needs a loop of at least three triangles through its "
            "regions; check that the regions can be visited in the required order",
        )
    ]
