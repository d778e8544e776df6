"""The minimum-cost lasso on a product expanded on demand, guided by lower bounds.

The same lasso as :func:`tlmpc.planning.plan.plan` finds on the built product, with the same
cost (``prefix + beta * cycle``) and the same promise (docs/planning.md): the least of

* ``d0(s)`` over the accepting stays ``s``, and
* ``d0(u) + beta * (w(u, v) + d(v, u))`` over the accepting edges ``u -> v``,

but without building the product.  The searches are label-correcting searches in buckets of
``f = g + h`` (A* with an admissible bound ``h``, :mod:`tlmpc.planning.bounds`), on the edges
:meth:`~tlmpc.planning.lazy.LazyProduct.expand` gives:

1. the *prefix search* from the initial nodes, guided by a bound on the whole lasso still to
   pay (to a stay, or to an accepting edge plus ``beta`` times the cheapest way back);
2. each accepting edge ``u -> v`` it expands becomes a *candidate* with the lower bound
   ``g(u) + beta * (w + b(v, u))``; candidates are closed (a search from ``v`` back to ``u``
   guided by a bound on reaching ``u``) in increasing order of their bound, interleaved with
   the prefix search so that the one with the smallest bound or ``f`` goes first;
3. everything stops when no bound nor ``f`` is below the best lasso found.

A node whose ``f`` reaches the incumbent is never expanded: every lasso through it costs at
least that much.  Closing searches are capped as on the built product (``stats.optimal``).
"""

from __future__ import annotations

import heapq
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from tlmpc.abstraction.model import FloatArray, IntArray
from tlmpc.base.pages import plain_pages
from tlmpc.planning.bounds import (
    CostToGo,
    RegionGraph,
    StackedCostToGo,
    cost_to_go,
    cost_to_go_to_cells,
    region_graph,
)
from tlmpc.planning.lazy import Edges, LazyProduct
from tlmpc.planning.product import BoolArray
from tlmpc.planning.search import BUCKET_WIDTH, relax_offers

Bound = Callable[[IntArray], FloatArray]

#: Closing searches run side by side up to this many product nodes in all (their arrays,
#: about 30 bytes a node, are written only where a search meets a node: the pages of the
#: others are never written, so a copy costs about what its search reaches).
CLOSING_NODES = 40_000_000
#: A candidate due to be closed waits until the prefix search's ``f`` has passed its bound by
#: this fraction (or the incumbent, or a group is full): the candidates of one anchor region
#: have bounds that close together, and searches side by side cost the rounds of one.
LOOKAHEAD = 1e-3


@dataclass(slots=True)
class _Arrays:
    """A search's per-node arrays, valid where ``seen`` holds: a node's entries are written
    when the search first meets it (:meth:`meet`), so that one set serves many searches and
    the pages of nodes never met are never written (nor, on most systems, even mapped)."""

    seen: BoolArray
    dist: FloatArray
    pred: IntArray
    via: FloatArray
    queued: BoolArray
    estimate: npt.NDArray[np.float32]  # the bound at each node met
    touched: list[IntArray] = field(default_factory=list)

    @staticmethod
    def of(size: int) -> _Arrays:
        """Arrays for ``size`` nodes, none met yet (only ``seen`` is written, with zeros: on
        plain pages, see :mod:`tlmpc.base.pages`; the others are written per node met)."""
        with plain_pages():
            return _Arrays(
                seen=np.zeros(size, dtype=bool),
                dist=np.empty(size),
                pred=np.empty(size, dtype=np.int64),
                via=np.empty(size),
                queued=np.zeros(size, dtype=bool),
                estimate=np.empty(size, dtype=np.float32),
            )

    def meet(self, nodes: IntArray) -> BoolArray:
        """Mark ``nodes`` met, unreached and unqueued where they were not met before; returns
        which of ``nodes`` were not (their bound is still to be written).  ``pred`` and
        ``via`` are left as they are: the first offer to an unreached node writes both before
        reading them (:func:`~tlmpc.planning.search.relax_offers`), and a source's are
        written by the search that starts there."""
        fresh = ~self.seen[nodes]
        new = nodes[fresh]
        if len(new):
            self.seen[new] = True
            self.dist[new] = np.inf
            self.queued[new] = False
            self.touched.append(new)
        return fresh

    def distance(self, nodes: IntArray) -> FloatArray:
        """The tentative distance of each of ``nodes`` (inf for a node never met)."""
        found: FloatArray = np.where(self.seen[nodes], self.dist[nodes], np.inf)
        return found

    def reset(self) -> None:
        """Back to no node met (only the touched nodes are written)."""
        for nodes in self.touched:
            self.seen[nodes] = False
        self.touched = []


def _runs(labels: IntArray) -> list[tuple[int, IntArray]]:
    """(label, the positions holding it, in their order) per distinct label, ascending: a
    stable sort and its runs (cheaper than numpy's unique and one pass per label, on the few
    hundred items of a round)."""
    if not len(labels):
        return []
    order = np.argsort(labels, kind="stable")
    ordered = labels[order]
    cuts = (np.flatnonzero(ordered[1:] != ordered[:-1]) + 1).tolist()
    starts, ends = [0, *cuts], [*cuts, len(order)]
    firsts = ordered[starts].tolist()
    return [(first, order[a:b]) for first, a, b in zip(firsts, starts, ends, strict=True)]


def _sorted_distinct(values: IntArray) -> IntArray:
    """``np.unique(values)``: a sort and its first of each run (numpy's unique hashes first,
    several times slower on the few hundred nodes of a bucket)."""
    ordered = np.sort(values)
    first = np.empty(len(ordered), dtype=bool)
    first[:1] = True
    np.not_equal(ordered[1:], ordered[:-1], out=first[1:])
    distinct: IntArray = ordered[first]
    return distinct


class _Buckets:
    """One search's queued nodes by bucket key (``f`` in ``[k w, (k + 1) w)``), maybe stale:
    a node no longer queued, or queued again in another bucket, is skipped when read."""

    __slots__ = ("floor", "keys", "parts")

    def __init__(self) -> None:
        self.parts: dict[int, list[IntArray]] = {}  # key -> queued nodes
        self.keys: list[int] = []  # a heap of the keys
        self.floor = 0  # the key of the bucket expanded last

    def add(self, nodes: IntArray, keys: IntArray) -> None:
        """Put ``nodes`` in the buckets ``keys`` (raised to the floor: never below the bucket
        being expanded)."""
        keys = np.maximum(keys, self.floor)
        low, high = int(keys.min()), int(keys.max())
        if low == high:
            self.put(low, nodes)
            return
        for key, at in _runs(keys):
            self.put(key, nodes[at])

    def put(self, key: int, nodes: IntArray) -> None:
        """Put ``nodes`` in the bucket ``key`` (at least the floor)."""
        if key in self.parts:
            self.parts[key].append(nodes)
        else:
            self.parts[key] = [nodes]
            heapq.heappush(self.keys, key)

    def lowest(self, queued: BoolArray) -> IntArray | None:
        """The queued nodes of the lowest bucket that has any (None: nothing queued)."""
        while self.keys:
            key = self.keys[0]
            parts = self.parts[key]
            nodes = parts[0] if len(parts) == 1 else _sorted_distinct(np.concatenate(parts))
            nodes = nodes[queued[nodes]]
            if len(nodes):
                self.parts[key] = [nodes]
                return nodes
            del self.parts[key]
            heapq.heappop(self.keys)
        return None

    def pop(self) -> None:
        """Drop the lowest bucket (:meth:`lowest` found it) and make it the floor."""
        self.floor = heapq.heappop(self.keys)
        del self.parts[self.floor]


class GuidedSearch:
    """A label-correcting search on a lazy product in buckets of ``f = g + bound``.

    :meth:`step` expands the nodes of the lowest bucket (every edge out of them) and
    returns those edges; offers whose ``g + bound`` reaches ``ceiling`` are dropped (no path
    through them can beat it).  Distances are exact for every node whose ``f`` lies below
    :meth:`lowest` once the search has stepped past it.

    The queued nodes are kept per bucket (``f`` in ``[k w, (k + 1) w)`` for the bucket
    width ``w``), so a round reads only the nodes it expands, not every node waiting: a
    guided search's frontier holds hundreds of times more nodes than one bucket.  A node
    whose distance got shorter is queued again in its new bucket (never below the bucket
    being expanded); the entry it had is skipped when its bucket comes (the node is no
    longer queued, or was queued again and is expanded at most once more).

    Searches side by side (``copy_size``, with ``copies`` of the node numbers) keep a
    bucket queue each, and a round expands every copy's lowest bucket: each copy goes in the
    order of its own ``f`` (its ``f`` values may lie far from the others'), and the copies
    share the rounds all the same.
    """

    def __init__(
        self,
        product: LazyProduct,
        arrays: _Arrays,
        sources: IntArray,
        bound: Bound,
        offsets: FloatArray | None = None,
        copy_size: int = 0,
        copies: int = 1,
    ) -> None:
        self.product = product
        self.arrays = arrays
        self.bound = bound
        self.copy_size = copy_size  # nonzero: node n is node n % copy_size of copy n // it
        if offsets is None:
            sources = np.unique(np.asarray(sources, dtype=np.int64))
            offsets = np.zeros(len(sources))
        estimate = self.estimate_at(sources)
        finite = np.isfinite(estimate)
        sources, offsets = sources[finite], offsets[finite]
        arrays.dist[sources] = offsets
        arrays.pred[sources] = -1
        arrays.via[sources] = np.inf
        arrays.queued[sources] = True
        self.sources = sources
        weights = product.move_weight
        self.width = BUCKET_WIDTH * float(weights.mean()) if len(weights) else 1.0
        self.reached = len(sources)
        self.rounds = 0  # steps taken (a round expands one bucket of every copy)
        self.queues = [_Buckets() for _ in range(copies if copy_size else 1)]
        self._queue(sources, offsets + estimate[finite])

    def estimate_at(self, nodes: IntArray) -> FloatArray:
        """The bound at ``nodes``, computed once per node (kept in single precision,
        rounded down so that it stays a lower bound)."""
        unknown = self.arrays.meet(nodes)
        fresh = nodes[unknown]
        if len(fresh):
            exact = self.bound(fresh) * (1.0 - 1e-6)
            self.arrays.estimate[fresh] = exact.astype(np.float32)
        return self.arrays.estimate[nodes].astype(np.float64)

    def _queue(self, nodes: IntArray, f: FloatArray) -> None:
        """Put ``nodes`` (distinct, finite ``f``) in their buckets."""
        if not len(nodes):
            return
        keys = (f / self.width).astype(np.int64)
        if len(self.queues) == 1:
            self.queues[0].add(nodes, keys)
            return
        copy = nodes // self.copy_size
        low, high = int(copy.min()), int(copy.max())
        if low == high:
            self.queues[low].add(nodes, keys)
            return
        # Grouped by copy and key at once: one sort of (key, copy) labels for the round, not
        # one per copy (each copy's keys raised to its own floor first).
        copies = len(self.queues)
        floors = np.array([queue.floor for queue in self.queues], dtype=np.int64)
        labels = np.maximum(keys, floors[copy]) * copies + copy
        for label, at in _runs(labels):
            key, k = divmod(label, copies)
            self.queues[k].put(key, nodes[at])

    def _f(self, nodes: IntArray) -> FloatArray:
        f: FloatArray = self.arrays.dist[nodes] + self.arrays.estimate[nodes]
        return f

    def lowest(self) -> float:
        """The least ``f`` of a queued node in the lowest buckets (inf when none is queued;
        searches side by side: the least over the copies)."""
        least = np.inf
        for queue in self.queues:
            nodes = queue.lowest(self.arrays.queued)
            if nodes is not None:
                least = min(least, float(self._f(nodes).min()))
        return least

    def exhausted(self, ceilings: FloatArray) -> bool:
        """Whether no copy has a node in its lowest bucket whose ``f`` is below the copy's
        ceiling (then none has any: the copy's other buckets lie higher)."""
        for k, queue in enumerate(self.queues):
            nodes = queue.lowest(self.arrays.queued)
            if nodes is not None and float(self._f(nodes).min()) < ceilings[k]:
                return False
        return True

    def step(
        self, ceiling: float | FloatArray = np.inf, *, marks: bool = True
    ) -> tuple[Edges, IntArray]:
        """Expand the lowest bucket (of every copy); returns its edges and the nodes whose
        distance got shorter (queued again).  ``ceiling`` may be one per copy: then the
        bucket's nodes whose ``f`` reaches their copy's ceiling are dropped, not expanded.
        Without ``marks`` the edges' acceptance marks are not looked up (see
        :meth:`LazyProduct.expand`)."""
        arrays = self.arrays
        self.rounds += 1
        buckets: list[IntArray] = []
        for queue in self.queues:
            nodes = queue.lowest(arrays.queued)
            if nodes is not None:
                queue.pop()
                buckets.append(nodes)
        if not buckets:
            active = np.zeros(0, dtype=np.int64)
        else:
            active = buckets[0] if len(buckets) == 1 else np.concatenate(buckets)
        arrays.queued[active] = False
        if isinstance(ceiling, np.ndarray):
            active = active[self._f(active) < ceiling[active // self.copy_size]]
        if self.copy_size:
            local = active % self.copy_size
            edges = self.product.expand(local, base=active - local, marks=marks)
        else:
            edges = self.product.expand(active, marks=marks)
        du = arrays.dist[edges.tails]
        d = du + edges.weights
        v = edges.heads
        if isinstance(ceiling, np.ndarray):
            ceiling = ceiling[v // self.copy_size]
        u = edges.tails
        keep = d + self.estimate_at(v) < ceiling
        if np.count_nonzero(keep) < len(keep):
            u, v, d, du = u[keep], v[keep], d[keep], du[keep]
        improved = relax_offers(arrays.dist, arrays.via, arrays.pred, v, d, du, u)
        fresh = improved[~arrays.queued[improved]]
        arrays.queued[fresh] = True
        self.reached += len(fresh)  # (every v was met by estimate_at above)
        # Every improved node goes in the bucket of its new f (queued ones too: theirs fell).
        # (Every improved node is one of v: met, its bound known.)
        self._queue(improved, self._f(improved))
        return edges, improved

    def path(self, target: int) -> list[int]:
        """The nodes from a source to ``target`` along the predecessors (in the product's
        own numbers when the search runs in copies)."""
        nodes = [target]
        while self.arrays.pred[nodes[-1]] >= 0:
            nodes.append(int(self.arrays.pred[nodes[-1]]))
        nodes.reverse()
        if self.copy_size:
            return [node % self.copy_size for node in nodes]
        return nodes


@dataclass(frozen=True, slots=True)
class GuidedLasso:
    """The best lasso: its cost bound, the prefix's nodes (to the anchor) and the cycle's
    (from the anchor, without coming back to it; one node for a stay), with the search's
    statistics."""

    cost: float
    prefix: list[int]
    cycle: list[int]
    searches: int
    optimal: bool
    reached: int
    rounds: int  # the rounds of the prefix search and of the closing searches


class _Bounds:
    """The bounds the lasso search needs, each computed once."""

    def __init__(self, product: LazyProduct, graph: RegionGraph, beta: float) -> None:
        self.product = product
        self.graph = graph
        self.beta = beta
        self.returns: dict[int, CostToGo] = {}
        self.cell_distance: dict[int, FloatArray] = {}
        self.to_cell: dict[tuple[int, int], CostToGo] = {}
        self.arounds: dict[tuple[int, int], CostToGo] = {}
        self.single: dict[int, Bound] = {}
        nq = graph.num_states
        stays = product.stutter_accepts[graph.classes].T  # (Q, local)
        stay = np.where(stays | stays[:, [graph.background]], 0.0, np.inf)
        self.stay = stay
        anywhere, entered = self._accepting_terminal(nq)
        self.lasso = cost_to_go(graph, np.minimum(stay, anywhere), np.minimum(stay, entered))

    def back_to(self, q: int) -> CostToGo:
        """A bound on the cost from any node to a node of state ``q``."""
        if q not in self.returns:
            terminal = np.full((self.graph.num_states, len(self.graph.classes)), np.inf)
            terminal[q, :] = 0.0
            self.returns[q] = cost_to_go(self.graph, terminal)
        return self.returns[q]

    def around(self, q: int, landmark: int) -> CostToGo:
        """A bound on the cost from any node to a node of state ``q`` and then into a
        triangle of ``landmark`` (a local class other than the background)."""
        key = (q, landmark)
        if key not in self.arounds:
            index = int(np.flatnonzero(self.graph.landmarks == landmark)[0])
            final = np.ascontiguousarray(self.graph.distance[:, index])
            self.arounds[key] = cost_to_go_to_cells(self.graph, q, final)
        return self.arounds[key]

    def _accepting_terminal(self, nq: int) -> tuple[FloatArray, FloatArray]:
        """(Q, local) twice: per region-level node, ``beta`` times a bound on closing a
        cycle through an accepting edge taken there (its move, then the way back to its
        tail's state); first anywhere in the region, then right after entering it (the way
        to the edge's landmark counted from the region's boundary entry cells)."""
        graph, product = self.graph, self.product
        count = len(graph.classes)
        terminal = np.full((nq, count), np.inf)
        entered_terminal = np.full((nq, count), np.inf)
        local_of = {int(c): i for i, c in enumerate(graph.classes.tolist())}
        kinds, states, width = product.marked.shape
        for kind in range(kinds):
            entered = local_of.get(int(product.kind_class[kind]))
            if entered is None:
                continue
            for q in range(states):
                for j in range(width):
                    if not product.marked[kind, q, j]:
                        continue
                    back = self.back_to(q)
                    q_next = int(product.successor[kind, q, j])
                    for c in range(count):
                        landmark = entered not in (graph.background, c)
                        at = entered if landmark else c
                        # After the edge: its head is a boundary entry cell of a landmark it
                        # enters, anywhere in c or the background otherwise.
                        rest = self.beta * back.at_region(q_next, at, entered=landmark)
                        if landmark:
                            # The cycle itself: back to q, then into that landmark again.
                            around = self.around(q, entered).at_region(
                                q_next, entered, entered=True
                            )
                            rest = max(rest, self.beta * around)
                        elif entered != graph.background:
                            around = self.around(q, entered).at_region(q_next, entered)
                            rest = max(rest, self.beta * around)
                        # The way to the landmark is paid partly before the edge (at weight
                        # one) and partly by it (at beta): at least the lesser.
                        weight = min(1.0, self.beta)
                        move = weight * graph.delta[c, entered] if landmark else 0.0
                        terminal[q, c] = min(terminal[q, c], move + rest)
                        move = weight * graph.delta_entry[c, entered] if landmark else 0.0
                        entered_terminal[q, c] = min(entered_terminal[q, c], move + rest)
        stutter_marked = product.stutter_marked[graph.classes]  # (local, Q, J)
        for c in range(count):
            for other in {c, graph.background}:
                for q in range(nq):
                    for j in range(stutter_marked.shape[2]):
                        if stutter_marked[other, q, j]:
                            q_next = int(product.stutter_successor[graph.classes[other], q, j])
                            cost = self.beta * self.back_to(q).at_region(q_next, c)
                            terminal[q, c] = min(terminal[q, c], cost)
                            entered_terminal[q, c] = min(entered_terminal[q, c], cost)
        return terminal, entered_terminal

    def _to(self, target: int) -> CostToGo:
        """The region-level bound to the node ``target``'s state and then its cell."""
        nq = self.product.num_states
        cell, state = target // nq, target % nq
        if (cell, state) not in self.to_cell:
            if cell not in self.cell_distance:
                self.cell_distance[cell] = self.graph.distance_to(np.array([cell]))
            self.to_cell[cell, state] = cost_to_go_to_cells(
                self.graph, state, self.cell_distance[cell]
            )
        return self.to_cell[cell, state]

    def closing(self, target: int) -> Bound:
        """A bound on the cost from any node to the node ``target``: the region-level one
        to its state and then its cell, and the straight line to its cell's position."""
        if target not in self.single:
            self.single[target] = self.closings([target], self.product.num_nodes)
        return self.single[target]

    def closings(self, targets: list[int], size: int) -> Bound:
        """:meth:`closing` of each of ``targets`` at once: node ``n`` is node ``n % size``
        bounded by the closing bound of ``targets[n // size]`` (searches side by side)."""
        nq = self.product.num_states
        back = StackedCostToGo.of([self._to(target) for target in targets])
        position = self.product.position
        goal = position[np.array(targets, dtype=np.int64) // nq]
        scale = self.graph.scale * (1.0 - 1e-9)

        def bound(nodes: IntArray) -> FloatArray:
            which = nodes // size
            cell_nodes = nodes - which * size
            offset = position[cell_nodes // nq] - goal[which]
            straight = np.sqrt(offset[:, 0] * offset[:, 0] + offset[:, 1] * offset[:, 1])
            result: FloatArray = np.maximum(back(which, cell_nodes), straight * scale)
            return result

        return bound


def guided_lasso(
    product: LazyProduct,
    allowed_cells: BoolArray,
    *,
    beta: float,
    max_searches: int,
) -> GuidedLasso | None:
    """The minimum-cost accepting lasso of ``product`` (None when there is none), see the
    module doc; past ``max_searches`` closing searches the best found, ``optimal`` false."""
    if not len(product.initial):
        return None
    graph = region_graph(product, allowed_cells)
    bounds = _Bounds(product, graph, beta)
    prefix = GuidedSearch(product, _Arrays.of(product.num_nodes), product.initial, bounds.lasso)
    closing_arrays: _Arrays | None = None
    # Closing searches run side by side, each in its own copy of the node numbers, as many as
    # CLOSING_NODES allows.
    width = max(1, min(max_searches, CLOSING_NODES // max(product.num_nodes, 1)))
    best: tuple[float, list[int], list[int]] | None = None
    candidates: list[tuple[float, int, int, float, float]] = []  # bound, u, v, w, g(u)
    searches = 0
    rounds = 0  # of the closing searches
    capped = False
    for node in prefix.sources[product.stays_accepting(prefix.sources)].tolist():
        best = _better(best, (0.0, [node], [node]))
    while True:
        incumbent = best[0] if best is not None else np.inf
        f = prefix.lowest()
        due = bool(candidates) and candidates[0][0] < min(f, incumbent)
        if due and width > 1 and f < min(incumbent, candidates[0][0] * (1.0 + LOOKAHEAD)):
            # The prefix search goes on a little (the candidates met meanwhile close in the
            # same group: searches side by side share their rounds), unless a group is full.
            due = _due_tails(candidates, f, width) >= width
        if due:
            if searches >= max_searches and best is not None:
                capped = True
                break
            room = max_searches - searches if best is not None else len(candidates)
            groups = _next_groups(candidates, prefix.arrays.dist, incumbent, beta, room, width)
            candidates = [c for c in candidates if (c[1], c[4]) not in groups.taken]
            heapq.heapify(candidates)
            if not groups.tails:
                continue
            needed = product.num_nodes * len(groups.tails)
            if closing_arrays is None or len(closing_arrays.dist) < needed:
                closing_arrays = None  # released before the larger one is allocated
                closing_arrays = _Arrays.of(needed)
            results, closing_rounds = _close_together(product, closing_arrays, groups, bounds)
            rounds += closing_rounds
            searches += len(groups.tails)
            for u, g, (back, back_path) in zip(groups.tails, groups.g, results, strict=True):
                if back is None:
                    continue
                total = g + beta * back
                if total < (best[0] if best is not None else np.inf) - 1e-12:
                    best = (total, prefix.path(u), [u, *back_path[:-1]])
            continue
        if f >= incumbent or not np.isfinite(f):
            break
        edges, improved = prefix.step(ceiling=incumbent)
        staying = improved[product.stays_accepting(improved)]
        if len(staying):
            node = int(staying[np.argmin(prefix.arrays.dist[staying])])
            if prefix.arrays.dist[node] < incumbent - 1e-12:
                best = (float(prefix.arrays.dist[node]), prefix.path(node), [node])
        for offer in _candidates(edges, prefix.arrays.dist, bounds, incumbent):
            heapq.heappush(candidates, offer)
    if best is None:
        return None
    cost, prefix_nodes, cycle_nodes = best
    return GuidedLasso(
        cost=cost,
        prefix=prefix_nodes,
        cycle=cycle_nodes,
        searches=searches,
        optimal=not capped,
        reached=prefix.reached,
        rounds=prefix.rounds + rounds,
    )


def _candidates(
    edges: Edges, dist: FloatArray, bounds: _Bounds, incumbent: float
) -> list[tuple[float, int, int, float, float]]:
    """The accepting edges among ``edges`` as cycle candidates ``(bound, u, v, w, g(u))``
    whose bound ``g(u) + beta * (w + b(v, u))`` is below the incumbent."""
    found: list[tuple[float, int, int, float, float]] = []
    marked = np.flatnonzero(edges.accepting)
    if not len(marked):
        return found
    tails, heads, weights = edges.tails[marked], edges.heads[marked], edges.weights[marked]
    for tail in np.unique(tails).tolist():
        mine = tails == tail
        back = bounds.closing(tail)(heads[mine])
        g = float(dist[tail])
        for head, weight, b in zip(
            heads[mine].tolist(), weights[mine].tolist(), back.tolist(), strict=True
        ):
            estimate = g + bounds.beta * (weight + b)
            if estimate < incumbent:
                found.append((estimate, tail, head, weight, g))
    return found


def _due_tails(candidates: list[tuple[float, int, int, float, float]], f: float, most: int) -> int:
    """How many distinct (tail, g) pairs the candidates whose bound is below ``f`` have,
    counted up to ``most`` (the heap is walked from its root through those alone)."""
    tails: set[tuple[int, float]] = set()
    stack = [0]
    while stack and len(tails) < most:
        at = stack.pop()
        if at < len(candidates) and candidates[at][0] < f:
            tails.add((candidates[at][1], candidates[at][4]))
            stack.extend((2 * at + 1, 2 * at + 2))
    return len(tails)


def _better(
    best: tuple[float, list[int], list[int]] | None, offer: tuple[float, list[int], list[int]]
) -> tuple[float, list[int], list[int]]:
    if best is None or offer[0] < best[0] - 1e-12:
        return offer
    return best


@dataclass(slots=True)
class _Groups:
    """Closing searches to run side by side: per accepting edges' tail ``u`` (at distance
    ``g`` from the start), its edges' heads and weights and the limit the incumbent allows;
    ``taken`` are the (tail, g) pairs removed from the candidates (stale ones included)."""

    tails: list[int] = field(default_factory=list)
    g: list[float] = field(default_factory=list)
    heads: list[IntArray] = field(default_factory=list)
    weights: list[FloatArray] = field(default_factory=list)
    limits: list[float] = field(default_factory=list)
    taken: set[tuple[int, float]] = field(default_factory=set)


def _next_groups(
    candidates: list[tuple[float, int, int, float, float]],
    dist: FloatArray,
    incumbent: float,
    beta: float,
    room: int,
    width: int,
) -> _Groups:
    """The candidates to close next, in order of their bound: every pending candidate out of
    one tail closes in one search (from all its heads at once, each starting at its edge's
    weight), up to ``width`` tails, fewer than ``room``, all with bounds below the incumbent.
    Candidates whose tail got nearer since are dropped: its expansion offered them again."""
    groups = _Groups()
    for bound, u, _, _, g in sorted(candidates):
        if len(groups.tails) >= min(width, room) or bound >= incumbent:
            break
        if (u, g) in groups.taken:
            continue
        groups.taken.add((u, g))
        if dist[u] < g:
            continue
        same = [c for c in candidates if c[1] == u and c[4] == g]
        groups.tails.append(u)
        groups.g.append(g)
        groups.heads.append(np.array([c[2] for c in same], dtype=np.int64))
        groups.weights.append(np.array([c[3] for c in same]))
        groups.limits.append((incumbent - g) / max(beta, 1e-12))
    return groups


def _close_together(
    product: LazyProduct, arrays: _Arrays, groups: _Groups, bounds: _Bounds
) -> tuple[list[tuple[float | None, list[int]]], int]:
    """Per group: the cheapest way from its tail ``u`` through one of its accepting edges
    back to ``u`` if it costs at most the group's limit, its cost and its nodes from the head
    to ``u``; the searches share their rounds (returned too)."""
    arrays.reset()
    size = product.num_nodes
    count = len(groups.tails)
    base = np.arange(count, dtype=np.int64) * size
    sources = np.concatenate([heads + base[k] for k, heads in enumerate(groups.heads)])
    offsets = np.concatenate(groups.weights)
    targets = np.array(groups.tails, dtype=np.int64) + base
    limits = np.array(groups.limits)
    bound = bounds.closings(groups.tails, size)
    search = GuidedSearch(
        product, arrays, sources, bound, offsets=offsets, copy_size=size, copies=count
    )
    g = np.array(groups.g)
    while True:
        reached = arrays.distance(targets)
        if np.isfinite(reached).any():  # (no copy's lasso yet: no copy limits another)
            limits = np.minimum(limits, _others_limit(g, reached, bounds.beta))
        ceilings = np.minimum(reached, limits)
        if search.exhausted(ceilings):
            break
        search.step(ceiling=ceilings, marks=False)  # (its edges' marks are not read)
    found: list[tuple[float | None, list[int]]] = []
    reached = arrays.distance(targets)
    limits = np.minimum(limits, _others_limit(g, reached, bounds.beta))
    for k in range(count):
        distance = float(reached[k])
        if not np.isfinite(distance) or distance > limits[k]:
            found.append((None, []))
        else:
            found.append((distance, search.path(int(targets[k]))))
    return found, search.rounds


def _others_limit(g: FloatArray, reached: FloatArray, beta: float) -> FloatArray:
    """Per copy: the cycle cost past which its lasso cannot beat another copy's lasso found
    so far (``g + beta * reached``, a real lasso's cost once its tail is reached), with a
    little room so that rounding never cuts a copy whose lasso ties with the best: a copy's
    own lasso never limits it."""
    totals = g + beta * reached
    if len(totals) < 2:
        return np.full(len(totals), np.inf)
    order = np.argsort(totals, kind="stable")
    others = np.full(len(totals), totals[order[0]])
    others[order[0]] = totals[order[1]]  # the best copy's: the second best
    limit: FloatArray = (others - g) / max(beta, 1e-12)
    return limit + 1e-9 * (1.0 + np.abs(limit))
