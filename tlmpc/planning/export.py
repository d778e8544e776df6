"""The paper's route: the transition system D and the negated task for SPIN and NuSMV.

A counterexample to ``!task`` is a run of D satisfying the task.  D keeps its stutter
self-loops (the robot may stay in a triangle) and, by default, tlmpc's no-bounce rule (a run
never leaves a triangle through the edge it came in by), so a model checker plans over exactly
the runs tlmpc's planner considers; ``bounce=True`` gives the paper's plain D, whose shortest
trails can be shorter on maps where the shortest route bounces (see docs/model-checkers.md).
"""

from __future__ import annotations

import hashlib
import re
from collections.abc import Callable

from tlmpc.abstraction.model import Abstraction
from tlmpc.base.errors import UsageError, error
from tlmpc.ltl.ast import (
    TRUE,
    Formula,
    Prop,
)
from tlmpc.ltl.printer import to_nusmv, to_spin
from tlmpc.ltl.transform import substitute

PREFIX = "p_"  # region propositions get a prefix so no region name clashes with a keyword

#: The only names that may reach a model as identifiers: the mission language's own rule
#: (no length limit), which is also a subset of Promela's, NuSMV's and DOT's identifier
#: grammars (SPIN's length limit is met by :func:`promela_name`).
IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")

#: Prefix of the Promela tables ``r_<region>[t]`` (whether triangle ``t`` lies in the region);
#: it differs from :data:`PREFIX`, so a table never has a proposition's name.
TABLE_PREFIX = "r_"

#: The longest region name a Promela identifier keeps whole.  SPIN's lexer overflows on
#: identifiers of about 500 characters; a longer name is cut to this many characters and
#: followed by ``_`` and 16 hex digits of the name's SHA-256, so it is longer than every name
#: kept whole and distinct from every other cut name.
PROMELA_NAME_LIMIT = 200


def promela_name(region: str) -> str:
    """The region's name as a Promela identifier's tail: itself, or cut and tagged with its
    hash when it is longer than :data:`PROMELA_NAME_LIMIT` (deterministic)."""
    if len(region) <= PROMELA_NAME_LIMIT:
        return region
    digest = hashlib.sha256(region.encode("utf-8")).hexdigest()[:16]
    return f"{region[:PROMELA_NAME_LIMIT]}_{digest}"


def _same_name(region: str) -> str:
    return region


#: Characters a user's text keeps in a model comment: none can open, close or end a comment
#: (no ``*``, ``/``, ``--``, newline) or start a quoted string or escape in any of the formats.
_COMMENT_SAFE = re.compile(r"[^A-Za-z0-9_ .,:;()+=-]")


def comment_text(text: str, limit: int = 80) -> str:
    """``text`` reduced to characters that cannot close or end a comment in Promela
    (``/* */``), NuSMV (``--`` to end of line) or DOT (``/* */``); others become ``?``."""
    safe = _COMMENT_SAFE.sub("?", text[:limit])
    while "--" in safe:  # an SMV comment cannot be closed, but keep the text plain
        safe = safe.replace("--", "-?")
    return safe


def checked_regions(abstraction: Abstraction, formula: Formula) -> None:
    """Refuse (U039) a region or proposition name that is not a plain identifier.

    The mission schema allows only identifiers, so only an edited ``abstraction.json`` or
    ``mission.json`` can get here; such a name must never reach a model as code.
    """
    names = [*abstraction.regions, *sorted({n for letter in abstraction.letters for n in letter})]
    names += sorted(formula.props())
    for name in names:
        if not IDENTIFIER.fullmatch(name):
            raise UsageError(
                error(
                    "U039",
                    f"region name {name!r} is not an identifier; refusing to export it",
                    hint="region names are letters, digits and _ (was the output edited?)",
                )
            )
    unknown = sorted(formula.props() - set(abstraction.regions))
    if unknown:
        raise UsageError(
            error(
                "U039",
                f"the task names regions the abstraction does not have: {', '.join(unknown)}",
                hint="mission.json and abstraction.json come from different compiles",
            )
        )


def _prefixed(formula: Formula, rename: Callable[[str], str] = _same_name) -> Formula:
    return substitute(formula, {p: Prop(PREFIX + rename(p)) for p in formula.props()})


def _members(abstraction: Abstraction) -> dict[str, list[int]]:
    members: dict[str, list[int]] = {name: [] for name in abstraction.regions}
    for triangle, letter in enumerate(abstraction.letter_of.tolist()):
        for name in abstraction.letters[letter]:
            members[name].append(triangle)
    return members


#: Assignments per ``d_step``: SPIN rejects longer ones ("d_step sequence too long").
D_STEP_CHUNK = 1000


def _table_steps(abstraction: Abstraction) -> list[str]:
    """``d_step`` blocks filling the ``hidden`` tables once: ``nb[3*t + i] = n`` for every
    neighbour ``n`` of every triangle and ``r_<region>[t] = 1`` for every triangle of every
    region, a dozen assignments per line."""
    assignments = [
        f"nb[{3 * triangle + i}] = {int(n)};"
        for triangle in range(abstraction.num_triangles)
        for i, n in enumerate(abstraction.neighbors[triangle].tolist())
        if n >= 0
    ]
    assignments += [
        f"{TABLE_PREFIX}{promela_name(region)}[{triangle}] = 1;"
        for region, triangles in _members(abstraction).items()
        for triangle in triangles
    ]
    lines: list[str] = []
    for chunk in range(0, len(assignments), D_STEP_CHUNK):
        part = assignments[chunk : chunk + D_STEP_CHUNK]
        lines.append("  d_step {")
        lines += ["    " + " ".join(part[k : k + 12]) for k in range(0, len(part), 12)]
        lines.append("  }")
    return lines


def to_promela(
    abstraction: Abstraction, formula: Formula, name: str = "mission", *, bounce: bool = False
) -> str:
    """A Promela model of D with the never claim source ``ltl task { !(formula) }``.

    The model moves ``t`` to a neighbour or stays (one step each), and never leaves a triangle
    through the edge it entered by (the variable ``prev``), as tlmpc's planner; ``bounce=True``
    drops that rule and gives the paper's plain D.  Adjacency and region membership live in
    ``hidden`` tables set once by a few ``d_step`` blocks, so the model (and ``pan.c``) stays
    linear in the number of triangles.  Each region's proposition is a ``bit`` that every move
    sets from its table: the ``ltl`` text names only these bits, so it stays as short as the
    task however many triangles a region has (SPIN expands macros into the ``ltl`` text, and
    its LTL parser fails on a long one).  The state vector holds ``t``, ``prev`` and the bits,
    which follow from ``t``, so they add no states.  Every move prints ``tlmpc: t = N``, so
    ``spin -t`` replays a trail as a list of triangles.
    """
    checked_regions(abstraction, formula)
    m = abstraction.num_triangles
    entry = "" if bounce else "prev = t; "
    kind = "bounces allowed" if bounce else "no bounce"
    lines = [
        f"/* tlmpc export of {comment_text(name)}: the transition system D ({m} triangles, "
        f"stutter, {kind}). */",
        "/* SPIN's counterexample to the negated task is a plan for the task. */",
        f"hidden int nb[{3 * m}] = -1;  /* nb[3*t + i]: neighbour of t across edge i */",
        f"int t = {abstraction.start};  /* the triangle the robot is in */",
    ]
    if not bounce:
        lines.append("int prev = -1;  /* the triangle t was entered from (no bounce) */")
    updates = ""
    for region, triangles in _members(abstraction).items():
        proposition, table = PREFIX + promela_name(region), TABLE_PREFIX + promela_name(region)
        if not triangles:
            lines.append(f"#define {proposition} false  /* a region with no triangle */")
            continue
        inside = int(abstraction.start in triangles)
        lines += [
            f"hidden byte {table}[{m}];  /* 1: the triangle lies in the region */",
            f"bit {proposition} = {inside};  /* the robot is in the region */",
        ]
        updates += f"{proposition} = {table}[t]; "
    lines += ["", "active proctype robot() {", *_table_steps(abstraction), "  do"]
    for i in range(3):
        k = f"3*t + {i}"
        guard = f"nb[{k}] >= 0" + ("" if bounce else f" && nb[{k}] != prev")
        move = f'{entry}t = nb[{k}]; {updates}printf("tlmpc: t = %d\\n", t)'
        lines.append(f"  :: d_step {{ {guard} -> {move} }}")
    lines += [
        "  :: t >= 0 -> skip  /* stutter (a bare skip would be an unconditional self-loop) */",
        "  od",
        "}",
        "",
        f"ltl task {{ !({to_spin(_prefixed(formula, promela_name))}) }}",
        "",
    ]
    return "\n".join(lines)


def to_smv(
    abstraction: Abstraction, formula: Formula, name: str = "mission", *, bounce: bool = False
) -> str:
    """A NuSMV model of D with ``LTLSPEC !(formula)``; ``prev`` and a ``TRANS`` constraint
    keep tlmpc's no-bounce rule unless ``bounce=True`` (see :func:`to_promela`)."""
    checked_regions(abstraction, formula)
    n = abstraction.num_triangles
    kind = "bounces allowed" if bounce else "no bounce"
    lines = [
        f"-- tlmpc export of {comment_text(name)}: the transition system D ({n} triangles, "
        f"stutter, {kind}).",
        "MODULE main",
        f"VAR t : 0..{n - 1};",
    ]
    if not bounce:
        lines.append(f"VAR prev : -1..{n - 1};  -- the triangle t was entered from")
    lines += ["ASSIGN", f"  init(t) := {abstraction.start};"]
    if not bounce:
        lines += [
            "  init(prev) := -1;",
            "  next(prev) := case next(t) = t : prev; TRUE : t; esac;",
        ]
    lines.append("  next(t) := case")
    for triangle in range(n):
        successors = [triangle, *(int(x) for x in abstraction.neighbors[triangle] if x >= 0)]
        lines.append(f"    t = {triangle} : {{{', '.join(str(s) for s in successors)}}};")
    lines.append("  esac;")
    if not bounce:
        lines.append("TRANS next(t) = t | next(t) != prev;")
    lines.append("DEFINE")
    for region, triangles in _members(abstraction).items():
        members = ", ".join(str(i) for i in triangles)
        lines.append(f"  {PREFIX}{region} := {'t in {' + members + '}' if triangles else 'FALSE'};")
    lines += [f"LTLSPEC !({to_nusmv(_prefixed(formula))})", ""]
    return "\n".join(lines)


def to_dot_graph(abstraction: Abstraction, name: str = "mission") -> str:
    """Graphviz DOT of D: one node per triangle labelled with its regions.

    The graph gets a fixed identifier; the mission name appears only in a comment."""
    checked_regions(abstraction, TRUE)
    lines = [
        "graph D {",
        f"  /* tlmpc export of {comment_text(name)} */",
        "  node [shape=circle, fontsize=8];",
    ]
    centroids = abstraction.vertices[abstraction.triangles].mean(axis=1)
    for triangle in range(abstraction.num_triangles):
        labels = ",".join(abstraction.labels(triangle))
        x, y = centroids[triangle].tolist()
        extra = ', style=filled, fillcolor="#ddeeff"' if labels else ""
        start = ", penwidth=3" if triangle == abstraction.start else ""
        lines.append(
            f'  {triangle} [label="{triangle}\\n{labels}", pos="{x:.4g},{y:.4g}!"{extra}{start}];'
        )
    for triangle in range(abstraction.num_triangles):
        for other in abstraction.neighbors[triangle].tolist():
            if other > triangle:
                lines.append(f"  {triangle} -- {other};")
    lines.append("}")
    return "\n".join(lines) + "\n"
