"""Progress inside long stages: a line on standard error while a stage runs long.

The stages themselves stay silent; while one runs longer than :data:`FIRST` seconds, a
background thread reports it on stderr with the stage's name and the time spent:

* on a terminal, one status line rewritten in place (``\\r``) every :data:`EVERY` seconds and
  cleared when the stage ends;
* anywhere else (a pipe, a CI log, a file), whole lines — ``… NAME: running for 2.0 s`` — the
  first after :data:`FIRST` seconds and then at doubling intervals (2, 4, 8, 16 s ...), so a
  long job's log shows that it is alive without being flooded, and ``… NAME: done in 9.3 s``
  when the stage ends.

Commands silence it with ``--quiet`` (they do not start it).
"""

from __future__ import annotations

import contextlib
import threading
import time
from collections.abc import Iterator
from typing import TextIO

#: Seconds before the first report, and between rewrites of a terminal's status line.
FIRST = 2.0
EVERY = 0.5


@contextlib.contextmanager
def heartbeat(
    name: str, stream: TextIO, *, first: float | None = None, every: float = EVERY
) -> Iterator[None]:
    """Report on ``stream`` while the body runs longer than ``first`` seconds (default
    :data:`FIRST`)."""
    first = FIRST if first is None else first
    isatty = getattr(stream, "isatty", None)
    terminal = bool(isatty is not None and isatty())
    stop = threading.Event()
    started = time.perf_counter()
    shown = False

    def beat() -> None:
        nonlocal shown
        if stop.wait(first):
            return
        wait = max(first, every)
        while True:
            spent = time.perf_counter() - started
            if terminal:
                stream.write(f"\r… {name}: {spent:5.1f} s")
            else:
                stream.write(f"… {name}: running for {spent:.1f} s\n")
            stream.flush()
            shown = True
            if not terminal:
                wait *= 2  # 2, 4, 8, 16 s ... apart: alive, not flooding a log
            if stop.wait(every if terminal else wait):
                return

    thread = threading.Thread(target=beat, name=f"tlmpc-progress-{name}", daemon=True)
    thread.start()
    try:
        yield
    finally:
        stop.set()
        thread.join()
        if shown:
            if terminal:
                stream.write("\r\033[K")  # clear the status line
            else:
                stream.write(f"… {name}: done in {time.perf_counter() - started:.1f} s\n")
            stream.flush()
