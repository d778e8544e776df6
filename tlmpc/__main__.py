"""``python -m tlmpc``."""

from tlmpc.cli import main

raise SystemExit(main())
