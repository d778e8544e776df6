"""GR(1) synthesis benchmark: SYNTCOMP's robot-grid family (gr_1 .. gr_4), tlmpc against omega.

Each solver runs in a child process on the same TLSF file in the same run; the table gives each
child's CPU time (user + system: reading, building the BDDs, solving, the realizability check)
and the answer.  omega (with the same ``dd`` CUDD bindings) gets the very game tlmpc reads: the
parts of tlmpc's IR printed in omega's TLA+ syntax, env goals as omega's ``<>[]`` complements,
Mealy, the standard (not plus-one) controllable predecessor, ``\\A \\E`` initial condition.
The suite lives in ``$TLMPC_SHARED_BENCHMARKS/gr1`` (else ``../shared/benchmarks/gr1`` beside
the repository); omega is optional (``pip install omega``): without it its columns stay empty.

    python -m bench.bench_synth [--files gr_1 gr_2] [--no-omega]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
from pathlib import Path
from typing import Any

from bench.tables import markdown_table

ROOT = Path(__file__).resolve().parent.parent
FAMILY = "syntcomp-robot-grid/non_parametric"

_TLMPC = """
import json, sys, time
from tlmpc.synth.readers import read_spec
from tlmpc.synth.solver import Game, solve
spec = read_spec(sys.argv[1])
solution = solve(Game.build(spec), keep_layers=False)
print(json.dumps({"realizable": solution.realizable, "cpre": solution.cpre_count}))
"""

_OMEGA = """
import json, sys
from omega.games import gr1
from omega.symbolic import temporal as trl
from tlmpc.synth.readers import read_spec
from tlmpc.synth.spec import Atom, Binary, Const, Nary, Not

def tla(e):
    if isinstance(e, Const):
        return "TRUE" if e.value else "FALSE"
    if isinstance(e, Atom):
        return e.name + ("'" if e.primed else "")
    if isinstance(e, Not):
        return "~ (" + tla(e.arg) + ")"
    if isinstance(e, Nary):
        op = {"and": r" /\\ ", "or": r" \\/ ", "xor": " # "}[e.op]
        return "(" + op.join("(" + tla(a) + ")" for a in e.args) + ")"
    op = " => " if e.op == "->" else " <=> "
    return "((" + tla(e.left) + ")" + op + "(" + tla(e.right) + "))"

def conj(parts):
    return r" /\\ ".join("(" + tla(p.formula) + ")" for p in parts) or "TRUE"

spec = read_spec(sys.argv[1])
aut = trl.Automaton()
aut.declare_variables(**{v.name: "bool" for v in spec.variables})
aut.varlist["env"] = [v.name for v in spec.owned("env")]
aut.varlist["sys"] = [v.name for v in spec.owned("sys")]
aut.init["env"] = conj(spec.select("env", "init"))
aut.init["sys"] = conj(spec.select("sys", "init"))
aut.action["env"] = conj(spec.select("env", "safety"))
aut.action["sys"] = conj(spec.select("sys", "safety"))
env_goals = [p for p in spec.select("env", "liveness")]
sys_goals = [p for p in spec.select("sys", "liveness")]
aut.win["<>[]"] = aut.bdds_from(*["~ (" + tla(p.formula) + ")" for p in env_goals] or ["FALSE"])
aut.win["[]<>"] = aut.bdds_from(*[tla(p.formula) for p in sys_goals] or ["TRUE"])
aut.qinit = r"\\A \\E"
aut.moore = False
aut.plus_one = False
z, _, _ = gr1.solve_streett_game(aut)
print(json.dumps({"realizable": bool(gr1.is_realizable(z, aut))}))
"""


def suite() -> Path:
    """The benchmark folder of the robot-grid family."""
    base = os.environ.get("TLMPC_SHARED_BENCHMARKS") or str(ROOT.parent / "shared" / "benchmarks")
    return Path(base) / "gr1" / FAMILY


def child(code: str, path: Path) -> tuple[dict[str, Any] | None, float]:
    """Run ``code`` on ``path`` in a fresh interpreter: its JSON answer and CPU seconds."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    done = subprocess.run(
        [sys.executable, "-c", code, str(path)], capture_output=True, text=True, check=False
    )
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    seconds = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if done.returncode != 0:
        sys.stderr.write(done.stderr[-2000:])
        return None, seconds
    return json.loads(done.stdout.strip().splitlines()[-1]), seconds


def main(argv: list[str] | None = None) -> int:
    """Print the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--files", nargs="*", default=["gr_1", "gr_2", "gr_3", "gr_4"])
    parser.add_argument("--no-omega", action="store_true")
    args = parser.parse_args(argv)
    folder = suite()
    if not folder.is_dir():
        print(f"the robot-grid suite is absent ({folder})")
        return 0
    try:
        import omega  # noqa: F401

        with_omega = not args.no_omega
    except ImportError:
        with_omega = False
    rows: list[dict[str, Any]] = []
    for name in args.files:
        path = folder / f"{name}.tlsf"
        ours, our_cpu = child(_TLMPC, path)
        row: dict[str, Any] = {
            "file": path.name,
            "tlmpc": "realizable" if ours and ours["realizable"] else "unrealizable",
            "tlmpc CPU s": round(our_cpu, 2),
        }
        if ours is None:
            row["tlmpc"] = "failed"
        if with_omega:
            theirs, their_cpu = child(_OMEGA, path)
            row["omega"] = (
                "failed"
                if theirs is None
                else "realizable"
                if theirs["realizable"]
                else "unrealizable"
            )
            row["omega CPU s"] = round(their_cpu, 2)
            row["tlmpc / omega"] = round(our_cpu / their_cpu, 3) if their_cpu else ""
        rows.append(row)
        print(markdown_table([row]).splitlines()[-1], file=sys.stderr, flush=True)
    print(markdown_table(rows))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
