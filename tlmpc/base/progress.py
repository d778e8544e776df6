"""Progress inside long stages: a heartbeat line on a terminal while a stage runs.

The stages themselves stay silent; while one runs longer than a moment, a background thread
rewrites one status line (``\\r``) on stderr with the stage's name and the time spent, and clears
it when the stage ends.  Only when stderr is a terminal: logs and pipes get the per-stage
lines of ``tlmpc compile`` and nothing else.
"""

from __future__ import annotations

import contextlib
import threading
import time
from collections.abc import Iterator
from typing import TextIO

#: Seconds before the first heartbeat, and between heartbeats.
FIRST = 1.0
EVERY = 0.5


@contextlib.contextmanager
def heartbeat(
    name: str, stream: TextIO, *, first: float = FIRST, every: float = EVERY
) -> Iterator[None]:
    """Show ``… NAME: 3.5 s`` on ``stream`` while the body runs (when it is a terminal)."""
    isatty = getattr(stream, "isatty", None)
    if isatty is None or not isatty():
        yield
        return
    stop = threading.Event()
    started = time.perf_counter()
    shown = False

    def beat() -> None:
        nonlocal shown
        if stop.wait(first):
            return
        while True:
            stream.write(f"\r… {name}: {time.perf_counter() - started:5.1f} s")
            stream.flush()
            shown = True
            if stop.wait(every):
                return

    thread = threading.Thread(target=beat, name=f"tlmpc-progress-{name}", daemon=True)
    thread.start()
    try:
        yield
    finally:
        stop.set()
        thread.join()
        if shown:
            stream.write("\r\033[K")  # clear the status line
            stream.flush()
