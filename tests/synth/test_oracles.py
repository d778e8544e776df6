"""Random small GR(1) games: realizability agrees with two independent solvers, and every
strategy wins by an explicit-state check.

* Spot (``spot.ltl_to_game`` / ``solve_game``, Mealy like the game) decides the LTL formula of
  the game's strict reading, ``theta_e -> (theta_s /\\ (rho_s W ~rho_e) /\\ ((G rho_e /\\
  GF J^e) -> GF J^s))``, which is exactly what the GR(1) game decides.
* gr1py (an enumerative GR(1) solver that reads gr1c's format) solves the same ``.spc`` text
  under gr1c's default initial condition.

Unrealizable games get a counterstrategy checked the same way, and a core that Spot finds
unrealizable, each of whose parts Spot finds necessary.

Formulas are printed fully parenthesised so that no two tools' precedence rules can differ.
"""

from __future__ import annotations

import pytest
from game_oracle import (
    check_counterstrategy,
    check_strategy,
    holds,
    strict_ltl_of,
    valuations,
)
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tlmpc.synth.core import minimal_core
from tlmpc.synth.counter import extract_counterstrategy
from tlmpc.synth.readers.gr1c import parse_gr1c
from tlmpc.synth.solver import Game, solve
from tlmpc.synth.spec import GameSpec
from tlmpc.synth.strategy import extract

spot = pytest.importorskip("spot")
gr1py_cli = pytest.importorskip("gr1py.cli")
gr1py_solve = pytest.importorskip("gr1py.solve")

ENV = ("e0", "e1")
SYS = ("s0", "s1")

# a formula is a tuple tree: ("v", name, primed) | ("c", bool) | ("!", a) | (op, a, b)
Tree = tuple[object, ...]


def formulas(atoms: list[tuple[str, bool]], depth: int = 3) -> st.SearchStrategy[Tree]:
    leaves = st.one_of(
        st.sampled_from([("v", name, primed) for name, primed in atoms]),
        st.sampled_from([("c", True), ("c", False)]),
    )
    return st.recursive(
        leaves,
        lambda inner: st.one_of(
            st.tuples(st.just("!"), inner),
            st.tuples(st.sampled_from(["&", "|", "->", "<->"]), inner, inner),
        ),
        max_leaves=depth + 2,
    )


def gr1c_text(tree: Tree) -> str:
    kind = tree[0]
    if kind == "v":
        return f"{tree[1]}{chr(39) if tree[2] else ''}"
    if kind == "c":
        return "True" if tree[1] else "False"
    if kind == "!":
        return f"!({gr1c_text(tree[1])})"  # type: ignore[arg-type]
    return f"({gr1c_text(tree[1])} {kind} {gr1c_text(tree[2])})"  # type: ignore[arg-type]


def ltl_text(tree: Tree) -> str:
    kind = tree[0]
    if kind == "v":
        return f"X({tree[1]})" if tree[2] else str(tree[1])
    if kind == "c":
        return "1" if tree[1] else "0"
    if kind == "!":
        return f"!({ltl_text(tree[1])})"  # type: ignore[arg-type]
    return f"({ltl_text(tree[1])} {kind} {ltl_text(tree[2])})"  # type: ignore[arg-type]


current = [(n, False) for n in ENV + SYS]
games = st.fixed_dictionaries(
    {
        "env_init": st.lists(formulas([(n, False) for n in ENV]), max_size=1),
        "sys_init": st.lists(formulas([(n, False) for n in SYS]), max_size=1),
        "env_trans": st.lists(formulas(current + [(n, True) for n in ENV]), max_size=2),
        "sys_trans": st.lists(formulas(current + [(n, True) for n in ENV + SYS]), max_size=2),
        "env_goal": st.lists(formulas(current), max_size=2),
        "sys_goal": st.lists(formulas(current), max_size=2),
    }
)


def spc(game: dict[str, list[Tree]]) -> str:
    def section(name: str, trees: list[Tree], lead: str) -> str:
        return f"{name}: " + " & ".join(f"{lead}{gr1c_text(t)}" for t in trees) + ";\n"

    return (
        f"ENV: {' '.join(ENV)};\nSYS: {' '.join(SYS)};\n"
        + section("ENVINIT", game["env_init"], "")
        + section("SYSINIT", game["sys_init"], "")
        + section("ENVTRANS", game["env_trans"], "[]")
        + section("SYSTRANS", game["sys_trans"], "[]")
        + section("ENVGOAL", game["env_goal"], "[]<>")
        + section("SYSGOAL", game["sys_goal"], "[]<>")
    )


def strict_ltl(game: dict[str, list[Tree]]) -> str:
    def conj(trees: list[Tree]) -> str:
        return " & ".join(f"({ltl_text(t)})" for t in trees) or "1"

    env_safety, sys_safety = conj(game["env_trans"]), conj(game["sys_trans"])
    assumption = " & ".join(
        [f"G({env_safety})"] + [f"G F({ltl_text(t)})" for t in game["env_goal"]]
    )
    guarantee = " & ".join(f"G F({ltl_text(t)})" for t in game["sys_goal"]) or "1"
    return (
        f"({conj(game['env_init'])}) -> (({conj(game['sys_init'])}) & "
        f"(({sys_safety}) W !({env_safety})) & (({assumption}) -> ({guarantee})))"
    )


def spot_realizable(formula: str) -> bool:
    info = spot.synthesis_info()
    arena = spot.ltl_to_game(spot.formula(formula), list(SYS), info)
    return bool(spot.solve_game(arena))


def _no_dead_ends(spec: GameSpec) -> bool:
    everything = spec.owned("env") + spec.owned("sys")
    env_safety, sys_safety = spec.select("env", "safety"), spec.select("sys", "safety")
    return all(
        any(holds(env_safety, s, t) and holds(sys_safety, s, t) for t in valuations(everything))
        for s in valuations(everything)
    )


@settings(
    max_examples=40,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
@given(games)
def test_agrees_with_spot_and_gr1py(game: dict[str, list[Tree]]) -> None:
    text = spc(game)
    spec = parse_gr1c(text, file="random.spc")
    solution = solve(Game.build(spec))
    assert solution.realizable == spot_realizable(strict_ltl(game)), text
    if _no_dead_ends(spec):  # gr1py fails on a state without successors
        tsys, exprtab = gr1py_cli.loads(text)
        assert solution.realizable == bool(gr1py_solve.check_realizable(tsys, exprtab)), text
    if solution.realizable:
        check_strategy(spec, extract(solution))
    else:
        check_counterstrategy(spec, extract_counterstrategy(solution))
        core = minimal_core(spec)
        assumptions = tuple(p for p in spec.parts if p.owner == "env")
        assert not spot_realizable(strict_ltl_of(spec.with_parts(assumptions + core.parts)))
        for dropped in core.parts:
            rest = tuple(p for p in core.parts if p is not dropped)
            assert spot_realizable(strict_ltl_of(spec.with_parts(assumptions + rest))), (
                f"the core is not minimal: {dropped.text} can go"
            )
