"""Every external GR(1) benchmark with a published answer gets that answer.

The suites live in ``$TLMPC_SHARED_BENCHMARKS/gr1``, else ``<repo>/../shared/benchmarks/gr1``
(their README lists the published answers and where they come from); the tests skip cleanly
where the folder is absent.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from game_oracle import check_counterstrategy, check_strategy

from tlmpc.synth.counter import extract_counterstrategy
from tlmpc.synth.readers import read_spec
from tlmpc.synth.readers.gr1c import parse_gr1c
from tlmpc.synth.solver import Game, solve
from tlmpc.synth.spec import InitMode
from tlmpc.synth.strategy import extract, to_json
from tlmpc.synth.symbolic import Encoding

ROOT = Path(__file__).resolve().parents[2]
SUITES = (
    Path(os.environ.get("TLMPC_SHARED_BENCHMARKS") or ROOT.parent / "shared" / "benchmarks") / "gr1"
)

GR1C = "gr1c/tests/specs"
SLUGS = "slugs/examples"
GRID = "syntcomp-robot-grid/non_parametric"

#: (file, initial-state quantification, published answer), from each suite's upstream tests
PUBLISHED: list[tuple[str, InitMode, bool]] = [
    (f"{GR1C}/gridworld_bool.spc", "forall_env_exists_sys", True),
    (f"{GR1C}/gridworld_env.spc", "forall_env_exists_sys", True),
    (f"{GR1C}/arbiter4.spc", "forall_env_exists_sys", True),
    (f"{GR1C}/trivial_2var.spc", "forall_env_exists_sys", True),
    (f"{GR1C}/free_counter.spc", "forall_env_exists_sys", True),
    (f"{GR1C}/empty.spc", "forall_env_exists_sys", True),
    (f"{GR1C}/trivial_mustblock.spc", "forall_env_exists_sys", True),
    (f"{GR1C}/trivial_un.spc", "forall_env_exists_sys", False),
    (f"{GR1C}/trivial_partwin.spc", "all_init", False),
    (f"{SLUGS}/networks.slugsin", "forall_env_exists_sys", True),
    (f"{SLUGS}/optimisticRecoveryTest.slugsin", "forall_env_exists_sys", True),
    (f"{SLUGS}/semantics_diference.slugsin", "forall_env_exists_sys", True),
    (f"{SLUGS}/simple_safety_example.slugsin", "forall_env_exists_sys", True),
    (f"{SLUGS}/firefighting.slugsin", "forall_env_exists_sys", True),
    (f"{SLUGS}/baby_network.slugsin", "forall_env_exists_sys", False),
    (
        f"{SLUGS}/example_outermost_fixed_point_unrealizability.slugsin",
        "forall_env_exists_sys",
        False,
    ),
]


#: SYNTCOMP's robot-grid family: every gr_*.tlsf is realizable (upstream README); seconds to
#: minutes each, hence slow
ROBOT_GRID = [f"{GRID}/gr_{n}.tlsf" for n in (1, 2, 3, 4)]


def _suite_file(relative: str) -> Path:
    path = SUITES / relative
    if not path.is_file():
        pytest.skip(f"the benchmark suite is absent ({path})")
    return path


@pytest.mark.parametrize(("relative", "mode", "answer"), PUBLISHED, ids=lambda v: str(v))
def test_published_answer(relative: str, mode: InitMode, answer: bool) -> None:
    spec = read_spec(str(_suite_file(relative)), init_mode=mode)
    assert solve(Game.build(spec)).realizable is answer


@pytest.mark.slow
@pytest.mark.parametrize("relative", ROBOT_GRID)
def test_robot_grid_is_realizable(relative: str) -> None:
    spec = read_spec(str(_suite_file(relative)))
    assert solve(Game.build(spec), keep_layers=False).realizable


SMALL_REALIZABLE = [r for r, _, answer in PUBLISHED if answer and "gridworld_bool" not in r]


@pytest.mark.parametrize("relative", SMALL_REALIZABLE)
def test_strategy_wins_by_explicit_check(relative: str) -> None:
    """The extracted Mealy machine wins, checked state by state and cycle by cycle."""
    spec = read_spec(str(_suite_file(relative)))
    solution = solve(Game.build(spec))
    check_strategy(spec, extract(solution))


UNREALIZABLE = [(r, mode) for r, mode, answer in PUBLISHED if not answer]


@pytest.mark.parametrize(("relative", "mode"), UNREALIZABLE)
def test_counterstrategy_defeats_every_system(relative: str, mode: InitMode) -> None:
    """The environment's counterstrategy, checked node by node and cycle by cycle."""
    spec = read_spec(str(_suite_file(relative)), init_mode=mode)
    check_counterstrategy(spec, extract_counterstrategy(solve(Game.build(spec))))


def test_the_strategy_does_not_depend_on_the_variable_order() -> None:
    """CUDD reorders variables dynamically; the written strategy must not change with it."""
    # the system may answer with a, with b or with both: only a fixed order of choice gives
    # the same answer whatever the BDD's variable order
    spec = parse_gr1c("ENV: x;\nSYS: a b;\nSYSTRANS: [](a' | b') & [](x' -> a' | b');\n")
    documents = []
    for reverse in (False, True):
        enc = Encoding(spec)
        names = sorted(enc.bdd.vars, key=enc.bdd.level_of_var)
        if reverse:
            enc.bdd.configure(reordering=False)
            enc.bdd.reorder({name: len(names) - 1 - k for k, name in enumerate(names)})
        documents.append(to_json(extract(solve(Game.build(spec, enc)))))
    assert documents[0] == documents[1]
