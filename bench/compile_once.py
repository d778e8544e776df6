"""Run ``tlmpc compile`` twice in one fresh interpreter and print timings as JSON.

The first run is what a user's command line costs (``cold``: the imports of tlmpc, numpy,
scipy, clarabel, matplotlib ... included; only the interpreter's own start-up, about 40 ms, is
not); the second, with the libraries loaded, is the compiler's own work (``warm``).  Peak RSS
is the process's.
"""

from __future__ import annotations

import io
import json
import resource
import sys
import time


def _compile(mission: str, out: str) -> tuple[int, float, dict[str, object] | None, str]:
    started = time.perf_counter()  # before the import: a cold run pays for every import
    from tlmpc.cli import main as tlmpc_main

    stdout, stderr = io.StringIO(), io.StringIO()
    code = tlmpc_main(["compile", mission, "-o", out, "-q", "--json", "--force"], stdout, stderr)
    seconds = time.perf_counter() - started
    summary = json.loads(stdout.getvalue())["result"] if code == 0 else None
    return code, seconds, summary, stderr.getvalue()[-2000:]


def main() -> None:
    mission, out = sys.argv[1], sys.argv[2]
    code, cold, _, err = _compile(mission, out + "-cold")
    if code != 0:
        print(json.dumps({"exit": code, "stderr": err}))
        return
    code, warm, summary, err = _compile(mission, out)
    result = {
        "exit": code,
        "cold_seconds": cold,
        "compile_seconds": warm,
        "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
        "summary": summary,
        "stderr": err,
    }
    print(json.dumps(result))


if __name__ == "__main__":
    main()
