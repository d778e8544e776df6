"""``python -m bench.hostile [--quick] [NAME...]``: hostile inputs through the CLI, with time
and peak memory.

Each case runs ``tlmpc`` in a fresh process under a 3 GB address-space limit (so a runaway case
cannot take the machine down) and prints one row: exit code, wall seconds, peak RSS, and
whether the answer meets the bar (exit 0/1/2, no traceback, under 10 s of CPU and 2 GB).
``--quick`` leaves out the huge inputs (10^6-vertex boundaries, the 50 MB mission, hundreds of
MiB of comments, 10^7 zeros or CSV rows; none of their files is written) and runs the rest.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
LIMIT = 3 * 1024**3

VALID = """\
version: 1
workspace: {{boundary: {boundary}}}
regions: {{a: {{rect: [45, 45, 55, 55]}}}}
robot: {{start: [50, 50]}}
task: [visit a]
"""


def _ring(n: int) -> str:
    points = (
        f"[{50 + 40 * math.cos(2 * math.pi * k / n):.6f}, "
        f"{50 + 40 * math.sin(2 * math.pi * k / n):.6f}]"
        for k in range(n)
    )
    return "[" + ", ".join(points) + "]"


def _ring_points(n: int) -> list[list[float]]:
    return [
        [
            round(50 + 40 * math.cos(2 * math.pi * k / n), 6),
            round(50 + 40 * math.sin(2 * math.pi * k / n), 6),
        ]
        for k in range(n)
    ]


def _big_cases(put: Callable[[str, str | bytes], str], work: Path) -> list[tuple[str, list[str]]]:
    """Huge inputs: a 50 MB mission, 10^6-vertex boundaries written several ways (with mistakes
    deep inside), hundreds of MiB of comments, 10^7 zeros and a CSV log of 10^7 rows."""
    n = 10**6
    points = _ring_points(n)
    mission = {
        "version": 1,
        "workspace": {"boundary": points},
        "regions": {"a": {"rect": [45, 45, 55, 55]}},
        "robot": {"start": [50, 50]},
        "task": ["visit a"],
    }
    json_path = put("ring6.json", json.dumps(mission))
    bad: list[list[Any]] = [list(p) for p in points]
    bad[900_000] = [bad[900_000][0], "far"]
    bad_text = "[" + ",\n  ".join(json.dumps(p) for p in bad) + "]"
    crossed = [list(p) for p in points]
    crossed[950_000], crossed[950_500] = crossed[950_500], crossed[950_000]
    block = (
        "version: 1\nworkspace:\n  boundary:\n"
        + "\n".join(f"  - [{x}, {y}]" for x, y in points)
        + "\nregions: {a: {rect: [45, 45, 55, 55]}}\nrobot: {start: [50, 50]}\ntask: [visit a]\n"
    )
    with (work / "comment.yaml").open("w") as stream:
        stream.write(VALID.format(boundary="{rect: [0, 0, 100, 100]}"))
        line = "# " + "x" * 1022 + "\n"
        for _ in range(250 * 1024):  # 250 MiB of comment, under the 256 MiB limit
            stream.write(line)
    with (work / "over.yaml").open("w") as stream:
        for _ in range(260 * 1024):
            stream.write("# " + "x" * 1022 + "\n")
    rows = work / "rows.csv"
    with rows.open("w") as stream:
        for chunk in range(100):
            stream.write("".join(f"{chunk * 100_000 + i},0,0\n" for i in range(100_000)))
    spec = str(ROOT / "specs" / "example1.yaml")
    return [
        ("check 50 MB mission", ["check", put("big.yaml", "# " + "x" * (50 * 2**20) + "\n")]),
        (
            "check 10^6-vertex boundary",
            ["check", put("ring6.yaml", VALID.format(boundary=_ring(10**6)))],
        ),
        ("verify CSV 10^7 rows", ["verify", str(rows), "--mission", spec]),
        ("check 10^6-vertex boundary, JSON mission", ["check", json_path]),
        (
            "check 10^6 vertices, a bad point at 900,000",
            ["check", put("ring6-bad.yaml", VALID.format(boundary=bad_text))],
        ),
        (
            "check 10^6 vertices, a crossing at 950,000",
            [
                "check",
                put(
                    "ring6-cross.json", json.dumps({**mission, "workspace": {"boundary": crossed}})
                ),
            ],
        ),
        (
            "check 10^6 vertices, one `- [x, y]` per line",
            ["check", put("ring6-block.yaml", block)],
        ),
        (
            "check 10^7 zeros in one list",
            ["check", put("zeros.yaml", "a: [" + "0," * 10**7 + "0]\n")],
        ),
        ("check 250 MiB of comments", ["check", str(work / "comment.yaml")]),
        ("check 260 MiB file", ["check", str(work / "over.yaml")]),
    ]


def build(work: Path, *, quick: bool = False) -> list[tuple[str, list[str]]]:
    """The corpus: (name, argv) pairs, writing the input files into ``work``; ``quick`` leaves
    out the huge inputs and writes none of their files."""

    def put(name: str, text: str | bytes) -> str:
        path = work / name
        if isinstance(text, bytes):
            path.write_bytes(text)
        else:
            path.write_text(text, encoding="utf-8")
        return str(path)

    spec = str(ROOT / "specs" / "example1.yaml")
    bomb = ["a0: &a0 [x, x, x, x, x, x, x, x, x, x]"]
    bomb += [f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 10)}]" for i in range(1, 10)]
    regions = "\n".join(
        f"  r{i}: {{rect: [{1 + 3 * (i % 5)}, {1 + 3 * (i // 5)}, "
        f"{2 + 3 * (i % 5)}, {2 + 3 * (i // 5)}]}}"
        for i in range(20)
    )
    names = ", ".join(f"r{i}" for i in range(20))
    patrol = (
        "version: 1\nworkspace: {boundary: {rect: [0, 0, 16, 13]}}\nregions:\n"
        f"{regions}\nrobot: {{start: [0.5, 0.5]}}\ntask: ['patrol {names}']\n"
    )
    trace = {
        "format": "tlmpc.trace/1",
        "ltl": "G F a",
        "regions": {"a": [[0, 0], [2, 0], [2, 2], [0, 2]]},
        "workspace": {},
        "boundary": "right",
        "points": [[0, 5, 5], [1, 1, 1], [2, 1, 1.5]],
        "loop_start": 2,
        "max_speed": 0,
    }
    hostile_name = work / "hostile.yaml"
    hostile_name.write_text(
        (ROOT / "specs" / "example1.yaml")
        .read_text()
        .replace(
            "name: paper-example-1", 'name: "*/ init { c_code { system(\\"touch PWNED\\") } } /*"'
        )
    )
    exported = work / "exported"
    cases = [
        ("check /dev/zero", ["check", "/dev/zero"]),
        ("check alias bomb (10^10)", ["check", put("bomb.yaml", "\n".join(bomb) + "\n")]),
        (
            "check flow nesting 25,000",
            ["check", put("deep.yaml", "a: " + "[" * 25_000 + "]" * 25_000)],
        ),
        (
            "check 10^5-vertex boundary",
            ["check", put("ring5.yaml", VALID.format(boundary=_ring(10**5)))],
        ),
        (
            "check 1e-6",
            [
                "check",
                put(
                    "exp.yaml",
                    VALID.format(boundary="{rect: [0, 0, 100, 100]}").replace(
                        "[50, 50]}", "[50, 50], max_speed: 1e-6}"
                    ),
                ),
            ],
        ),
        (
            "check blank ltl",
            [
                "check",
                put(
                    "blank.yaml",
                    VALID.format(boundary="{rect: [0, 0, 100, 100]}").replace(
                        "task: [visit a]", 'ltl: "  "'
                    ),
                ),
            ],
        ),
        (
            "compile patrol over 20 regions",
            ["compile", put("patrol20.yaml", patrol), "-o", str(work / "p20"), "-q"],
        ),
        (
            "compile hostile name",
            ["compile", str(hostile_name), "-o", str(exported), "--until", "abstraction", "-q"],
        ),
        (
            "export promela (hostile name)",
            ["export", str(exported), "--format", "promela", "-o", str(work / "m.pml")],
        ),
        ("verify JSON nested 10^5", ["verify", put("deep.json", "[" * 10**5 + "]" * 10**5)]),
        (
            "verify 5,000-digit integer",
            ["verify", put("int.json", '{"format": "tlmpc.trace/1", "x": ' + "9" * 5000 + "}")],
        ),
        (
            "verify CSV field 200 KB",
            ["verify", put("wide.csv", "0," + "1" * 200_000 + ",1\n"), "--mission", spec],
        ),
        ("verify loop_start = last, max_speed 0", ["verify", put("last.json", json.dumps(trace))]),
        ("compile -o /proc/x", ["compile", spec, "-o", "/proc/tlmpc-x", "--until", "load", "-q"]),
    ]
    if quick:
        return cases
    return [*cases, *_big_cases(put, work)]


def _limit() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (LIMIT, LIMIT))


def run_case(argv: list[str], work: Path) -> tuple[int, float, float, float, str]:
    """Exit code, wall seconds, CPU seconds, peak RSS in MB, and the stderr of one run."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    started = time.perf_counter()
    process = subprocess.Popen(
        [sys.executable, "-m", "tlmpc", *argv],
        cwd=work,
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        preexec_fn=_limit,
    )
    assert process.stderr is not None
    err = process.stderr.read().decode(errors="replace")
    _, status, usage = os.wait4(process.pid, 0)
    process.returncode = os.waitstatus_to_exitcode(status)
    seconds = time.perf_counter() - started
    cpu = usage.ru_utime + usage.ru_stime
    return process.returncode, seconds, cpu, usage.ru_maxrss / 1024, err


def main(
    report: Callable[[str], object] = print, only: Sequence[str] = (), *, quick: bool = False
) -> int:
    """Run the corpus (the cases whose name contains one of ``only``, when given; without the
    huge inputs when ``quick``) and print the table; exit 1 when a case misses the bar."""
    failures = 0
    with tempfile.TemporaryDirectory() as folder:
        work = Path(folder)
        report("| case | exit | wall s | CPU s | peak MB | ok | first diagnostic |")
        report("|---|---|---|---|---|---|---|")
        for name, argv in build(work, quick=quick):
            if only and not any(part in name for part in only):
                continue
            code, seconds, cpu, peak, err = run_case(argv, work)
            # CPU time, not wall time, against the 10 s bar: the machine may be shared.
            ok = code in (0, 1, 2) and "Traceback" not in err and cpu < 10 and peak < 2048
            failures += not ok
            first = next((line for line in err.splitlines() if "[" in line), err[:60])
            first = first.split("]: ", 1)[0].rsplit(" ", 1)[-1] + "]" if "]: " in first else ""
            report(
                f"| {name} | {code} | {seconds:.2f} | {cpu:.2f} | {peak:.0f} | "
                f"{'yes' if ok else 'NO'} | {first} |"
            )
        pwned = any(work.rglob("PWNED"))
        report(f"\nPWNED file created: {pwned}")
    return 1 if failures or pwned else 0


if __name__ == "__main__":
    parser = argparse.ArgumentParser(prog="python -m bench.hostile", description=__doc__)
    parser.add_argument("names", nargs="*", metavar="NAME", help="run the cases naming this")
    parser.add_argument("--quick", action="store_true", help="leave out the huge inputs")
    args = parser.parse_args()
    raise SystemExit(main(only=args.names, quick=args.quick))
