"""Lark parsers built once per grammar and reused from a per-user cache across runs.

Building an LALR parser (grammar analysis and tables) costs tens of milliseconds on every
start — a large share of a ``tlmpc check`` from a pre-commit hook.  Lark can serialise the
built parser; we keep that file in the user's own cache directory (never a shared
temporary folder: the file is unpickled on load), named by a digest of the grammar, the
options and the versions of lark and Python, so an edited grammar or an upgrade builds afresh.

``TLMPC_CACHE_DIR`` chooses the directory; ``TLMPC_CACHE_DIR=off`` disables the cache.
Any failure to read or write the cache only costs the build: lark falls back by itself.
"""

from __future__ import annotations

import hashlib
import os
import sys
from pathlib import Path
from typing import Any


def cache_directory() -> Path | None:
    """Where built parsers are kept (``None``: caching is off or impossible)."""
    chosen = os.environ.get("TLMPC_CACHE_DIR")
    if chosen is not None:
        if chosen.strip().lower() in ("", "off", "0", "no", "false"):
            return None
        base = Path(chosen)
    else:
        xdg = os.environ.get("XDG_CACHE_HOME")
        base = (Path(xdg) if xdg else Path.home() / ".cache") / "tlmpc"
    try:
        base.mkdir(mode=0o700, parents=True, exist_ok=True)
    except OSError:
        return None
    return base if os.access(base, os.W_OK) else None


def lalr_parser(grammar: str, **options: Any) -> Any:
    """A ``Lark(grammar, parser="lalr", **options)``, from the cache when it was built before."""
    from lark import Lark
    from lark import __version__ as lark_version

    directory = cache_directory()
    if directory is None:
        return Lark(grammar, parser="lalr", **options)
    key = "\0".join([grammar, repr(sorted(options.items())), lark_version, sys.version.split()[0]])
    digest = hashlib.sha256(key.encode("utf-8")).hexdigest()[:24]
    return Lark(grammar, parser="lalr", cache=str(directory / f"lark-{digest}.cache"), **options)
