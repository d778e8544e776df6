"""Why a robot log the bag reader failed on cannot be read, in words.

The reader (``rosbags``) fails deep inside on a recording cut short or garbled, with a Python
error that names no place in the file.  Walking the file's own record layout (ROS 1 bags and
MCAP files) finds where it ends or breaks ("record 2 (chunk, at byte 43) declares 8,451 bytes,
but the file ends 57 bytes into it"); otherwise the reader's own message is kept when it is
worded for people.
"""

from __future__ import annotations

import contextlib
from pathlib import Path
from typing import Any

_MCAP_MAGIC = b"\x89MCAP0\r\n"
_MCAP_RECORDS = {
    0x01: "header",
    0x02: "footer",
    0x03: "schema",
    0x04: "channel",
    0x05: "message",
    0x06: "chunk",
    0x07: "message index",
    0x08: "chunk index",
    0x09: "attachment",
    0x0A: "attachment index",
    0x0B: "statistics",
    0x0C: "metadata",
    0x0D: "metadata index",
    0x0E: "summary offset",
    0x0F: "data end",
}
_ROS1_MAGIC = b"#ROSBAG V2.0\n"
_ROS1_RECORDS = {
    0x02: "message data",
    0x03: "bag header",
    0x04: "index data",
    0x05: "chunk",
    0x06: "chunk info",
    0x07: "connection",
}
#: Records looked at by :func:`_damage` at most (it runs only after the reader failed).
_SCAN_RECORDS = 4_000_000


def reader_failure(exc: BaseException, path: Path) -> tuple[str, str | None]:
    """Why the bag reader failed on ``path``, as a sentence, and a hint (or None).

    A recording cut short is said to be (with the record where it ends), found by walking the
    file's records (ROS 1 bags and MCAP files); else the reader's own message (``rosbags``
    and SQLite word theirs for people), or, for a Python error from deep inside the reader
    (a garbled length or name: ``TypeError``, ``KeyError``, ...), that the file is corrupt.
    """
    import errno
    import sqlite3

    damage = _damage(path)
    if damage is not None:
        return damage
    if type(exc).__module__.startswith("rosbags") or isinstance(exc, sqlite3.Error):
        text = " ".join(str(exc).split())  # one line (a type error quotes a definition)
        return (text if len(text) <= 200 else text[:199] + "…") or type(exc).__name__, None
    if isinstance(exc, OSError) and exc.strerror and exc.errno != errno.EINVAL:
        return exc.strerror, None  # EINVAL: a seek to a garbled offset
    return (
        "the file is corrupt (its contents do not parse as a bag)",
        "it may have been damaged in a copy: compare it with the robot's own",
    )


def _damage(path: Path) -> tuple[str, str] | None:
    """Where the ROS 1 bag or MCAP file ``path`` (or a bag directory's MCAP file) is cut
    short, with a hint; None when its records are whole (or it is neither)."""
    import os

    try:
        for file, kind in _storage_files(path):
            if kind not in _SALVAGE:
                continue
            with open(file, "rb") as stream:
                size = os.fstat(stream.fileno()).st_size
                if kind == "mcap":
                    stream.seek(len(_MCAP_MAGIC))
                    found = _mcap_damage(stream, size)
                else:
                    stream.seek(len(_ROS1_MAGIC))
                    found = _ros1_damage(stream, size)
            if found is not None:
                state = "truncated" if found.startswith("it ends") else "truncated or corrupt"
                return (
                    f"the file{_inside(file, path)} is {state}: {found}",
                    f"a recording cut short (the recorder stopped, or the disk filled); "
                    f"{_SALVAGE[kind]} may salvage its whole records",
                )
    except OSError:
        return None
    return None


def storage_damage(path: Path) -> tuple[str, str] | None:
    """Where the bag ``path`` is damaged although a reader opens it, with a hint: a storage
    file cut short (as :func:`reader_failure` finds), an MCAP message record that readers skip
    (its channel is not declared, or its log time lies outside its chunk's range), or a
    sqlite3 file that fails SQLite's ``quick_check``; None when none is found.  It reads every
    record: call it once a bag is known to be damaged (its counts do not add up)."""
    found = _damage(path) or sqlite_damage(path)
    if found is not None:
        return found
    try:
        for file, kind in _storage_files(path):
            if kind != "mcap":
                continue
            with open(file, "rb") as stream:
                lost = _mcap_lost_message(stream)
            if lost is not None:
                return (
                    f"the file{_inside(file, path)} is corrupt: {lost}",
                    "a byte changed in a copy (the file has no checksums to tell); "
                    "compare it with the robot's own",
                )
    except OSError:
        return None
    return None


def sqlite_damage(path: Path) -> tuple[str, str] | None:
    """SQLite's own ``PRAGMA quick_check`` of the bag's sqlite3 files (a pass over their
    pages, cheaper than the query that reads the messages): what it finds in the first file
    it fails on, with a hint; None when they pass (or there are none)."""
    import sqlite3

    try:
        files = [file for file, kind in _storage_files(path) if kind == "sqlite3"]
    except OSError:
        return None
    for file in files:
        try:
            uri = f"{file.resolve().as_uri()}?immutable=1"
            with contextlib.closing(sqlite3.connect(uri, uri=True)) as database:
                results = [str(row[0]) for row in database.execute("PRAGMA quick_check(3)")]
        except sqlite3.Error as exc:
            results = [str(exc)]
        if results != ["ok"]:
            return (
                f"the file{_inside(file, path)} is corrupt: SQLite's quick_check finds "
                + "; ".join(" ".join(result.split()) for result in results),
                "a damaged database (a crash while recording, or a bad copy); `sqlite3 FILE "
                '".recover"` may salvage its rows into a new file',
            )
    return None


_SALVAGE = {"mcap": "`mcap recover`", "ros1": "`rosbag reindex`"}
_SQLITE_MAGIC = b"SQLite format 3\x00"


def _storage_files(path: Path) -> list[tuple[Path, str]]:
    """The storage files of the bag ``path`` (itself, or a bag directory's files), each with
    its kind by its first bytes: ``"mcap"``, ``"ros1"``, ``"sqlite3"`` or ``""``."""
    found: list[tuple[Path, str]] = []
    for file in sorted(path.iterdir()) if path.is_dir() else [path]:
        if not file.is_file():
            continue
        with open(file, "rb") as stream:
            start = stream.read(len(_SQLITE_MAGIC))
        if start.startswith(_MCAP_MAGIC):
            found.append((file, "mcap"))
        elif start.startswith(_ROS1_MAGIC):
            found.append((file, "ros1"))
        else:
            found.append((file, "sqlite3" if start == _SQLITE_MAGIC else ""))
    return found


def _inside(file: Path, path: Path) -> str:
    """`` (NAME)`` when ``file`` is a file of the bag directory ``path``."""
    return f" ({file.name})" if file != path else ""


def _mcap_lost_message(stream: Any) -> str | None:
    """The first message record of a whole MCAP file that readers skip, in words: one on a
    channel the file does not declare, or one in a chunk whose log time lies outside the
    chunk's range (readers pick a chunk's messages by that range)."""
    from rosbags.rosbag2.storage_mcap import decompress

    channels: set[int] = set()
    offset = len(_MCAP_MAGIC)
    stream.seek(offset)
    for number in range(1, _SCAN_RECORDS):
        head = stream.read(9)
        if len(head) < 9 or head[0] == 0x02:  # the footer
            return None
        body = stream.read(int.from_bytes(head[1:], "little"))
        where = f"record {number} ({_MCAP_RECORDS.get(head[0], 'unknown')}, at byte {offset})"
        offset += 9 + len(body)
        skipped = _skipped_message(head[0], body, channels, None)
        if skipped is not None:
            return f"{where} {skipped}"
        if head[0] == 0x06 and len(body) >= 40:
            begin, end, size = (int.from_bytes(body[at : at + 8], "little") for at in (0, 8, 16))
            named = int.from_bytes(body[28:32], "little")
            compression = body[32 : 32 + named].decode("utf-8", "replace")
            packed = int.from_bytes(body[32 + named : 40 + named], "little")
            try:
                records = decompress(body[40 + named : 40 + named + packed], compression, size, 0)
            except Exception:  # a chunk that does not unpack is damaged another way
                return f"{where} does not decompress ({compression or 'uncompressed'})"
            lost = _chunk_lost_message(records, channels, begin, end)
            if lost is not None:
                return f"{where}: {lost}"
    return None


def _chunk_lost_message(records: bytes, channels: set[int], begin: int, end: int) -> str | None:
    """The first message record of a chunk's (uncompressed) ``records`` that readers skip."""
    at = 0
    while at + 9 <= len(records):
        kind, length = records[at], int.from_bytes(records[at + 1 : at + 9], "little")
        skipped = _skipped_message(kind, records[at + 9 : at + 9 + length], channels, (begin, end))
        if skipped is not None:
            return f"its message record at byte {at:,} of the unpacked chunk {skipped}"
        at += 9 + length
    return None


def _skipped_message(
    opcode: int, body: bytes, channels: set[int], window: tuple[int, int] | None
) -> str | None:
    """Why readers skip the MCAP record ``opcode``/``body`` if it is a message (in words,
    after the record's place), else None; a channel record joins ``channels``.  A message in a
    chunk must also lie in the chunk's log-time ``window``."""
    if opcode == 0x04 and len(body) >= 2:
        channels.add(int.from_bytes(body[:2], "little"))
    elif opcode == 0x05 and len(body) >= 22:
        channel = int.from_bytes(body[:2], "little")
        if channel not in channels:
            return f"is on channel {channel}, which the file does not declare"
        log_time = int.from_bytes(body[6:14], "little")
        if window is not None and not window[0] <= log_time <= window[1]:
            begin, end = window
            return f"has log time {log_time:,} ns, outside the chunk's {begin:,}-{end:,} ns"
    return None


def _mcap_damage(stream: Any, size: int) -> str | None:
    """Where an MCAP file ends early: its records are opcode (1 byte), length (8 bytes,
    little-endian) and body, up to the footer and the closing magic."""
    offset = len(_MCAP_MAGIC)
    for number in range(1, _SCAN_RECORDS):
        head = stream.read(9)
        if not head:
            return f"it ends at byte {size}, where record {number} should begin"
        kind = _MCAP_RECORDS.get(head[0], f"opcode 0x{head[0]:02x}")
        where = f"record {number} ({kind}, at byte {offset})"
        if len(head) < 9:
            return f"it ends at byte {size}, inside the length of {where}"
        length = int.from_bytes(head[1:], "little")
        if offset + 9 + length > size:
            return (
                f"{where} declares {length:,} bytes, but the file ends "
                f"{size - offset - 9:,} bytes into it"
            )
        offset += 9 + length
        stream.seek(offset)
        if head[0] == 0x02:  # the footer: the closing magic follows
            if size - offset < len(_MCAP_MAGIC):
                return f"it ends at byte {size}, inside the closing magic after the footer"
            return None
    return None


def _ros1_damage(stream: Any, size: int) -> str | None:
    """Where a ROS 1 bag ends early: its records are a header (length, 4 bytes, then fields)
    and data (length, 4 bytes, then bytes); the bag header record says where the index is."""
    offset = len(_ROS1_MAGIC)
    index = None
    for number in range(1, _SCAN_RECORDS):
        if offset == size:
            if index is not None and index > size:
                return f"it ends at byte {size}, before its index (at byte {index:,})"
            return None
        head = stream.read(4)
        if len(head) < 4:
            return f"it ends at byte {size}, inside the header length of record {number}"
        header_length = int.from_bytes(head, "little")
        if offset + 4 + header_length > size:
            return (
                f"record {number} (at byte {offset}) declares a header of {header_length:,} "
                f"bytes, but the file ends {size - offset - 4:,} bytes into it"
            )
        header = stream.read(header_length)
        fields = _ros1_fields(header)
        op = fields.get("op", b"")
        kind = _ROS1_RECORDS.get(op[0], "unknown") if len(op) == 1 else "unknown"
        if kind == "bag header" and len(fields.get("index_pos", b"")) == 8:
            index = int.from_bytes(fields["index_pos"], "little")
        head = stream.read(4)
        where = f"record {number} ({kind}, at byte {offset})"
        if len(head) < 4:
            return f"it ends at byte {size}, inside the data length of {where}"
        data_length = int.from_bytes(head, "little")
        end = offset + 8 + header_length + data_length
        if end > size:
            return (
                f"{where} declares {data_length:,} bytes of data, but the file ends "
                f"{size - (offset + 8 + header_length):,} bytes into them"
            )
        offset = end
        stream.seek(offset)
    return None


def _ros1_fields(header: bytes) -> dict[str, bytes]:
    """A ROS 1 record header's ``name=value`` fields (each after its 4-byte length)."""
    fields: dict[str, bytes] = {}
    at = 0
    while at + 4 <= len(header):
        length = int.from_bytes(header[at : at + 4], "little")
        name, _, value = header[at + 4 : at + 4 + length].partition(b"=")
        fields[name.decode("latin-1")] = value
        at += 4 + length
    return fields
