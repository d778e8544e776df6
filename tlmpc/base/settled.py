"""Whether the current run has done its work: from then on a Ctrl-C or SIGTERM is late.

``tlmpc compile`` puts its whole output in place with one rename.  A signal arriving after
that, while the command prints its last line, removes its lock file and restores its signal
handlers, can no longer leave anything half-written; ending the run for it would only report
a complete output as interrupted (exit 130 or 143), or cut the clean-up short (a lock file
left behind, a traceback from the middle of restoring the handlers).  So the command line's
handlers let a late signal pass (:mod:`tlmpc.cli`), and the run ends with its own exit code.

:func:`settle` is called where a run's result becomes final (the output's commit, and the
command line once the command returned); :func:`begin` at the start of every command-line
run.  A library caller's signal handlers are its own: the flag changes nothing for them.
"""

from __future__ import annotations

_SETTLED = [False]


def begin() -> None:
    """A new run starts: nothing of it is final yet."""
    _SETTLED[0] = False


def settle() -> None:
    """The run's result is final (its output in place): later signals are late."""
    _SETTLED[0] = True


def is_settled() -> bool:
    """Whether :func:`settle` was called since the run began."""
    return _SETTLED[0]
