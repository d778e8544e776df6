"""How big the product will be, estimated before it is built.

The product of the transition system (``m`` triangles, four entry slots each) and the
automaton (``Q`` states, ``K`` acceptance sets, degeneralized into at most ``Q * (K + 1)``
states) is built as numpy arrays: about 60 bytes per edge while building and 25 in the final
graph, plus the search's arrays per node.  A product within the budget is built; a larger one
is searched as it is expanded (:mod:`tlmpc.planning.guided`), which stores per node only the
searches' arrays (50 bytes), so only a product with more nodes than that search allows stops
with a diagnostic (P040) instead of exhausting the machine's memory.

Vertex passages (:mod:`tlmpc.planning.passages`) add edges that grow with the square of the
number of triangles around a vertex; they are estimated from those counts before any passage
is listed, and refused (P060) beyond :data:`MAX_PASSAGE_EDGES`.
"""

from __future__ import annotations

from dataclasses import dataclass

from tlmpc.abstraction.model import Abstraction
from tlmpc.automata.model import Automaton
from tlmpc.base.errors import UsageError, error

#: Upper bounds the planner accepts.  The edge estimate is loose (on grid maps the built
#: product has a fifth of it): a million-triangle grid with a 4-state automaton is estimated
#: at 128M edges, holds 24M, and compiles in about 4 GB.
MAX_PRODUCT_NODES = 40_000_000
MAX_PRODUCT_EDGES = 160_000_000
#: The most nodes the guided search handles: two searches' arrays, 50 bytes a node.
MAX_GUIDED_NODES = 32_000_000

#: The most product edges vertex passages may add.  Building them takes about 130 bytes and
#: half a microsecond of CPU per edge (the moves, their letters and the edge batches, then the
#: graph merged with them), so the budget keeps them near 2.6 GB; a mesh of good shape has a
#: few triangles around each vertex and needs a tiny fraction of it.
MAX_PASSAGE_EDGES = 20_000_000

SLOTS = 4  # as in tlmpc.planning.product: three entry edges and the start
MOVES_PER_NODE = 4  # leave through one of three edges (two after entering) or stutter


@dataclass(frozen=True, slots=True)
class ProductSize:
    """Upper bounds on the product's nodes and edges."""

    nodes: int
    edges: int

    @property
    def fits(self) -> bool:
        """True when both are within the planner's budget."""
        return self.nodes <= MAX_PRODUCT_NODES and self.edges <= MAX_PRODUCT_EDGES


def estimate_product(abstraction: Abstraction, automaton: Automaton) -> ProductSize:
    """Upper bounds on the product's size, from the input sizes alone (nothing is built)."""
    # Degeneralization keeps a counter 0..K beside each state (K + 1 copies) when K >= 2.
    copies = automaton.num_acc + 1 if automaton.num_acc >= 2 else 1
    states = max(automaton.num_states, 1) * copies
    edges = max(len(automaton.edges), 1) * copies
    triangles = abstraction.num_triangles
    return ProductSize(
        nodes=triangles * SLOTS * states,
        edges=triangles * SLOTS * MOVES_PER_NODE * edges,
    )


def check_product_size(abstraction: Abstraction, automaton: Automaton) -> ProductSize:
    """The estimate; raises :class:`UsageError` (P040) when the product would not fit even
    the guided search (a product beyond the budget for building it is searched that way)."""
    size = estimate_product(abstraction, automaton)
    if not size.fits and size.nodes > MAX_GUIDED_NODES:
        raise UsageError(
            error(
                "P040",
                f"the product of the transition system ({abstraction.num_triangles:,} "
                f"triangles) and the automaton ({automaton.num_states:,} states, "
                f"{automaton.num_acc} acceptance sets) would have up to {size.nodes:,} nodes "
                f"and {size.edges:,} edges, more than the planner's budget "
                f"({MAX_PRODUCT_NODES:,} nodes and {MAX_PRODUCT_EDGES:,} edges to build it, "
                f"{MAX_GUIDED_NODES:,} nodes to search it as it is expanded)",
                hint="use a coarser mesh (a larger options.max_area), or split the task into "
                "smaller missions",
            )
        )
    return size


def passages_too_large(abstraction: Abstraction, automaton: Automaton) -> UsageError:
    """P060: the plan needs vertex passages, which only the built product has, and the
    product is beyond the budget for building it."""
    size = estimate_product(abstraction, automaton)
    return UsageError(
        error(
            "P060",
            "no plan exists along the mesh's edges, and the search through mesh vertices "
            f"needs the product built: up to {size.nodes:,} nodes and {size.edges:,} edges, "
            f"more than the planner's budget ({MAX_PRODUCT_NODES:,} nodes, "
            f"{MAX_PRODUCT_EDGES:,} edges)",
            hint="use a coarser mesh (a larger options.max_area), or widen the passage the "
            "plan must take so that it runs through an edge",
        )
    )


def check_passage_edges(edges: int, *, widest_fan: int, at: tuple[float, float]) -> None:
    """Raises :class:`UsageError` (P060) when vertex passages would add more than
    :data:`MAX_PASSAGE_EDGES` edges to the product (``edges``: the estimate); ``widest_fan``
    triangles lie around the vertex ``at``, the most around any contact vertex."""
    if edges <= MAX_PASSAGE_EDGES:
        return
    x, y = at
    raise UsageError(
        error(
            "P060",
            "no plan exists along the mesh's edges, and the search through mesh vertices "
            f"would add up to {edges:,} product edges, more than the planner's budget "
            f"({MAX_PASSAGE_EDGES:,}): they grow with the square of the triangles around a "
            f"vertex, and {widest_fan:,} lie around ({x:.6g}, {y:.6g})",
            hint="widen the passage the plan must take so that it runs through an edge; "
            "dozens of triangles or more around one vertex are a sliver the mesh had to fill "
            "(move the features near it apart, or exactly together), many contact vertices "
            "a fine mesh (a larger options.max_area)",
        )
    )
