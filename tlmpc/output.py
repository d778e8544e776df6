"""Atomic output directories: all artifacts appear together, or none do.

Artifacts are written into a fresh temporary directory next to ``OUT`` (same file system, so
the final rename is atomic) and moved into place only when every one was written.  A failed
or interrupted run removes the temporary directory and leaves ``OUT`` exactly as it was.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import tempfile
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

from tlmpc.artifacts import dumps
from tlmpc.errors import UsageError, error

#: Every file name ``tlmpc compile`` may write; a directory holding only these is ours.
KNOWN_ARTIFACTS = frozenset(
    {
        "mission.json",
        "abstraction.json",
        "automaton.json",
        "automaton.hoa",
        "witness.json",
        "controllers.json",
        "trace.json",
        "verdict.json",
        "summary.json",
        "plan.png",
        "plan.svg",
    }
)


def replace_file(path: Path, data: bytes) -> None:
    """Write ``path`` beside itself and rename, so a reader never sees half a file and a
    failed write leaves the old file as it was."""
    handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    try:
        with os.fdopen(handle, "wb") as stream:
            stream.write(data)
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise


def is_tlmpc_output(directory: Path) -> bool:
    """True when ``directory`` is empty or holds a previous tlmpc output and nothing else."""
    entries = {p.name for p in directory.iterdir()}
    if not entries:
        return True
    if not entries <= KNOWN_ARTIFACTS:
        return False
    summary = directory / "summary.json"
    if summary.exists():
        try:
            fmt = json.loads(summary.read_text(encoding="utf-8")).get("format", "")
        except (OSError, ValueError, AttributeError):
            return False
        return isinstance(fmt, str) and fmt.startswith("tlmpc.summary/")
    return True


def check_destination(out: Path, *, force: bool) -> None:
    """Refuse (exit 2) to replace something that is not a tlmpc output, unless ``force``."""
    if not out.exists():
        if not out.parent.exists():
            raise UsageError(
                error(
                    "U010",
                    f"the parent directory of {out} does not exist",
                    hint="create it first, or choose another -o",
                )
            )
        return
    if not out.is_dir():
        raise UsageError(
            error("U011", f"{out} exists and is not a directory", hint="choose another -o")
        )
    if not force and not is_tlmpc_output(out):
        raise UsageError(
            error(
                "U012",
                f"{out} is not empty and does not look like a tlmpc output",
                hint="choose another -o, or pass --force to add the artifacts to it "
                "(other files in it are kept)",
            )
        )


def _write(path: Path, content: Any) -> None:
    if isinstance(content, bytes):
        path.write_bytes(content)
    elif isinstance(content, str):
        path.write_text(content, encoding="utf-8")
    else:
        path.write_text(dumps(content), encoding="utf-8")


@contextlib.contextmanager
def staging_directory(out: Path) -> Iterator[Path]:
    """A temporary directory beside ``out``; removed on exit unless it was committed."""
    parent = out.resolve().parent
    staging = Path(tempfile.mkdtemp(prefix=f".{out.name}.tlmpc-", dir=parent))
    try:
        yield staging
    finally:
        shutil.rmtree(staging, ignore_errors=True)


def write_artifacts(staging: Path, artifacts: Mapping[str, Any]) -> None:
    """Write each artifact (JSON document, text or bytes) into ``staging``."""
    for name, content in artifacts.items():
        _write(staging / name, content)


def commit(staging: Path, out: Path, *, force: bool) -> None:
    """Move the staged artifacts to ``out`` atomically.

    A previous tlmpc output (or an empty directory) is swapped out whole; a foreign directory
    (accepted only with ``force``) receives the files one by one and keeps its other files.
    """
    if out.exists() and not is_tlmpc_output(out):
        if not force:  # checked before compiling too; a race must not lose user files
            raise UsageError(error("U012", f"{out} changed and is no longer a tlmpc output"))
        for item in staging.iterdir():
            os.replace(item, out / item.name)
        return
    final = staging.parent / f".{out.name}.tlmpc-final"
    shutil.rmtree(final, ignore_errors=True)
    os.replace(staging, final)
    if out.exists():
        backup = staging.parent / f".{out.name}.tlmpc-old"
        shutil.rmtree(backup, ignore_errors=True)
        os.replace(out, backup)
        os.replace(final, out)
        shutil.rmtree(backup, ignore_errors=True)
    else:
        os.replace(final, out)
