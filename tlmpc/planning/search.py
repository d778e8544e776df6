"""Shortest paths on the product graph, with numpy alone (no graph library to import).

The graph is a CSR arrangement of its edges (:class:`Graph`).  :func:`shortest_paths` is a
label-correcting search processed in distance buckets (delta-stepping): each round relaxes,
all at once, every edge out of the queued nodes whose tentative distance lies in the lowest
bucket.  The distances it returns are those of Dijkstra's algorithm bit for bit: both are the
unique solution of ``d(v) = min over edges u -> v of fl(d(u) + w)`` with ``d = 0`` at the
sources, since floating-point addition is monotone and every weight is positive and large
enough not to vanish in the sum (the smallest, 1e-9, would only at distances beyond 1e7):
a second solution would differ first at some node, whose minimising edge comes from a node
where both agree.  :func:`closing_searches` runs several such searches at once.

**Tie-break.**  Among the edges ``u -> v`` that attain ``d(v)``, the predecessor of ``v`` is
the one with the smallest ``d(u)``, then the smallest node index ``u``.  A Dijkstra search
that keeps the first predecessor attaining the minimum (as scipy's does) agrees with this
wherever those smallest ``d(u)`` are unique; it orders equal ``d(u)`` by its heap instead.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from tlmpc.base.content import ContentEquality

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]
BoolArray = npt.NDArray[np.bool_]

#: Larger than any node index: a predecessor not chosen yet (searches return -1 instead).
NO_NODE = np.iinfo(np.int64).max
#: Bucket width as a multiple of the mean edge weight: wide enough to relax many nodes per
#: round, narrow enough that few are relaxed again.
BUCKET_WIDTH = 1.0


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class Graph(ContentEquality):
    """A weighted directed graph with its edges grouped by source (CSR).

    ``indptr[u]:indptr[u + 1]`` are the edges out of ``u``; ``targets`` and ``weights`` give
    each edge's head and weight (all weights positive), :attr:`sources` its tail (made when
    asked: a large product does not hold one more number per edge).
    """

    indptr: IntArray
    targets: IntArray
    weights: FloatArray
    num_nodes: int

    @property
    def nnz(self) -> int:
        """Number of edges."""
        return len(self.targets)

    @property
    def sources(self) -> IntArray:
        """Each edge's tail (an array as long as the edges, made anew at each call)."""
        counts = np.diff(self.indptr)
        tails: IntArray = np.repeat(np.arange(self.num_nodes, dtype=self.targets.dtype), counts)
        return tails

    def source_of(self, edges: IntArray) -> IntArray:
        """The tails of ``edges`` (edge numbers), looked up in ``indptr``."""
        tails: IntArray = np.searchsorted(self.indptr, edges, side="right") - 1
        return tails

    @staticmethod
    def from_edges(
        sources: IntArray, targets: IntArray, weights: FloatArray, num_nodes: int
    ) -> tuple[Graph, IntArray]:
        """The graph of these edges, and the order that took the input edges to it (edge k
        of the graph is input edge ``order[k]``; edges of one source keep their input order)."""
        order = np.argsort(sources, kind="stable")
        indptr = np.zeros(num_nodes + 1, dtype=np.int64)
        np.cumsum(np.bincount(sources, minlength=num_nodes), out=indptr[1:])
        graph = Graph(
            indptr=indptr,
            targets=targets[order],
            weights=weights[order],
            num_nodes=num_nodes,
        )
        return graph, order

    def weight(self, source: int, target: int) -> float:
        """The weight of the edge ``source -> target`` (KeyError when there is none)."""
        lo, hi = int(self.indptr[source]), int(self.indptr[source + 1])
        hits = np.flatnonzero(self.targets[lo:hi] == target)
        if not len(hits):
            raise KeyError((source, target))
        return float(self.weights[lo + int(hits[0])])

    def path_weights(self, nodes: Sequence[int]) -> list[float]:
        """The weights of the edges ``nodes[k] -> nodes[k + 1]`` along a path, each as
        :meth:`weight` gives it (KeyError when one is missing), looked up all at once."""
        path = np.asarray(nodes, dtype=np.int64)
        tails, heads = path[:-1], path[1:]
        edges = _out_edges(self, tails)
        counts = self.indptr[tails + 1] - self.indptr[tails]
        found = edges[self.targets[edges] == np.repeat(heads, counts)]
        if len(found) != len(tails):  # a missing edge, or parallel ones: one at a time
            return [self.weight(int(a), int(b)) for a, b in zip(tails, heads, strict=True)]
        weights: list[float] = self.weights[found].tolist()
        return weights


def _out_edges(graph: Graph, nodes: IntArray) -> IntArray:
    """Indices of every edge out of ``nodes``."""
    starts = graph.indptr[nodes]
    counts = graph.indptr[nodes + 1] - starts
    total = int(counts.sum())
    if total == 0:
        return np.zeros(0, dtype=np.int64)
    # Edge k of the run of node j is starts[j] + k: one arange shifted per run.
    shift = np.repeat(starts - (np.cumsum(counts) - counts), counts)
    return shift + np.arange(total, dtype=np.int64)


def relax_offers(
    dist: FloatArray,
    via: FloatArray,
    pred: IntArray,
    v: IntArray,
    d: FloatArray,
    du: FloatArray,
    u: IntArray,
) -> IntArray:
    """Take the offers ``u -> v`` (distance ``d`` through ``u``, itself at ``du``): each node
    keeps the smallest (distance, d(predecessor), predecessor) among what it had and its
    offers, by three scatter-minimums, one key after the other.  Returns the nodes whose
    distance got shorter, each once (they must be searched from again).  The pairs
    ``(u, v)`` must be distinct."""
    old = dist[v]
    np.minimum.at(dist, v, d)
    best = dist[v]
    win = d == best  # offers that attain the node's (new) distance
    shorter = best < old
    if np.count_nonzero(win) < len(win):
        v, du, u, shorter = v[win], du[win], u[win], shorter[win]
    # A shorter distance voids the former predecessor's rank.
    via[v[shorter]] = np.inf
    former = via[v]
    np.minimum.at(via, v, du)
    nearest = via[v]
    # A nearer predecessor replaces the former one; among equally near ones, the smallest.
    pred[v[nearest < former]] = NO_NODE
    tie = du == nearest
    np.minimum.at(pred, v[tie], u[tie])
    # The one offer per node that won: its predecessor is the node's (pairs are distinct).
    won = shorter & tie
    won[won] = u[won] == pred[v[won]]
    improved: IntArray = v[won]
    return improved


def _enqueue(frontier: IntArray, improved: IntArray, queued: BoolArray) -> IntArray:
    """The frontier with the improved nodes not already in it."""
    fresh = improved[~queued[improved]]
    queued[fresh] = True
    return np.concatenate([frontier, fresh])


def _each_once(nodes: IntArray, stamp: IntArray) -> IntArray:
    """``nodes`` with each node once, in the order of the positions kept (numpy's unique
    costs more than the rest of a round): of a node listed twice, only the position whose
    write to ``stamp`` (scratch, one entry per node) stayed."""
    count = np.arange(len(nodes))
    stamp[nodes] = count
    once: IntArray = nodes[stamp[nodes] == count]
    return once


def shortest_paths(
    graph: Graph,
    sources: IntArray,
    *,
    limit: float = np.inf,
    goals: BoolArray | None = None,
) -> tuple[FloatArray, IntArray]:
    """Distances from the nearest of ``sources`` and predecessors (-1 at sources and at
    unreached nodes), over paths of length at most ``limit`` (farther nodes stay at inf).

    With ``goals``, the search ends once the nearest goal node is known: every node up to
    that goal's distance is exact (ties included), every farther one is left at inf.
    See the module doc for the tie-break among equal predecessors.
    """
    dist, pred = _search(graph, sources, limit, goals, predecessors=True)
    assert pred is not None
    return dist, pred


def distances(graph: Graph, sources: IntArray) -> FloatArray:
    """The distances :func:`shortest_paths` gives (bit for bit: they are the unique solution
    the module doc names, whatever the order of the relaxations), without predecessors.

    The same search without the tie-break's two keys: a round takes one scatter-minimum
    instead of three and carries no tails, about a third less time for a search whose paths are
    not read (the guided search's bounds are distances to whole regions, over every cell)."""
    dist, _ = _search(graph, sources, np.inf, None, predecessors=False)
    return dist


def relax_distances(dist: FloatArray, v: IntArray, d: FloatArray) -> IntArray:
    """Take the offers ``d`` to ``v`` (distances only, one scatter-minimum): returns the
    nodes whose distance got shorter, twice where two offers tie at the new distance."""
    old = dist[v]
    np.minimum.at(dist, v, d)
    improved: IntArray = v[(d < old) & (d == dist[v])]
    return improved


def _search(
    graph: Graph,
    sources: IntArray,
    limit: float,
    goals: BoolArray | None,
    *,
    predecessors: bool,
) -> tuple[FloatArray, IntArray | None]:
    """:func:`shortest_paths`, or with ``predecessors`` false :func:`distances` (pred None)."""
    n = graph.num_nodes
    dist = np.full(n, np.inf)
    pred = np.full(n, -1, dtype=np.int64) if predecessors else None
    via = np.full(n, np.inf) if predecessors else None  # d(pred[v]): the tie-break's first key
    queued = np.zeros(n, dtype=bool)
    frontier = np.unique(np.asarray(sources, dtype=np.int64))
    dist[frontier] = 0.0
    queued[frontier] = True
    nearest_goal = np.inf
    if goals is not None and len(frontier) and goals[frontier].any():
        nearest_goal = 0.0
    width = BUCKET_WIDTH * float(graph.weights.mean()) if graph.nnz else 1.0
    indptr, targets, weights = graph.indptr, graph.targets, graph.weights
    stamp = np.empty(n if pred is None else 0, dtype=np.int64)  # without predecessors
    while len(frontier):
        current = dist[frontier]
        lowest = float(current.min())
        if lowest > nearest_goal:
            break  # every node at most nearest_goal away is final
        take = current <= lowest + width
        active, frontier = frontier[take], frontier[~take]
        queued[active] = False
        starts = indptr[active]
        counts = indptr[active + 1] - starts
        ends = np.cumsum(counts)
        total = int(ends[-1])
        if not total:
            continue
        # As in _out_edges; each edge's tail and its distance, repeated along its run, are
        # read from the active nodes rather than gathered per edge.
        edges = np.repeat(starts - ends + counts, counts) + np.arange(total)
        du = np.repeat(current[take], counts)
        v = targets[edges].astype(np.int64, copy=False)  # indexes many arrays: cast once
        d = du + weights[edges]
        if pred is None or via is None:
            frontier = _enqueue(frontier, _each_once(relax_distances(dist, v, d), stamp), queued)
            continue
        u = np.repeat(active, counts)
        if limit < np.inf:
            keep = d <= limit
            u, v, du, d = u[keep], v[keep], du[keep], d[keep]
        improved = relax_offers(dist, via, pred, v, d, du, u)
        if goals is not None and len(improved):
            hit = goals[improved]
            if hit.any():
                nearest_goal = min(nearest_goal, float(dist[improved[hit]].min()))
        frontier = _enqueue(frontier, improved, queued)
    if len(frontier) and pred is not None:
        # Stopped at the nearest goal: what lies beyond is not final.
        beyond = dist > nearest_goal
        dist[beyond] = np.inf
        pred[beyond] = -1
    return dist, pred


def closing_searches(
    graph: Graph, starts: IntArray, targets: IntArray, limits: FloatArray
) -> tuple[FloatArray, list[list[int]]]:
    """Several searches at once: from ``starts[k]`` to ``targets[k]`` within ``limits[k]``.

    Returns each target's distance (inf when farther than its limit) and the path to it
    (empty when unreached), exactly what :func:`shortest_paths` from ``starts[k]`` with the
    goal ``targets[k]`` and that limit gives: the searches share the rounds (a round costs
    about the same for one search as for ten), each in its own copy of the node numbers.
    """
    n = graph.num_nodes
    count = len(starts)
    total = n * count
    dist = np.full(total, np.inf)
    pred = np.full(total, -1, dtype=np.int64)
    via = np.full(total, np.inf)
    queued = np.zeros(total, dtype=bool)
    base = np.arange(count, dtype=np.int64) * n
    goal = base + np.asarray(targets, dtype=np.int64)
    limit = np.asarray(limits, dtype=np.float64)
    nearest = np.full(count, np.inf)  # per search: the distance of its target, once known
    frontier = base + np.asarray(starts, dtype=np.int64)
    dist[frontier] = 0.0
    queued[frontier] = True
    nearest[goal == frontier] = 0.0
    is_goal = np.zeros(total, dtype=bool)
    is_goal[goal] = True
    width = BUCKET_WIDTH * float(graph.weights.mean()) if graph.nnz else 1.0
    while len(frontier):
        current = dist[frontier]
        # A search whose target is known needs nothing beyond it.
        alive = current <= nearest[frontier // n]
        if not alive.all():
            queued[frontier[~alive]] = False
            frontier, current = frontier[alive], current[alive]
            if not len(frontier):
                break
        take = current <= float(current.min()) + width
        active, frontier = frontier[take], frontier[~take]
        queued[active] = False
        local = active % n
        starts = graph.indptr[local]
        counts = graph.indptr[local + 1] - starts
        ends = np.cumsum(counts)
        total = int(ends[-1])
        if not total:
            continue
        # As in shortest_paths, in each search's own copy of the node numbers.
        edges = np.repeat(starts - ends + counts, counts) + np.arange(total)
        u = np.repeat(active, counts)
        v = graph.targets[edges] + np.repeat(active - local, counts)
        du = np.repeat(current[take], counts)
        d = du + graph.weights[edges]
        keep = d <= limit[v // n]
        if not keep.all():
            u, v, du, d = u[keep], v[keep], du[keep], d[keep]
        improved = relax_offers(dist, via, pred, v, d, du, u)
        reached = improved[is_goal[improved]]
        if len(reached):
            searches = reached // n
            nearest[searches] = np.minimum(nearest[searches], dist[reached])
        frontier = _enqueue(frontier, improved, queued)
    distances = dist[goal]
    paths: list[list[int]] = []
    for k in range(count):
        if not np.isfinite(distances[k]):
            paths.append([])
            continue
        path = [int(goal[k])]
        while pred[path[-1]] >= 0:
            path.append(int(pred[path[-1]]))
        path.reverse()
        paths.append([node - int(base[k]) for node in path])
    return distances, paths
