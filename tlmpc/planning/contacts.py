"""Contact vertices: mesh vertices where labels meet, or where free space touches itself.

A vertex passage runs through such a vertex, and in the closed convention the word holds its
letter for an instant (every region whose closure holds the vertex, with :data:`POINT`).
"""

from __future__ import annotations

import numpy as np

from tlmpc.abstraction.model import Abstraction, IntArray
from tlmpc.planning.model import POINT

Letter = tuple[str, ...]


def contact_vertices(abstraction: Abstraction) -> IntArray:
    """Mesh vertices where the triangles around carry at least two different labels, and
    *pinches*: vertices of the mesh's outline whose triangles form two or more fans that
    share no edge (free space touching itself at a point between obstacles)."""
    count = abstraction.vertices.shape[0]
    corner_vertex = abstraction.triangles.reshape(-1)
    corner_letter = np.repeat(abstraction.letter_of, 3)
    low = np.full(count, np.iinfo(np.int64).max, dtype=np.int64)
    high = np.full(count, -1, dtype=np.int64)
    np.minimum.at(low, corner_vertex, corner_letter)
    np.maximum.at(high, corner_vertex, corner_letter)
    found = set(np.flatnonzero((high >= 0) & (low != high)).tolist())
    # Pinches lie on the outline: an endpoint of an edge without a neighbour.
    t, i = np.nonzero(abstraction.neighbors < 0)
    outline = np.unique(
        np.concatenate(
            [abstraction.triangles[t, (i + 1) % 3], abstraction.triangles[t, (i + 2) % 3]]
        )
    )
    candidates = np.setdiff1d(outline, np.fromiter(found, dtype=np.int64, count=len(found)))
    if len(candidates):
        holder = np.isin(abstraction.triangles, candidates)
        around: dict[int, list[int]] = {}
        for tri, local in zip(*np.nonzero(holder), strict=True):
            around.setdefault(int(abstraction.triangles[tri, local]), []).append(int(tri))
        for v, triangles in around.items():
            if _fans(abstraction, triangles) > 1:
                found.add(v)
    return np.asarray(sorted(found), dtype=np.int64)


def _fans(abstraction: Abstraction, triangles: list[int]) -> int:
    """How many edge-connected groups ``triangles`` (all around one vertex) form."""
    members = set(triangles)
    seen: set[int] = set()
    groups = 0
    for first in triangles:
        if first in seen:
            continue
        groups += 1
        stack = [first]
        seen.add(first)
        while stack:
            current = stack.pop()
            for n in abstraction.neighbors[current].tolist():
                if n in members and n not in seen:
                    seen.add(n)
                    stack.append(n)
    return groups


def vertex_point_letters(abstraction: Abstraction) -> dict[int, Letter]:
    """The closed convention's letter at each contact vertex: every region of a triangle
    around it (regions are unions of triangles, so these are exactly the regions whose
    closure holds the vertex), with :data:`POINT`."""
    contacts = contact_vertices(abstraction)
    holder = np.isin(abstraction.triangles, contacts)
    t, k = np.nonzero(holder)
    count = len(abstraction.letters)
    pairs = np.unique(abstraction.triangles[t, k] * count + abstraction.letter_of[t])
    owners, letter_ids = (pairs // count).tolist(), (pairs % count).tolist()
    combos: dict[tuple[int, ...], Letter] = {}
    found: dict[int, Letter] = {}
    start = 0
    for index in range(1, len(owners) + 1):
        if index < len(owners) and owners[index] == owners[start]:
            continue
        combo = tuple(letter_ids[start:index])
        if combo not in combos:
            names = {n for i in combo for n in abstraction.letters[i]}
            combos[combo] = tuple(sorted({*names, POINT}))
        found[owners[start]] = combos[combo]
        start = index
    return found
