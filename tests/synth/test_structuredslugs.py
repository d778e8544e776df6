"""slugs' structured format: published answers, slugs' own translation as the oracle of the
format's meaning, and located refusals.

The oracle is slugs' compiler (tests/synth/slugs/compiler, run as a program): it translates a
``.structuredslugs`` file into ``.slugsin`` over the integer variables' bits.  Each part read
by tlmpc must hold on exactly the valuations where slugs' translation of the same line holds
(evaluated bit by bit by the definition-level evaluator, every valuation enumerated), and the
whole specification must get the same answer.
"""

from __future__ import annotations

import itertools
import operator
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest
from game_oracle import evaluate, mentioned
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tlmpc.base.errors import UsageError
from tlmpc.synth.readers import read_spec
from tlmpc.synth.readers.slugsin import parse_slugsin
from tlmpc.synth.readers.structuredslugs import CompareOp, parse_structuredslugs
from tlmpc.synth.solver import Game, solve
from tlmpc.synth.spec import Compare, Expr, GameSpec, Linear, Part, Variable

HERE = Path(__file__).resolve().parent / "slugs"
#: every example but basicEvasion (a 24 x 8 grid with a moving obstacle: realizable, but its
#: solve alone takes about half a minute, twice over here)
EXAMPLES = sorted(
    p for p in (HERE / "examples").glob("*.structuredslugs") if p.stem != "basicEvasion"
)
#: slugs' tools/testSomeExamples.py
PUBLISHED = {
    "water_reservoir": True,
    "maximallyPermissiveTestPre": True,
    "maximallyPermissiveTest": True,
}


def slugs_translation(path: Path) -> str:
    """slugs' compiler's ``.slugsin`` for ``path``."""
    done = subprocess.run(
        [sys.executable, str(HERE / "compiler" / "compiler.py"), str(path)],
        capture_output=True,
        text=True,
        check=True,
        cwd=HERE / "compiler",
    )
    return done.stdout


def test_every_published_answer() -> None:
    for name, realizable in PUBLISHED.items():
        spec = read_spec(str(HERE / "examples" / f"{name}.structuredslugs"))
        assert solve(Game.build(spec)).realizable == realizable, name


@pytest.mark.slow
@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_the_answer_is_that_of_slugs_translation(path: Path, tmp_path: Path) -> None:
    ours = read_spec(str(path))
    translated = parse_slugsin(slugs_translation(path), file="translated.slugsin")
    assert solve(Game.build(ours)).realizable == solve(Game.build(translated)).realizable


# --- each line means what slugs' translation means --------------------------------------------

INTS = {"x": (0, 3), "y": (2, 4), "z": (1, 1)}
BOOLS = ("a", "b")


def _atoms(primed: bool) -> st.SearchStrategy[str]:
    tick = "'" if primed else ""
    return st.sampled_from([f"{b}{tick}" for b in BOOLS] + ["TRUE", "FALSE"])


def _sums(primed: bool) -> st.SearchStrategy[str]:
    tick = "'" if primed else ""
    term = st.one_of(st.sampled_from([f"{v}{tick}" for v in INTS]), st.integers(0, 6).map(str))
    return st.lists(term, min_size=1, max_size=3).map(lambda ts: " + ".join(ts))


def _comparisons(primed: bool) -> st.SearchStrategy[str]:
    return st.tuples(
        _sums(primed), st.sampled_from(["=", "!=", "<", "<=", ">", ">="]), _sums(primed)
    ).map(lambda t: f"{t[0]} {t[1]} {t[2]}")


def _formulas(primed: bool) -> st.SearchStrategy[str]:
    leaves = st.one_of(_atoms(primed), _comparisons(primed))
    return st.recursive(
        leaves,
        lambda inner: st.one_of(
            inner.map(lambda f: f"!({f})"),
            st.tuples(
                # no ^: slugs' grammar has it, but its compiler stops at it
                inner,
                st.sampled_from(["&", "|", "->", "<->", "/\\", "\\/"]),
                inner,
            ).map(lambda t: f"({t[0]} {t[1]} {t[2]})"),
        ),
        max_leaves=4,
    )


def _with_next(now: str, then: str) -> str:
    return f"({now}) & X({then})"


lines = st.lists(
    st.one_of(
        _formulas(False),
        _formulas(True),
        st.tuples(_formulas(False), _formulas(False)).map(lambda t: _with_next(*t)),
    ),
    min_size=1,
    max_size=8,
)


def _document(body: list[str]) -> str:
    ints = "\n".join(f"{v}: {low}...{high}" for v, (low, high) in INTS.items())
    return (
        f"[INPUT]\n{BOOLS[0]}\n{ints}\n\n[OUTPUT]\n{BOOLS[1]}\n\n[SYS_TRANS]\n"
        + "\n".join(body)
        + "\n"
    )


def _user_parts(spec: GameSpec, count: int) -> list[Part]:
    return [p for p in spec.parts if p.kind == "safety" and p.owner == "sys"][:count]


def _states(varied: set[str]) -> list[dict[str, int | bool]]:
    """Every valuation of the variables in ``varied``, the others at their lowest value."""
    domains: list[list[int | bool]] = [[False, True] for _ in BOOLS]
    domains += [list(range(low, high + 1)) for low, high in INTS.values()]
    names = list(BOOLS) + list(INTS)
    domains = [d if n in varied else d[:1] for n, d in zip(names, domains, strict=True)]
    return [dict(zip(names, combo, strict=True)) for combo in itertools.product(*domains)]


def _read(*formulas: Expr) -> tuple[set[str], set[str]]:
    """The variables (a bit ``x@1`` read as its integer ``x``) whose current and whose next
    value any of ``formulas`` reads: no formula depends on the others."""
    names = set().union(*(mentioned(f) for f in formulas))
    now = {name.partition("@")[0] for name, primed in names if not primed}
    after = {name.partition("@")[0] for name, primed in names if primed}
    return now, after


def _bits(state: dict[str, int | bool], names: list[str]) -> dict[str, bool]:
    """The slugs translation's bit variables (``x@0.0.3``, ``x@1``, ...) of a state."""
    values: dict[str, bool] = {b: bool(state[b]) for b in BOOLS}
    for name in names:
        base, _, rest = name.partition("@")
        if not rest:
            continue
        index = int(rest.split(".")[0])
        low = INTS[base][0]
        values[name] = bool(((int(state[base]) - low) >> index) & 1)
    return values


@pytest.mark.slow
@settings(
    max_examples=25,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
@given(body=lines)
def test_each_line_means_what_slugs_translation_means(
    body: list[str], tmp_path_factory: pytest.TempPathFactory
) -> None:
    text = _document(body)
    path = tmp_path_factory.mktemp("structured") / "random.structuredslugs"
    path.write_text(text)
    ours = _user_parts(parse_structuredslugs(text, file=str(path)), len(body))
    theirs_spec = parse_slugsin(slugs_translation(path), file="translated.slugsin")
    theirs = _user_parts(theirs_spec, len(body))
    assert len(ours) == len(theirs) == len(body)
    bit_names = [v.name for v in theirs_spec.variables]
    for mine, slugs, line in zip(ours, theirs, body, strict=True):
        # every valuation of what either side reads (the rest changes neither side's truth)
        now_read, after_read = _read(mine.formula, slugs.formula)
        afters = [(after, _bits(after, bit_names)) for after in _states(after_read)]
        for now in _states(now_read):
            now_bits = _bits(now, bit_names)
            for after, after_bits in afters:
                assert evaluate(mine.formula, now, after) == evaluate(
                    slugs.formula, now_bits, after_bits
                ), (line, now, after)


# --- refusals ------------------------------------------------------------------------------

REFUSED = [
    ("[INPUT]\nx: 0...3\n[SYS_TRANS]\nx' = x - 1\n", "Q135", 4, 8),
    ("[INPUT]\nx: 0...3\n[SYS_TRANS]\nx' = x * 2\n", "Q135", 4, 8),
    ("[INPUT]\na\n[SYS_LIVENESS]\nG F a\n", "Q134", 4, 1),
    ("[INPUT]\na\n[SYS_TRANS]\na U a\n", "Q134", 4, 3),
    ("[INPUT]\na\n[SYS_TRANS]\nX(a')\n", "Q134", 4, 3),
    ("[INPUT]\na\n[SYS_TRANS]\nX X a\n", "Q134", 4, 3),
    ("[INPUT]\na\n[SYS_TRANS]\na & c\n", "Q133", 4, 5),
    ("[INPUT]\na\nx: 0...3\n[SYS_TRANS]\nx & a\n", "Q130", 5, 3),
    ("[INPUT]\na\n[SYS_TRANS]\na + 1 = 2\n", "Q130", 4, 3),
    ("[INPUT]\na\n[SYS_TRANS]\n(a & a\n", "Q130", 4, 7),
    ("[INPUT]\nx: 3...1\n", "Q132", 2, 4),
    ("[INPUT]\nx: 0..3\n", "Q132", 2, 4),
    ("[INPUT]\nx\nx\n", "Q132", 3, 1),
    ("[OBSERVABLE_INPUT]\nx\n", "Q131", 1, 1),
    ("[WHATEVER]\n", "Q131", 1, 1),
    ("a\n[INPUT]\n", "Q131", 1, 1),
    ("[OUTPUT]\ny\n[ENV_INIT]\n!y & TRUE\n", "Q136", 4, 2),
    # a line that is already prefix is read by the slugsin reader, with its codes
    ("[OUTPUT]\ny\n[ENV_INIT]\ny\n", "Q035", 4, 1),
    ("[OUTPUT]\ny: 0...2\n[ENV_TRANS]\ny' = 1\n", "Q136", 4, 1),
    ("[INPUT]\nx: 0...3\n[SYS_TRANS]\nx@0 = 1\n", "Q135", 4, 1),
]


@pytest.mark.parametrize(("text", "code", "line", "col"), REFUSED)
def test_refusals_are_located(text: str, code: str, line: int, col: int) -> None:
    with pytest.raises(UsageError) as caught:
        parse_structuredslugs(text, file="bad.structuredslugs")
    found = caught.value.diagnostics[0]
    assert (found.code, found.line, found.col) == (code, line, col), found


def test_precedence_and_associativity_follow_slugs() -> None:
    """``->`` is left-associative in slugs' grammar: ``a -> b -> c`` is ``(a -> b) -> c``;
    ``&`` binds tighter than ``|``, ``|`` than ``^``, ``^`` than ``->``."""
    text = "[INPUT]\na\nb\nc\n[SYS_TRANS]\na -> b -> c\na | b & c\na ^ b | c\n"
    parts = parse_structuredslugs(text).parts
    for state in itertools.product([False, True], repeat=3):
        a, b, c = state
        values = {"a": a, "b": b, "c": c}
        assert evaluate(parts[0].formula, values) == ((not ((not a) or b)) or c)
        assert evaluate(parts[1].formula, values) == (a or (b and c))
        assert evaluate(parts[2].formula, values) == (a != (b or c))


ARITHMETIC = """\
[INPUT]
x: 0...3
y: 2...4
[OUTPUT]
b
[SYS_TRANS]
x' = x + 1
x' + 1 = x
x + y >= 5 & x' + x' < y + 2
(x + 2) + y' != 7 -> b'
X(y = x + 2) | b
3 + 4 = 7
"""


def test_arithmetic_lines_mean_exact_sums() -> None:
    """Each line against Python's own arithmetic, and its BDD against the evaluator on every
    valuation (the encoding of sums by partial sums)."""
    from tlmpc.synth.strategy import bits_of
    from tlmpc.synth.symbolic import Encoding

    spec = parse_structuredslugs(ARITHMETIC, file="a.structuredslugs")
    parts = [p for p in spec.parts if p.kind == "safety" and p.owner == "sys"]
    State = dict[str, int | bool]
    expected: list[Callable[[State, State], bool]] = [
        lambda n, a: a["x"] == n["x"] + 1,
        lambda n, a: a["x"] + 1 == n["x"],
        lambda n, a: n["x"] + n["y"] >= 5 and 2 * a["x"] < n["y"] + 2,
        lambda n, a: (n["x"] + 2 + a["y"] == 7) or bool(a["b"]),
        lambda n, a: a["y"] == a["x"] + 2 or bool(n["b"]),
        lambda n, a: True,
    ]
    enc = Encoding(spec)
    states = [
        {"x": x, "y": y, "b": b} for x in range(4) for y in range(2, 5) for b in (False, True)
    ]
    for part, python in zip(parts, expected, strict=True):
        u = enc.part(part)
        for now in states:
            for after in states:
                truth = python(now, after)
                assert evaluate(part.formula, now, after) == truth, (part.text, now, after)
                bits = {**bits_of(enc, now, False), **bits_of(enc, after, True)}
                assert (enc.bdd.let(bits, u) == enc.bdd.true) == truth, (part.text, now, after)


# --- integer comparisons on the bits --------------------------------------------------------

#: odd lows, a range of one value, a range that fills its bits and one that does not
_LINEAR_VARS = (
    Variable("p", "env", 3, 8),
    Variable("q", "sys", 0, 7),
    Variable("r", "sys", 5, 5),
    Variable("s", "env", 2, 4),
)
_OPS = ["=", "!=", "<", "<=", ">", ">="]
_terms = st.lists(
    st.tuples(
        st.integers(-3, 3).filter(bool),
        st.sampled_from([v.name for v in _LINEAR_VARS]),
        st.booleans(),
    ),
    min_size=0,
    max_size=3,
)


@settings(max_examples=120, deadline=None)
@given(terms=_terms, op=st.sampled_from(_OPS), value=st.integers(-30, 30))
def test_linear_comparisons_match_brute_force(
    terms: list[tuple[int, str, bool]], op: CompareOp, value: int
) -> None:
    """Every bit pattern of the variables read (out-of-range ones included) against Python's
    arithmetic, for sums and for gr1c's single-variable comparisons."""
    from tlmpc.synth.symbolic import Encoding

    spec = GameSpec(_LINEAR_VARS, (), "forall_env_exists_sys", "structuredslugs", "t")
    enc = Encoding(spec)
    nodes: list[Expr] = [Linear(tuple(terms), op, value)]
    if len(terms) == 1 and terms[0][0] == 1:
        nodes.append(Compare(terms[0][1], op, value, terms[0][2]))
    test = {
        "=": operator.eq,
        "!=": operator.ne,
        "<": operator.lt,
        "<=": operator.le,
        ">": operator.gt,
        ">=": operator.ge,
    }[op]
    ranges = {v.name: (v.low or 0, v.high or 0) for v in _LINEAR_VARS}
    read = sorted({(name, primed) for _, name, primed in terms})
    bits = [(enc.next_bits if primed else enc.bits)[name] for name, primed in read]
    for node in nodes:
        u = enc.expr(node)
        for offsets in itertools.product(*(range(1 << len(b)) for b in bits)):
            values = {
                key: ranges[key[0]][0] + offset for key, offset in zip(read, offsets, strict=True)
            }
            inside = all(values[name, primed] <= ranges[name][1] for name, primed in read)
            total = sum(coef * values[name, primed] for coef, name, primed in terms)
            assignment = {
                bit: bool((offset >> k) & 1)
                for names, offset in zip(bits, offsets, strict=True)
                for k, bit in enumerate(names)
            }
            holds = enc.bdd.let(assignment, u) == enc.bdd.true
            assert holds == (inside and test(total, value)), (node, values)


def test_comparisons_over_huge_ranges_are_built_on_the_bits() -> None:
    """Ranges of a trillion values: the number of solutions is known, and the game of a
    counter that must visit 7 is realizable (a loop over the values would never finish)."""
    from tlmpc.synth.symbolic import Encoding

    big = 10**12
    text = f"[INPUT]\nx\n[OUTPUT]\nn: 0...{big}\nm: 0...{big}\n[SYS_LIVENESS]\nn = 7\n"
    spec = parse_structuredslugs(text, file="big.structuredslugs")
    assert solve(Game.build(spec)).realizable
    enc = Encoding(spec)
    width = 2 * len(enc.bits["n"])
    pairs = enc.expr(Linear(((1, "n", False), (1, "m", False)), "=", big + 1))
    assert enc.bdd.count(pairs, nvars=width) == big
    thirds = enc.expr(Linear(((3, "n", False),), "<=", big))
    assert enc.bdd.count(thirds, nvars=width // 2) == big // 3 + 1
    above = enc.expr(Compare("m", ">", big - 5))
    assert enc.bdd.count(above, nvars=width // 2) == 5
