"""``python -m tlmpc``."""

from tlmpc.cli import run

run()
