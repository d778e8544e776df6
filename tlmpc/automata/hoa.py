"""HOA v1 (Hanoi Omega-Automata) export and a reader for round trips.

The reader covers what tlmpc and Spot write for (generalized) Büchi automata: explicit edge
labels over AP indices (``t f ! & | ( )``), acceptance sets on edges or on states, several
edges per state.  Aliases and implicit labels are not supported (B002).
"""

from __future__ import annotations

import functools
import re
from typing import TYPE_CHECKING, Any

from tlmpc.automata.model import Automaton, Edge
from tlmpc.base.errors import InvalidInputError, error
from tlmpc.base.version import __version__
from tlmpc.ltl.ast import TRUE, And, Const, Formula, Not, Or, Prop, conjoin, disjoin
from tlmpc.ltl.printer import to_text

if TYPE_CHECKING:  # lark is imported by the reader only: writing HOA (every compile) needs none
    from lark import Lark


def _label(guard: Formula, index: dict[str, int]) -> str:
    if isinstance(guard, Const):
        return "t" if guard.value else "f"
    if isinstance(guard, Prop):
        return str(index[guard.name])
    if isinstance(guard, Not):
        return "!" + _label(guard.arg, index)
    if isinstance(guard, And):
        return " & ".join(
            f"({_label(a, index)})" if isinstance(a, Or) else _label(a, index) for a in guard.args
        )
    if isinstance(guard, Or):
        return " | ".join(_label(a, index) for a in guard.args)
    raise ValueError(f"guards are propositional, got {guard!r}")


def _escaped(text: str) -> str:
    """``text`` for a double-quoted string of HOA or DOT: each backslash and quote escaped by a
    backslash, which both formats read back (Graphviz would otherwise take a backslash that
    ends a name for an escape of the next quote and end the string there)."""
    return text.replace("\\", "\\\\").replace('"', '\\"')


def _quote(text: str) -> str:
    return '"' + _escaped(text) + '"'


def to_hoa(automaton: Automaton) -> str:
    """The automaton in HOA v1 format."""
    index = {ap: i for i, ap in enumerate(automaton.aps)}
    k = automaton.num_acc
    lines = ["HOA: v1", f'tool: "tlmpc" "{__version__}"']
    if automaton.formula:
        name = automaton.formula
        if automaton.letters is not None:
            # Other tools read `name:` as the automaton's language; say it is only the
            # formula's on the map's letters (the letters follow in `tlmpc-letters:`).
            name = f"{name} (restricted to {len(automaton.letters)} letters)"
        lines.append(f"name: {_quote(name)}")
        lines.append(f"tlmpc-ltl: {_quote(automaton.formula)}")
    if automaton.letters is not None:
        lines.append(
            "tlmpc-letters: "
            + str(len(automaton.letters))
            + "".join(
                " " + _quote(" ".join(str(index[a]) for a in letter if a in index))
                for letter in automaton.letters
            )
        )
    lines.append(f"States: {automaton.num_states}")
    lines.append(f"Start: {automaton.initial}")
    lines.append(f"AP: {len(automaton.aps)}" + "".join(f" {_quote(a)}" for a in automaton.aps))
    if automaton.state_based:
        lines += ["acc-name: Buchi", "Acceptance: 1 Inf(0)"]
        lines.append("properties: trans-labels explicit-labels state-acc")
    elif k == 0:
        lines += ["acc-name: all", "Acceptance: 0 t"]
        lines.append("properties: trans-labels explicit-labels trans-acc")
    else:
        name = "Buchi" if k == 1 else f"generalized-Buchi {k}"
        condition = "&".join(f"Inf({i})" for i in range(k))
        lines += [f"acc-name: {name}", f"Acceptance: {k} {condition}"]
        lines.append("properties: trans-labels explicit-labels trans-acc")
    lines.append("--BODY--")
    out: dict[int, list[Edge]] = {}
    for edge in automaton.edges:
        out.setdefault(edge.src, []).append(edge)
    for state in range(automaton.num_states):
        name = automaton.state_names[state] if state < len(automaton.state_names) else ""
        edges = out.get(state, [])
        state_marks = ""
        if automaton.state_based and edges and edges[0].marks:
            state_marks = " {0}"
        lines.append(f"State: {state} {_quote(name)}{state_marks}".rstrip())
        for edge in edges:
            marks = ""
            if not automaton.state_based and edge.marks:
                marks = " {" + " ".join(str(m) for m in sorted(edge.marks)) + "}"
            lines.append(f"  [{_label(edge.guard, index)}] {edge.dst}{marks}")
    lines.append("--END--")
    return "\n".join(lines) + "\n"


_GRAMMAR = r"""
start: header "--BODY--" body "--END--"
header: item+
item: HEADER_NAME value*
?value: INT -> int_value
      | STRING -> string_value
      | IDENT -> ident_value
      | T_CONST -> ident_value
      | F_CONST -> ident_value
      | acc_cond
acc_cond: ACC_ATOM
body: state*
state: "State:" INT STRING? marks? edge*
edge: "[" label "]" INT marks?
marks: "{" INT* "}"
?label: disj
?disj: conj ("|" conj)*
?conj: lit ("&" lit)*
?lit: "!" lit -> neg
    | "(" disj ")"
    | INT -> ap
    | T_CONST -> true
    | F_CONST -> false
// `t`/`f` only as whole words: not the first letter of `tool:` or `trans-acc`.
T_CONST.2: /t(?![A-Za-z0-9_:-])/
F_CONST.2: /f(?![A-Za-z0-9_:-])/
HEADER_NAME: /[A-Za-z@][A-Za-z0-9_-]*:/
ACC_ATOM: /(Inf|Fin)\(!?\d+\)([&|](Inf|Fin)\(!?\d+\))*/
IDENT: /[A-Za-z_][A-Za-z0-9_-]*/
STRING: /"([^"\\]|\\.)*"/
%import common.INT
%import common.WS
COMMENT: /\/\*(.|\n)*?\*\//
%ignore WS
%ignore COMMENT
"""


@functools.cache
def _parser() -> Lark:
    from lark import Lark

    return Lark(_GRAMMAR, parser="earley", propagate_positions=True)


def _formula(tree: Any, aps: list[str]) -> Formula:
    from lark import Token

    if isinstance(tree, Token):
        if int(tree) >= len(aps):
            raise InvalidInputError(
                error("B003", f"label uses AP {int(tree)} but only {len(aps)} are declared")
            )
        return Prop(aps[int(tree)])
    kind = tree.data
    if kind == "ap":
        number = int(tree.children[0])
        if number >= len(aps):
            raise InvalidInputError(
                error(
                    "B003",
                    f"label uses AP {number} but only {len(aps)} are declared",
                    line=tree.meta.line,
                    col=tree.meta.column,
                )
            )
        return Prop(aps[number])
    if kind == "true":
        return TRUE
    if kind == "false":
        return Const(False)
    if kind == "neg":
        return Not(_formula(tree.children[0], aps))
    if kind == "conj":
        return conjoin([_formula(c, aps) for c in tree.children])
    if kind == "disj":
        return disjoin([_formula(c, aps) for c in tree.children])
    raise ValueError(kind)


def _unquote(token: str) -> str:
    # One left-to-right pass: `\\"` is a backslash then the closing quote's escape...
    return re.sub(r"\\(.)", r"\1", token[1:-1], flags=re.DOTALL)


def parse_hoa(text: str, *, file: str | None = None) -> Automaton:
    """Read one automaton written in HOA v1 (the subset described in the module doc)."""
    from lark import Token, Tree
    from lark.exceptions import LarkError, UnexpectedInput

    try:
        tree: Any = _parser().parse(text)
    except UnexpectedInput as exc:
        raise InvalidInputError(
            error(
                "B001",
                "not a HOA automaton: unexpected input",
                hint="expected HOA v1 (header, --BODY--, --END--)",
                file=file,
                line=exc.line,
                col=exc.column,
            )
        ) from None
    except LarkError as exc:
        raise InvalidInputError(error("B001", f"not a HOA automaton: {exc}", file=file)) from None
    header: dict[str, list[Any]] = {}
    for item in tree.children[0].children:
        key = str(item.children[0])[:-1]
        values = []
        for child in item.children[1:]:
            if isinstance(child, Tree) and child.children:
                values.append(child.children[0] if child.data != "acc_cond" else child)
            else:
                values.append(child)
        header.setdefault(key, []).append(values)
    if (
        header.get("HOA") != [[Token("IDENT", "v1")]]
        and str(header.get("HOA", [[""]])[0][0]) != "v1"
    ):
        raise InvalidInputError(error("B002", "unsupported HOA version", file=file))
    aps_values = header.get("AP", [[0]])[0]
    aps = [_unquote(str(v)) for v in aps_values[1:]]
    acceptance = header.get("Acceptance", [[0]])[0]
    num_acc = int(str(acceptance[0]))
    acc_name = " ".join(str(v) for v in header.get("acc-name", [[""]])[0])
    state_based = "state-acc" in " ".join(str(v) for v in header.get("properties", [[]])[0])
    letters = _letters(header.get("tlmpc-letters"), aps)
    formula_values = header.get("tlmpc-ltl") or header.get("name") or [[""]]
    formula = _unquote(str(formula_values[0][0])) if formula_values[0] else ""
    starts = header.get("Start", [[0]])
    edges: list[Edge] = []
    names: dict[int, str] = {}
    count = int(str(header.get("States", [[0]])[0][0])) if "States" in header else 0
    for state_tree in tree.children[1].children:
        children = list(state_tree.children)
        number = int(str(children[0]))
        count = max(count, number + 1)
        state_marks: frozenset[int] = frozenset()
        for child in children[1:]:
            if isinstance(child, Token) and child.type == "STRING":
                names[number] = _unquote(str(child))
            elif isinstance(child, Tree) and child.data == "marks":
                state_marks = frozenset(int(str(m)) for m in child.children)
        for child in children[1:]:
            if isinstance(child, Tree) and child.data == "edge":
                guard = _formula(child.children[0], aps)
                dst = int(str(child.children[1]))
                marks = state_marks
                if len(child.children) > 2:
                    marks = marks | frozenset(int(str(m)) for m in child.children[2].children)
                edges.append(Edge(src=number, dst=dst, guard=guard, marks=marks))
    if "all" in acc_name:
        num_acc = 0
    _check(acceptance, num_acc, aps, count, starts, edges, file)
    return Automaton(
        aps=tuple(aps),
        num_states=max(count, 1),
        initial=int(str(starts[0][0])),
        edges=tuple(edges),
        num_acc=num_acc,
        state_names=tuple(names.get(i, "") for i in range(max(count, 1))),
        formula=formula,
        state_based=state_based,
        letters=letters,
    )


def _letters(values: list[list[Any]] | None, aps: list[str]) -> tuple[tuple[str, ...], ...] | None:
    """The ``tlmpc-letters:`` header (a count, then each letter as AP indices in a string)."""
    if not values or not values[0]:
        return None
    out = []
    for value in values[0][1:]:
        indices = _unquote(str(value)).split()
        out.append(tuple(aps[int(i)] for i in indices if i.isdigit() and int(i) < len(aps)))
    return tuple(out)


def _check(
    acceptance: list[Any],
    num_acc: int,
    aps: list[str],
    count: int,
    starts: list[list[Any]],
    edges: list[Edge],
    file: str | None,
) -> None:
    """Reject what the reader cannot represent faithfully (B003), instead of misreading it."""
    from lark import Tree

    condition = "".join(
        str(v.children[0]) if isinstance(v, Tree) else str(v) for v in acceptance[1:]
    )
    expected = "&".join(f"Inf({i})" for i in range(num_acc)) if num_acc else "t"
    problems: list[str] = []
    if condition and condition != expected and not (num_acc == 0 and condition == "t"):
        problems.append(
            f"acceptance condition {condition!r} is not generalized Büchi ({expected!r})"
        )
    if len(starts) != 1 or len(starts[0]) != 1:
        problems.append("exactly one initial state is supported")
    elif not 0 <= int(str(starts[0][0])) < max(count, 1):
        problems.append(f"initial state {starts[0][0]} is out of range")
    for edge in edges:
        if not 0 <= edge.dst < count:
            problems.append(f"edge {edge.src} -> {edge.dst}: no state {edge.dst}")
        if any(m >= num_acc for m in edge.marks) and num_acc:
            problems.append(f"edge {edge.src} -> {edge.dst}: acceptance set out of range")
    if problems:
        raise InvalidInputError(
            [
                error("B003", p, hint="tlmpc reads (generalized) Büchi HOA", file=file)
                for p in problems
            ]
        )


def to_dot(automaton: Automaton) -> str:
    """Graphviz DOT of the automaton (acceptance marks as {i} on edges or double circles)."""
    lines = [
        "digraph automaton {",
        "  rankdir=LR;",
        "  node [shape=circle, fontsize=10];",
        '  init [shape=point, label=""];',
        f"  init -> {automaton.initial};",
    ]
    accepting = {e.src for e in automaton.edges if automaton.state_based and e.marks}
    for state in range(automaton.num_states):
        shape = "doublecircle" if state in accepting else "circle"
        name = automaton.state_names[state] if state < len(automaton.state_names) else ""
        label = f"{state}\\n{_escaped(name)}"  # a DOT line break, then the name
        lines.append(f'  {state} [shape={shape}, label="{label}"];')
    for edge in automaton.edges:
        label = to_text(edge.guard)
        if edge.marks and not automaton.state_based:
            label += " {" + ",".join(str(m) for m in sorted(edge.marks)) + "}"
        label = _escaped(label)
        lines.append(f'  {edge.src} -> {edge.dst} [label="{label}"];')
    lines.append("}")
    return "\n".join(lines) + "\n"
