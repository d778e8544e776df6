"""Boundary instants in planning: where the robot starts, and what a crossing reads.

Two facts the triangle graph alone does not carry:

* **The start may lie on an edge or a vertex.**  Every triangle whose closure contains the
  start point can be the first one of the plan (:func:`start_cells`).  The edges of that
  triangle that contain the start are *blocked* for its first move: leaving through them at
  t = 0 would never enter the triangle's interior (the plan would count a label the robot
  never has), and entering the interior and leaving by the same edge is a bounce.
* **Under the closed convention a crossing is an instant with its own label**: a point of the
  edge shared by triangles t and n lies in the closure of every region containing t or n, so
  the crossing reads ``labels(t) | labels(n)``.  The start point, too, reads every region
  whose closure contains it before the first triangle's interior.  Continuous time has no
  first instant after a point, so the task cannot be read on that word with discrete LTL
  as it stands: :func:`closed_task` rewrites it (with the marker :data:`POINT` true exactly at
  point instants) into a formula whose discrete meaning on the point/open word equals the
  verifier's continuous meaning under the closed convention.

``StartCell`` and ``start_cells`` live in :mod:`tlmpc.abstraction.starts` (re-exported here).
Under the right-continuous convention (the default) a point reads the label of the piece it
opens, so neither the crossings nor the start point add a letter.
"""

from __future__ import annotations

import numpy as np
import shapely

from tlmpc.abstraction.model import Abstraction
from tlmpc.abstraction.starts import StartCell, start_cells
from tlmpc.ltl.ast import (
    And,
    Const,
    Eventually,
    Formula,
    Globally,
    Not,
    Or,
    Prop,
    Release,
    StrongRelease,
    Until,
    WeakUntil,
    conjoin,
    disjoin,
)
from tlmpc.ltl.transform import nnf
from tlmpc.planning.contacts import vertex_point_letters
from tlmpc.planning.model import POINT

__all__ = ["POINT", "StartCell", "closed_task", "start_cells", "task_formula", "task_letters"]


def start_point_label(abstraction: Abstraction, point: tuple[float, float]) -> tuple[str, ...]:
    """Regions whose closure contains ``point``: the verifier's closed label of the start,
    by its rule (within 1e-12 of the largest of the point's and the regions' coordinates)."""
    if not abstraction.regions:
        return ()
    names = list(abstraction.regions)
    corners = [np.asarray(abstraction.regions[name], dtype=np.float64) for name in names]
    low = np.array([c.min(axis=0) for c in corners])
    high = np.array([c.max(axis=0) for c in corners])
    extent = float(np.maximum(np.abs(low), np.abs(high)).max())
    reach = 1e-12 * max(abs(float(point[0])), abs(float(point[1])), extent)
    # Only regions whose bounding box comes within reach can: a cheap filter before shapely
    # (twice the reach, which is far above the rounding of these sums).
    where = np.asarray(point, dtype=np.float64)
    slack = 2.0 * reach
    near = np.flatnonzero(((low - slack <= where) & (where <= high + slack)).all(axis=1))
    probe = shapely.Point(point)
    return tuple(
        sorted(
            names[k]
            for k in near.tolist()
            if shapely.dwithin(shapely.Polygon(corners[k]), probe, reach)
        )
    )


def crossing_letter(left: tuple[str, ...], right: tuple[str, ...]) -> tuple[str, ...]:
    """The closed convention's letter of an instant on the edge between two labels."""
    return tuple(sorted({*left, *right, POINT}))


def closed_letters(
    abstraction: Abstraction, start_point: tuple[float, float]
) -> tuple[tuple[str, ...], ...]:
    """Every letter the closed convention's word can hold on this mesh.

    The triangles' letters, the start point's, and the crossing letters of adjacent label
    pairs; also ``L + POINT`` for every triangle letter ``L``, the letter of an edge inside
    one labelled area (refinement for U-turns makes new such edges), and the letters of the
    mesh vertices where labels meet (read by vertex passages).
    """
    letters = dict.fromkeys(abstraction.letters)
    letters[tuple(sorted({*start_point_label(abstraction, start_point), POINT}))] = None
    for letter in abstraction.letters:
        letters[crossing_letter(letter, ())] = None
    m = abstraction.num_triangles
    if m:
        t = np.repeat(np.arange(m, dtype=np.int64), 3)
        n = abstraction.neighbors.reshape(-1)
        keep = n >= 0
        count = len(abstraction.letters)
        pairs = np.unique(abstraction.letter_of[t[keep]] * count + abstraction.letter_of[n[keep]])
        for key in pairs.tolist():
            letters[
                crossing_letter(abstraction.letters[key // count], abstraction.letters[key % count])
            ] = None
    for letter in vertex_point_letters(abstraction).values():
        letters.setdefault(letter, None)
    return tuple(letters)


def task_letters(
    abstraction: Abstraction, convention: str, start_point: tuple[float, float]
) -> tuple[tuple[str, ...], ...]:
    """The letters the task's automaton must be built over under ``convention``."""
    if convention == "closed":
        return closed_letters(abstraction, start_point)
    return abstraction.letters


def task_formula(formula: Formula, convention: str) -> Formula:
    """The formula the planner's automaton reads under ``convention``."""
    return closed_task(formula) if convention == "closed" else formula


def closed_task(formula: Formula) -> Formula:
    """``formula`` rewritten so that its discrete meaning on the word point, open, point, ...
    (``POINT`` true at points) is its continuous meaning under the closed convention.

    The verifier's rule: at a point followed by an open piece, ``a U b`` needs ``a`` on part
    of that open piece before ``b`` can hold inside it (an open piece has no first instant).
    So ``a U b`` becomes ``b | (a U (b & (a | POINT)))``: a witness of ``b`` inside an open
    piece needs ``a`` there too, a witness at a point does not.  The rest follows by duality
    (``a R b = !(!a U !b)``) and the definitions of F, G, W, M; see docs/semantics.md.
    """
    return _closed(nnf(formula))


def _closed(f: Formula) -> Formula:
    point = Prop(POINT)
    if isinstance(f, Const | Prop | Not):  # NNF: a negation holds a proposition
        return f
    if isinstance(f, And):
        return conjoin([_closed(a) for a in f.args])
    if isinstance(f, Or):
        return disjoin([_closed(a) for a in f.args])
    if isinstance(f, Eventually):
        return Eventually(_closed(f.arg))
    if isinstance(f, Globally):
        return Globally(_closed(f.arg))
    if isinstance(f, Until):
        a, b = _closed(f.left), _closed(f.right)
        return disjoin([b, Until(a, conjoin([b, disjoin([a, point])]))])
    if isinstance(f, Release):
        a, b = _closed(f.left), _closed(f.right)
        return conjoin([b, Release(a, disjoin([b, conjoin([a, Not(point)])]))])
    if isinstance(f, WeakUntil):
        return disjoin([_closed(Until(f.left, f.right)), Globally(_closed(f.left))])
    if isinstance(f, StrongRelease):
        return _closed(Until(f.right, conjoin([f.left, f.right])))
    raise TypeError(f"not an LTL node in negation normal form: {f!r}")
