"""The verification cache: a log's record stored under a hash of everything it depends on.

The key (:func:`tlmpc.fleet.job.job_key`) hashes the log's bytes, the mission as read (task,
regions, workspace, convention, speed, body), the reading options and tlmpc's version, so a
new or changed log, a changed mission or a new tlmpc is verified again and nothing else is.
Each record is one small JSON file ``DIR/ab/abcdef....json``, written atomically (a temporary
file renamed into place), so workers on several machines sharing the folder never see half a
record.  The default folder is :func:`default_cache_dir`.
"""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
from pathlib import Path
from typing import Any

#: Bytes hashed at a time (a 24 h log is 150 MB).
READ_BLOCK = 1 << 20


def default_cache_dir() -> Path:
    """``$TLMPC_CACHE_DIR``, else ``$XDG_CACHE_HOME/tlmpc/verify``, else
    ``~/.cache/tlmpc/verify``."""
    chosen = os.environ.get("TLMPC_CACHE_DIR")
    if chosen:
        return Path(chosen)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "tlmpc" / "verify"


def content_digest(path: Path) -> str:
    """SHA-256 of a log file's bytes, or of a bag directory's files (names and bytes).

    Regular files only, as every reader (:func:`tlmpc.io.inputs.open_regular`): a FIFO or a
    device named like a log is refused (M050) at once, never waited on or read without end."""
    from tlmpc.io.inputs import open_regular

    digest = hashlib.sha256()
    files = sorted(p for p in path.rglob("*") if p.is_file()) if path.is_dir() else [path]
    for file in files:
        if path.is_dir():
            digest.update(file.relative_to(path).as_posix().encode() + b"\0")
        with open_regular(file, code="M050", what="log") as stream:
            while block := stream.read(READ_BLOCK):
                digest.update(block)
    return digest.hexdigest()


class Cache:
    """Records by key in ``folder`` (created when first written)."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder

    def _path(self, key: str) -> Path:
        return self.folder / key[:2] / f"{key}.json"

    def get(self, key: str) -> dict[str, Any] | None:
        """The stored record, or None (also for an unreadable or damaged entry)."""
        try:
            record = json.loads(self._path(key).read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return None
        return record if isinstance(record, dict) else None

    def put(self, key: str, record: dict[str, Any]) -> None:
        """Store ``record``; a folder that cannot be written only costs the next run time."""
        target = self._path(key)
        try:
            target.parent.mkdir(parents=True, exist_ok=True)
            handle, temporary = tempfile.mkstemp(dir=target.parent, suffix=".tmp")
        except OSError:
            return
        try:
            with os.fdopen(handle, "w", encoding="utf-8") as stream:
                json.dump(record, stream, allow_nan=True)
            os.replace(temporary, target)
        except OSError:
            Path(temporary).unlink(missing_ok=True)
