"""Run one ``tlmpc compile`` in this process and print timings and peak memory as JSON.

The benchmark driver starts this script in a fresh interpreter per run, so peak RSS is the
compile's own and imports are counted like a user's command line would count them.
"""

from __future__ import annotations

import io
import json
import resource
import sys
import time


def main() -> None:
    mission, out = sys.argv[1], sys.argv[2]
    started = time.perf_counter()
    from tlmpc.cli import main as tlmpc_main

    imported = time.perf_counter()
    stdout, stderr = io.StringIO(), io.StringIO()
    code = tlmpc_main(["compile", mission, "-o", out, "-q", "--json", "--force"], stdout, stderr)
    finished = time.perf_counter()
    result = {
        "exit": code,
        "import_seconds": imported - started,
        "compile_seconds": finished - imported,
        "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
        "summary": json.loads(stdout.getvalue()) if code == 0 else None,
        "stderr": stderr.getvalue()[-2000:],
    }
    print(json.dumps(result))


if __name__ == "__main__":
    main()
