"""The faces of the abstraction: maximal sets of edge-connected triangles with one label.

A reactive mission's game is played on faces, not triangles.  Inside a face the label never
changes and the robot can reach every edge the face shares with a neighbouring face, so the
words the robot can produce are the same, up to repetition, on the triangle graph and on the
face graph (docs/semantics.md); Next-free LTL cannot tell repetitions apart.  A map of a
hundred thousand triangles has as many faces as its regions cut it into, so the game's size
depends on the task's regions, not on the mesh.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from tlmpc.abstraction.build import connected_components
from tlmpc.abstraction.model import Abstraction, IntArray


@dataclass(frozen=True, slots=True)
class Faces:
    """``face_of[t]`` is triangle t's face; faces are numbered by their lowest triangle.

    ``adjacent[f]`` lists the faces sharing an edge with face f (sorted); ``letters[f]`` is
    the face's label (the region names true in it).
    """

    face_of: IntArray = field(compare=False)
    adjacent: tuple[tuple[int, ...], ...]
    letters: tuple[tuple[str, ...], ...]

    @property
    def count(self) -> int:
        """How many faces there are."""
        return len(self.letters)

    def with_region(self, region: str) -> tuple[int, ...]:
        """The faces inside ``region``."""
        return tuple(f for f, letter in enumerate(self.letters) if region in letter)


def faces_of(abstraction: Abstraction) -> Faces:
    """The faces of ``abstraction`` and which of them touch along an edge."""
    neighbors = abstraction.neighbors
    letter_of = abstraction.letter_of
    count = abstraction.num_triangles
    across = np.where(neighbors >= 0, neighbors, 0)
    same = (neighbors >= 0) & (letter_of[across] == letter_of[:, None])
    face_of = connected_components(np.where(same, neighbors, -1))
    faces = int(face_of.max()) + 1 if count else 0
    first = np.full(faces, count, dtype=np.int64)
    np.minimum.at(first, face_of, np.arange(count, dtype=np.int64))
    letters = tuple(abstraction.letters[int(letter_of[t])] for t in first.tolist())
    rows = np.repeat(np.arange(count, dtype=np.int64), 3)
    other = neighbors.reshape(-1)
    crossing = (other >= 0) & ~same.reshape(-1)
    pairs = np.unique(np.stack((face_of[rows[crossing]], face_of[other[crossing]]), axis=1), axis=0)
    adjacent: list[list[int]] = [[] for _ in range(faces)]
    for a, b in pairs.tolist():
        adjacent[a].append(b)
    return Faces(
        face_of=face_of, adjacent=tuple(tuple(sorted(a)) for a in adjacent), letters=letters
    )


def start_faces(
    abstraction: Abstraction, face_of: IntArray, point: tuple[float, float], located: int
) -> list[int]:
    """The faces a robot at ``point`` may enter first: the face of the triangle ``located``
    holding it, then, by number, those of the other triangles whose closure holds the point
    (a start on the boundary of faces: under the right-continuous convention its label at
    t = 0 is the one of the face it moves into, docs/semantics.md, "Starts on a boundary")."""
    from tlmpc.abstraction.starts import start_cells

    first = int(face_of[located])
    others = {int(face_of[cell.triangle]) for cell in start_cells(abstraction, point)}
    return [first, *sorted(others - {first})]
