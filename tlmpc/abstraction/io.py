"""``abstraction.json`` (``tlmpc.abstraction/1``): writing and reading back."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from tlmpc.abstraction.model import Abstraction
from tlmpc.io.arrays import ArrayList, TableList, plain
from tlmpc.mission.model import regions_document

FORMAT = "tlmpc.abstraction/1"


def abstraction_to_json(abstraction: Abstraction) -> dict[str, Any]:
    """The artifact document (labels per triangle as lists of region names), plain lists."""
    document: dict[str, Any] = plain(abstraction_document(abstraction))
    return document


def abstraction_document(abstraction: Abstraction) -> dict[str, Any]:
    """The artifact document as the pipeline keeps it until it is written: the per-vertex
    and per-triangle lists are stand-ins holding the arrays (:mod:`tlmpc.io.arrays`), which
    the writer encodes into the same text as :func:`abstraction_to_json`'s lists."""
    letters = [list(letter) for letter in abstraction.letters]
    return {
        "format": FORMAT,
        "vertices": ArrayList(abstraction.vertices),
        "triangles": ArrayList(abstraction.triangles),
        "neighbors": ArrayList(abstraction.neighbors),
        "labels": TableList(letters, abstraction.letter_of),
        "letters": letters,
        "letter_of": ArrayList(abstraction.letter_of),
        "start": abstraction.start,
        "components": ArrayList(abstraction.component),
        "regions": regions_document(list(abstraction.regions.items())),
        "stats": dict(abstraction.stats),
    }


def abstraction_from_json(document: Mapping[str, Any]) -> Abstraction:
    """Rebuild the :class:`Abstraction` written by :func:`abstraction_to_json`."""
    arrays: dict[str, Any] = {
        "vertices": np.asarray(document["vertices"], dtype=np.float64).reshape(-1, 2),
        "triangles": np.asarray(document["triangles"], dtype=np.int64).reshape(-1, 3),
        "neighbors": np.asarray(document["neighbors"], dtype=np.int64).reshape(-1, 3),
        "letter_of": np.asarray(document["letter_of"], dtype=np.int64),
        "component": np.asarray(document["components"], dtype=np.int64),
    }
    for array in arrays.values():
        array.setflags(write=False)
    return Abstraction(
        vertices=arrays["vertices"],
        triangles=arrays["triangles"],
        neighbors=arrays["neighbors"],
        letter_of=arrays["letter_of"],
        letters=tuple(tuple(letter) for letter in document["letters"]),
        start=int(document["start"]),
        component=arrays["component"],
        regions={
            name: tuple((float(x), float(y)) for x, y in poly)
            for name, poly in document["regions"].items()
        },
        stats=dict(document.get("stats", {})),
    )
