"""What a batch prints and writes: a line per log, the summary table, the results files."""

from __future__ import annotations

import json
import os
import stat
from collections import Counter
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, TextIO

from tlmpc.base.errors import UsageError, error
from tlmpc.fleet.job import finite
from tlmpc.verify.clock import seconds

#: The fields of a results row, in order (JSON lines and Parquet alike).
FIELDS = (
    "log",
    "mission",
    "verdict",
    "conjuncts",
    "first_violation",
    "robustness",
    "seconds",
    "samples",
    "start",
    "cached",
    "formula",
    "violations",
    "error",
)

STATUS = {
    "satisfied": "satisfied",
    "violated": "VIOLATED",
    "inconclusive": "inconclusive",
    "error": "ERROR",
}


def line(record: Mapping[str, Any]) -> str:
    """One line about one log: its verdict and, if violated, where it first failed."""
    text = f"{record['log']}: {STATUS[record['verdict']]}"
    first = record.get("first_violation")
    if first is not None:
        when = "" if first["t"] is None else f" at t={seconds(first['t'])} s"
        where = "" if first["x"] is None else f" at ({first['x']:.4g}, {first['y']:.4g})"
        text += f": {first['conjunct']}{when}{where}"
    if record["verdict"] == "error":
        text += f": {record['error']['message']}"
    if record.get("cached"):
        text += " (cached)"
    return text


def ordered(records: Sequence[Mapping[str, Any]], logs: Sequence[str]) -> list[dict[str, Any]]:
    """The records in the batch's own order (the order logs were named and found): a log
    named more than once has a record at each of its places."""
    places: dict[str, list[int]] = {}
    for index, log in enumerate(logs):
        places.setdefault(log, []).append(index)
    # the records of one log differ in `seconds` alone: any of them may take any of its places
    placed = []
    for record in records:
        free = places.get(record["log"])
        placed.append((free.pop() if free else len(logs), record["log"], record))
    placed.sort(key=lambda entry: (entry[0], entry[1]))
    return [{name: row.get(name) for name in FIELDS} for _, _, row in placed]


def summary(records: Sequence[Mapping[str, Any]], wall: float) -> dict[str, Any]:
    """Counts per verdict, per violated conjunct, and what the run cost."""
    verdicts = Counter(r["verdict"] for r in records)
    conjuncts: Counter[str] = Counter()
    for record in records:
        for conjunct in record["conjuncts"]:
            if conjunct["verdict"] == "violated":
                conjuncts[conjunct["conjunct"]] += 1
        if any(v["conjunct"] == "workspace" for v in record.get("violations") or []):
            conjuncts["workspace"] += 1
    return {
        "logs": len(records),
        "verdicts": {k: verdicts.get(k, 0) for k in STATUS},
        "violated_conjuncts": dict(sorted(conjuncts.items(), key=lambda kv: (-kv[1], kv[0]))),
        "verified": sum(1 for r in records if not r.get("cached") and r["verdict"] != "error"),
        "cached": sum(1 for r in records if r.get("cached")),
        "samples": sum(int(r.get("samples") or 0) for r in records),
        "seconds": sum(float(r.get("seconds") or 0.0) for r in records if not r.get("cached")),
        "wall_seconds": wall,
    }


def summary_table(numbers: Mapping[str, Any]) -> str:
    """The summary as a small text table."""
    rows = [("logs", str(numbers["logs"]))]
    rows += [(verdict, str(count)) for verdict, count in numbers["verdicts"].items()]
    rows += [
        ("verified now", str(numbers["verified"])),
        ("from the cache", str(numbers["cached"])),
        ("samples", f"{numbers['samples']:,}"),
        ("worker seconds", f"{numbers['seconds']:.2f}"),
        ("wall seconds", f"{numbers['wall_seconds']:.2f}"),
    ]
    rows += [(f"violated: {name}", str(n)) for name, n in numbers["violated_conjuncts"].items()]
    width = max(len(name) for name, _ in rows)
    return "".join(f"  {name:<{width}}  {value:>10}\n" for name, value in rows)


def visible(text: str) -> str:
    """``text`` with the bytes of a file name that are not UTF-8 shown as ``\\xNN``.

    Python keeps such bytes in a path as lone surrogates (``\\udce9`` for the byte 0xE9),
    which no UTF-8 file can hold: a report or a Parquet file shows the byte instead.  Any
    other lone surrogate (an escaped ``\\ud800`` read from JSON) is shown as ``\\uNNNN``."""
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        return "".join(_visible_char(ch) for ch in text)
    return text


def _visible_char(ch: str) -> str:
    code = ord(ch)
    if 0xDC80 <= code <= 0xDCFF:  # a file name's byte that is not UTF-8
        return f"\\x{code - 0xDC00:02x}"
    return f"\\u{code:04x}" if 0xD800 <= code <= 0xDFFF else ch


def _refused(path: Path, message: str, hint: str) -> UsageError:
    return UsageError(error("F007", message, hint=hint, file=str(path)))


def check_output(path: Path) -> None:
    """Refuse (F007) an output file the batch could not write at its end, before any log
    is verified: a link, a folder, a device or a FIFO at ``path`` (never replaced), or a
    path whose folder is a file or cannot be written."""
    try:
        info: os.stat_result | None = os.lstat(path)
    except FileNotFoundError:
        info = None
    except OSError as exc:
        raise _refused(
            path, f"cannot write {path}: {exc.strerror or exc}", "choose another file"
        ) from None
    if info is not None and not stat.S_ISREG(info.st_mode):
        kind = {stat.S_IFLNK: "a symbolic link", stat.S_IFDIR: "a folder"}.get(
            stat.S_IFMT(info.st_mode), "not a regular file"
        )
        raise _refused(path, f"{path} is {kind}; it is never replaced", "choose another file")
    folder = Path(os.path.abspath(path)).parent
    while not os.path.lexists(folder) and folder != folder.parent:
        folder = folder.parent  # made when the file is written
    if not folder.is_dir():
        raise _refused(
            path, f"cannot write {path}: {folder} is not a folder", "choose another file"
        )
    if not os.access(folder, os.W_OK | os.X_OK):
        raise _refused(
            path,
            f"cannot write {path}: the folder {folder} is not writable",
            "choose a folder you may write in",
        )


def write_atomically(path: Path, data: bytes) -> None:
    """Replace ``path`` with ``data`` as every output is replaced
    (:func:`tlmpc.io.outdir.replace_file`: whole or not at all, never over a link, a device
    or a FIFO, a replaced file's permissions kept), its folder made first; any refusal is
    F007, this command's code for an output it cannot write."""
    from tlmpc.io.outdir import replace_file

    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UsageError(
            error("F007", f"cannot write {path}: {exc.strerror or exc}", file=str(path))
        ) from None
    try:
        replace_file(path, data)
    except UsageError as exc:
        refused = exc.diagnostics[0]
        raise UsageError(
            error("F007", refused.message, hint=refused.hint, file=str(path))
        ) from None


def write_results(path: Path, rows: Sequence[Mapping[str, Any]]) -> None:
    """JSON lines, or Parquet when ``path`` ends in ``.parquet`` (needs pyarrow)."""
    if path.suffix.lower() == ".parquet":
        try:
            import pyarrow as pa
            import pyarrow.parquet as pq
        except ImportError:
            raise UsageError(
                error(
                    "F006",
                    "writing Parquet needs the `pyarrow` package, which is not installed",
                    hint="install the fleet extra (pip install 'tlmpc[fleet]') or write "
                    "JSON lines (--results FILE.jsonl)",
                    file=str(path),
                )
            ) from None
        table = pa.Table.from_pylist([dict(_parquet_row(r)) for r in rows], schema=_schema(pa))
        buffer = pa.BufferOutputStream()
        pq.write_table(table, buffer)
        write_atomically(path, buffer.getvalue().to_pybytes())
        return
    text = "".join(json.dumps(finite(dict(row)), sort_keys=False) + "\n" for row in rows)
    write_atomically(path, text.encode("utf-8"))


def _parquet_row(row: Mapping[str, Any]) -> dict[str, Any]:
    out = dict(row)
    out["error"] = None if row["error"] is None else row["error"]["message"]
    return {name: _visible_strings(value) for name, value in out.items()}


def _visible_strings(value: Any) -> Any:
    """``value`` with every string :func:`visible` (Parquet strings are UTF-8)."""
    if isinstance(value, str):
        return visible(value)
    if isinstance(value, dict):
        return {k: _visible_strings(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_visible_strings(v) for v in value]
    return value


def _schema(pa: Any) -> Any:
    point = pa.struct(
        [
            ("conjunct", pa.string()),
            ("t", pa.float64()),
            ("x", pa.float64()),
            ("y", pa.float64()),
        ]
    )
    return pa.schema(
        [
            ("log", pa.string()),
            ("mission", pa.string()),
            ("verdict", pa.string()),
            (
                "conjuncts",
                pa.list_(pa.struct([("conjunct", pa.string()), ("verdict", pa.string())])),
            ),
            ("first_violation", point),
            ("robustness", pa.float64()),
            ("seconds", pa.float64()),
            ("samples", pa.int64()),
            ("start", pa.float64()),
            ("cached", pa.bool_()),
            ("formula", pa.string()),
            ("violations", pa.list_(point)),
            ("error", pa.string()),
        ]
    )


def print_line(out: TextIO, record: Mapping[str, Any]) -> None:
    """The record's line, flushed at once (a batch reports each log as it finishes)."""
    out.write(line(record) + "\n")
    out.flush()
