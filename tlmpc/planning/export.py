"""The paper's route: the transition system D and the negated task for SPIN and NuSMV.

A counterexample to ``!task`` is a run of D satisfying the task.  D keeps its stutter
self-loops (the robot may stay in a triangle).  The exported models do not know tlmpc's
no-bounce rule (see docs/model-checkers.md), so their shortest trails can be shorter than
tlmpc's plans on maps where the shortest route bounces.
"""

from __future__ import annotations

from tlmpc.abstraction.model import Abstraction
from tlmpc.ltl.ast import Formula, Prop
from tlmpc.ltl.printer import to_spin
from tlmpc.ltl.transform import nnf, substitute

PREFIX = "p_"  # region macros get a prefix so no region name clashes with a keyword


def _prefixed(formula: Formula) -> Formula:
    return substitute(formula, {p: Prop(PREFIX + p) for p in formula.props()})


def _members(abstraction: Abstraction) -> dict[str, list[int]]:
    members: dict[str, list[int]] = {name: [] for name in abstraction.regions}
    for triangle, letter in enumerate(abstraction.letter_of.tolist()):
        for name in abstraction.letters[letter]:
            members[name].append(triangle)
    return members


def to_promela(abstraction: Abstraction, formula: Formula, name: str = "mission") -> str:
    """A Promela model of D with the never claim source ``ltl task { !(formula) }``."""
    lines = [
        f"/* tlmpc export of {name}: the transition system D ({abstraction.num_triangles} "
        "triangles, stutter included). */",
        "/* SPIN's counterexample to the negated task is a plan for the task. */",
        "int t;",
    ]
    for region, triangles in _members(abstraction).items():
        condition = " || ".join(f"t == {i}" for i in triangles) or "false"
        lines.append(f"#define {PREFIX}{region} ({condition})")
    lines += ["", "active proctype robot() {", f"  t = {abstraction.start};", "  do"]
    for triangle in range(abstraction.num_triangles):
        successors = [int(n) for n in abstraction.neighbors[triangle] if n >= 0]
        options = " ".join(f":: t = {n}" for n in successors)
        lines.append(f"  :: t == {triangle} -> if {options} :: skip fi")
    lines += ["  od", "}", "", f"ltl task {{ !({to_spin(_prefixed(formula))}) }}", ""]
    return "\n".join(lines)


def _smv(formula: Formula) -> str:
    spin = to_spin(nnf(_prefixed(formula)))
    return spin.replace("[]", "G ").replace("<>", "F ").replace("&&", "&").replace("||", "|")


def to_smv(abstraction: Abstraction, formula: Formula, name: str = "mission") -> str:
    """A NuSMV model of D with ``LTLSPEC !(formula)``."""
    n = abstraction.num_triangles
    lines = [
        f"-- tlmpc export of {name}: the transition system D ({n} triangles).",
        "MODULE main",
        f"VAR t : 0..{n - 1};",
        "ASSIGN",
        f"  init(t) := {abstraction.start};",
        "  next(t) := case",
    ]
    for triangle in range(n):
        successors = [triangle, *(int(x) for x in abstraction.neighbors[triangle] if x >= 0)]
        lines.append(f"    t = {triangle} : {{{', '.join(str(s) for s in successors)}}};")
    lines += ["  esac;", "DEFINE"]
    for region, triangles in _members(abstraction).items():
        members = ", ".join(str(i) for i in triangles)
        lines.append(f"  {PREFIX}{region} := {'t in {' + members + '}' if triangles else 'FALSE'};")
    lines += [f"LTLSPEC !({_smv(formula)})", ""]
    return "\n".join(lines)


def to_dot_graph(abstraction: Abstraction, name: str = "mission") -> str:
    """Graphviz DOT of D: one node per triangle labelled with its regions."""
    lines = [f'graph "{name}" {{', "  node [shape=circle, fontsize=8];"]
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
