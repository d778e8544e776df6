"""Strongly connected components of a directed graph: the one implementation every stage uses.

The graph is given as CSR arrays, the successors of node ``u`` being
``indices[indptr[u]:indptr[u + 1]]``: numpy arrays (the planner's product, millions of nodes)
or plain lists (an automaton's few states; :func:`csr` builds them from successor lists).
Nothing here imports numpy, so ``tlmpc check`` does not load it.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Protocol


class IntVector(Protocol):
    """A sequence of node numbers: a list, or a numpy integer array (``tolist`` gives ints)."""

    def __len__(self) -> int: ...

    def tolist(self) -> list[int]: ...


def csr(successors: Sequence[Iterable[int]]) -> tuple[list[int], list[int]]:
    """The CSR arrays ``(indptr, indices)`` of successor lists (each node's order kept)."""
    indptr = [0]
    indices: list[int] = []
    for row in successors:
        indices.extend(row)
        indptr.append(len(indices))
    return indptr, indices


def strong_components(
    indptr: Sequence[int] | IntVector,
    indices: Sequence[int] | IntVector,
    roots: Iterable[int] | None = None,
) -> list[int]:
    """A component number per node (Tarjan's algorithm, iterative).

    The search starts from each of ``roots`` in turn (every node, in order, when None) and
    follows each node's successors in their CSR order; nodes no root reaches get -1.  The
    components are numbered in the order Tarjan's algorithm completes them, so a component's
    number is smaller than the numbers of the components that reach it (a reverse topological
    order).  Iterative, so long chains cannot exhaust the interpreter's stack.
    """
    starts = _as_list(indptr)
    targets = _as_list(indices)
    n = len(starts) - 1
    index = [-1] * n
    low = [0] * n
    on_stack = [False] * n
    label = [-1] * n
    stack: list[int] = []
    counter = 0
    components = 0
    for root in range(n) if roots is None else roots:
        if index[root] >= 0:
            continue
        # Each frame: a node and the position of its next edge to look at.
        frames = [(root, starts[root])]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack[root] = True
        while frames:
            node, edge = frames[-1]
            if edge < starts[node + 1]:
                frames[-1] = (node, edge + 1)
                nxt = targets[edge]
                if index[nxt] < 0:
                    index[nxt] = low[nxt] = counter
                    counter += 1
                    stack.append(nxt)
                    on_stack[nxt] = True
                    frames.append((nxt, starts[nxt]))
                elif on_stack[nxt] and index[nxt] < low[node]:
                    low[node] = index[nxt]
                continue
            frames.pop()
            if frames:
                parent = frames[-1][0]
                if low[node] < low[parent]:
                    low[parent] = low[node]
            if low[node] == index[node]:
                while True:
                    member = stack.pop()
                    on_stack[member] = False
                    label[member] = components
                    if member == node:
                        break
                components += 1
    return label


def _as_list(values: Sequence[int] | IntVector) -> list[int]:
    """Plain ints: indexing a Python list is several times faster than a numpy array."""
    if isinstance(values, list):
        return values
    if isinstance(values, Sequence):
        return list(values)
    return values.tolist()
