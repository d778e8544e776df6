"""How big the product will be, estimated before it is built.

The product of the transition system (``m`` triangles, four entry slots each) and the
automaton (``Q`` states, ``K`` acceptance sets, degeneralized into at most ``Q * (K + 1)``
states) is built as numpy arrays: about 60 bytes per edge while building and 25 in the final
graph, plus the search's arrays per node.  An estimate from the sizes alone lets a
too-large mission stop with a diagnostic (P040) instead of exhausting the machine's memory.
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
    """The estimate; raises :class:`UsageError` (P040) when the product would not fit."""
    size = estimate_product(abstraction, automaton)
    if not size.fits:
        raise UsageError(
            error(
                "P040",
                f"the product of the transition system ({abstraction.num_triangles:,} "
                f"triangles) and the automaton ({automaton.num_states:,} states, "
                f"{automaton.num_acc} acceptance sets) would have up to {size.nodes:,} nodes "
                f"and {size.edges:,} edges, more than the planner's budget "
                f"({MAX_PRODUCT_NODES:,} nodes, {MAX_PRODUCT_EDGES:,} edges)",
                hint="use a coarser mesh (a larger options.max_area), or split the task into "
                "smaller missions",
            )
        )
    return size
