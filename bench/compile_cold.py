"""Run one tlmpc command in this fresh interpreter and print what it cost as JSON.

``python bench/compile_cold.py ARGS...`` runs ``tlmpc ARGS`` (e.g. ``compile M -o OUT -q``) and
prints one JSON line: exit code, seconds since the interpreter started importing tlmpc, CPU
seconds of the process (less sensitive than wall time to other jobs on the machine), its peak
RSS, and ``summary.json`` when the command was a compile.  The caller measures the wall time
of the whole process, interpreter start-up included.
"""

from __future__ import annotations

import io
import json
import resource
import sys
import time
from pathlib import Path


def main() -> None:
    argv = sys.argv[1:]
    started = time.perf_counter()
    from tlmpc.cli import main as tlmpc_main

    out, err = io.StringIO(), io.StringIO()
    code = tlmpc_main(argv, out, err)
    seconds = time.perf_counter() - started
    usage = resource.getrusage(resource.RUSAGE_SELF)
    summary = None
    if argv and argv[0] == "compile" and code == 0 and "-o" in argv:
        summary_path = Path(argv[argv.index("-o") + 1]) / "summary.json"
        summary = json.loads(summary_path.read_text(encoding="utf-8"))
    print(
        json.dumps(
            {
                "exit": code,
                "seconds": seconds,
                "cpu_seconds": usage.ru_utime + usage.ru_stime,
                "peak_rss_mb": usage.ru_maxrss / 1024.0,
                "summary": summary,
                "stderr": err.getvalue()[-2000:],
            }
        )
    )


if __name__ == "__main__":
    main()
