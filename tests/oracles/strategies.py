"""Hypothesis strategies for random LTL formulas and lasso words."""

from __future__ import annotations

import math
from typing import Any

from hypothesis import strategies as st

from tlmpc.ltl.ast import (
    FALSE,
    TRUE,
    And,
    BoundedEventually,
    BoundedGlobally,
    BoundedUntil,
    Equiv,
    Eventually,
    Formula,
    Globally,
    Implies,
    Interval,
    Not,
    Or,
    Prop,
    Release,
    StrongRelease,
    Until,
    WeakUntil,
)

PROPS = ("a", "b", "c", "d")


def formulas(props: tuple[str, ...] = PROPS, max_leaves: int = 12) -> st.SearchStrategy[Formula]:
    """Random formulas over ``props`` using every operator."""
    leaves = st.one_of(st.sampled_from([Prop(p) for p in props]), st.sampled_from([TRUE, FALSE]))

    def extend(inner: st.SearchStrategy[Formula]) -> st.SearchStrategy[Formula]:
        binary = st.sampled_from([Until, Release, WeakUntil, StrongRelease, Implies, Equiv])
        return st.one_of(
            st.builds(Not, inner),
            st.builds(Eventually, inner),
            st.builds(Globally, inner),
            st.builds(lambda a, b: And((a, b)), inner, inner),
            st.builds(lambda a, b, c: Or((a, b, c)), inner, inner, inner),
            st.builds(lambda op, a, b: op(a, b), binary, inner, inner),
        )

    return st.recursive(leaves, extend, max_leaves=max_leaves)


@st.composite
def lassos(
    draw: st.DrawFn, props: tuple[str, ...] = PROPS, letters: list[frozenset[str]] | None = None
) -> tuple[list[frozenset[str]], int]:
    """A lasso word (letters, loop start); letters drawn from ``letters`` when given."""
    if letters is None:
        letter = st.frozensets(st.sampled_from(props), max_size=len(props))
    else:
        letter = st.sampled_from(letters)
    word = draw(st.lists(letter, min_size=1, max_size=7))
    loop = draw(st.integers(0, len(word) - 1))
    return word, loop


#: Task templates for random missions; ``{a}``, ``{b}``, ``{c}`` are distinct regions.  They
#: cover the task language: reachability and sequences, safety only (``avoid``, a release),
#: recurrence (``patrol``, ``infinitely often``), persistence (``stay``), response
#: (``whenever``), until and release.  A template starting with ``ltl:`` is raw LTL.
TEMPLATES = (
    "visit {a}",
    "visit {a} then {b}",
    "visit {a}, {b} and {c}",
    "avoid {c}",
    "patrol {a}, {b}",
    "stay in {a}",
    "visit {a} then {b} while avoiding {c}",
    "whenever {a}, visit {b}",
    "avoid {c} until {a}",
    "visit {a} infinitely often",
    "visit {a} then return to {b}",
    "avoid {b} and {c}",
    "ltl: {a} R !{c}",
    "ltl: G F {a} & ({b} R !{c})",
)


#: The templates whose LTL is co-safe: every satisfying run has a finite good prefix.
CO_SAFE_TEMPLATES = frozenset(
    {
        "visit {a}",
        "visit {a} then {b}",
        "visit {a}, {b} and {c}",
        "avoid {c} until {a}",
        "visit {a} then return to {b}",
    }
)


@st.composite
def missions_with_template(
    draw: st.DrawFn, template: str | None = None
) -> tuple[dict[str, Any], str]:
    """A 12 x 8 box with up to one hole and three to five disjoint-or-overlapping regions, and
    the template its task came from (``template`` when given, else any of ``TEMPLATES``)."""
    regions: dict[str, Any] = {}
    count = draw(st.integers(3, 5))
    for k in range(count):
        x0 = draw(st.integers(0, 9))
        y0 = draw(st.integers(0, 5))
        w = draw(st.integers(1, 3))
        h = draw(st.integers(1, 3))
        regions[f"r{k}"] = {
            "rect": [x0 + 0.25, y0 + 0.25, min(x0 + w, 12) - 0.25, min(y0 + h, 8) - 0.25]
        }
    holes = []
    if draw(st.booleans()):
        holes.append({"rect": [5.5, 3.5, 6.5, 4.5]})
    names = sorted(regions)
    picks = draw(st.permutations(names))
    if template is None:
        template = draw(st.sampled_from(TEMPLATES))
    task = template.format(a=picks[0], b=picks[1], c=picks[2])
    document: dict[str, Any] = {
        "version": 1,
        "name": "random",
        "workspace": {"boundary": {"rect": [0, 0, 12, 8]}, "holes": holes},
        "regions": regions,
        "robot": {"start": [0.1, 7.9], "max_speed": 1.0},
    }
    if task.startswith("ltl: "):
        document["ltl"] = task.removeprefix("ltl: ")
    else:
        document["task"] = [task]
    return document, template


def missions() -> st.SearchStrategy[dict[str, Any]]:
    """Random mission documents (see :func:`missions_with_template`)."""
    return missions_with_template().map(lambda pair: pair[0])


lows = st.sampled_from([0.0, 0.25, 0.5, 1.0])
widths = st.sampled_from([0.0, 0.25, 0.5, 1.0, 2.0, math.inf])
intervals = st.builds(lambda low, width: Interval(low, low + width), lows, widths)


def bounded_formulas(
    props: tuple[str, ...] = ("a", "b"), max_leaves: int = 6
) -> st.SearchStrategy[Formula]:
    """Random formulas over ``props`` with time bounds (multiples of a quarter second) and
    the untimed operators."""
    leaves = st.one_of(st.sampled_from([Prop(p) for p in props]), st.sampled_from([TRUE, FALSE]))

    def extend(inner: st.SearchStrategy[Formula]) -> st.SearchStrategy[Formula]:
        return st.one_of(
            st.builds(BoundedEventually, inner, intervals),
            st.builds(BoundedGlobally, inner, intervals),
            st.builds(BoundedUntil, inner, inner, intervals),
            st.builds(Not, inner),
            st.builds(lambda a, b: And((a, b)), inner, inner),
            st.builds(lambda a, b: Or((a, b)), inner, inner),
            st.builds(Implies, inner, inner),
            st.builds(Eventually, inner),
            st.builds(Globally, inner),
            st.builds(Until, inner, inner),
            st.builds(Release, inner, inner),
        )

    return st.recursive(leaves, extend, max_leaves=max_leaves)
