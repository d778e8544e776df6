"""Robot logs → ``[t, x, y]`` sample arrays for the verifier.

* CSV (``.csv``, ``.tsv``, ``.txt``): ``#`` comment lines and blank lines are skipped; the
  separator is the first of ``,`` ``;`` tab found on the first data line, else whitespace; a
  header names the columns (``t``/``time``/``timestamp``/``stamp``, ``x``, ``y``, or names
  ending in ``.x``/``.y``/``_x``/``_y`` such as ``pose.position.x``), extra columns are
  ignored; ``columns`` chooses them by name or by 1-based number.  Without a header the file
  must have exactly three columns ``t, x, y`` unless ``columns`` gives their numbers.
* ROS 1 ``.bag``, ROS 2 bag directories (sqlite3 or MCAP storage) and ``.mcap`` files, read
  with the pure-Python ``rosbags``: the pose of ``nav_msgs/Odometry``,
  ``geometry_msgs/PoseStamped`` or ``geometry_msgs/PoseWithCovarianceStamped`` messages on
  ``topic`` (needed only when several topics carry poses), stamped with the message header
  (the log time when the header stamp is zero).  Samples are sorted by the integer stamps,
  then converted to seconds keeping distinct stamps distinct (:func:`stamp_seconds`); a
  repeated stamp is kept, for the verifier to refuse (V020) as in a CSV log.  At most
  :data:`MAX_LOG_SAMPLES` samples are read (M066).

An optional rigid ``transform`` ``(x, y, yaw)`` maps the log's frame into the mission's
(e.g. ``odom`` into ``map``): ``p_mission = R(yaw) p_log + (x, y)``.  For bags, ``frame``
instead looks the transform up in the bag's ``/tf`` and ``/tf_static`` at each pose's stamp
(:mod:`tlmpc.importers.frames`).

This module imports nothing from the planning stages; ``rosbags`` is imported only for bags.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import re
from array import array
from collections.abc import Callable, Generator, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from tlmpc.base.errors import UsageError, error
from tlmpc.base.extras import require
from tlmpc.importers.bag_counts import counted_messages
from tlmpc.importers.bag_damage import reader_failure, sqlite_damage

FloatArray = npt.NDArray[np.float64]

CSV_SUFFIXES = (".csv", ".tsv", ".txt")
BAG_SUFFIXES = (".bag", ".mcap", ".db3")
POSE_TYPES = {
    "nav_msgs/msg/Odometry": "pose.pose",
    "geometry_msgs/msg/PoseStamped": "pose",
    "geometry_msgs/msg/PoseWithCovarianceStamped": "pose.pose",
}
TIME_NAMES = ("t", "time", "timestamp", "stamp")

#: The most samples a log may have (the verifier's limit for CSV traces), and the most bytes
#: a CSV log may have; a bag's messages on the chosen topics count as they are read.
MAX_LOG_SAMPLES = 2_000_000
MAX_CSV_BYTES = 256 * 1024 * 1024


@dataclass(frozen=True, slots=True, kw_only=True)
class Log:
    """Samples ``[t, x, y]`` (bags: sorted by stamp) and where each came from."""

    samples: FloatArray = field(compare=False)
    lines: tuple[int, ...] = ()  # CSV line of each sample (empty for bags)
    source: str = ""
    topic: str | None = None
    #: a CSV log's separator (None: runs of blanks) and columns of t, x, y
    layout: tuple[str | None, tuple[int, int, int]] | None = None
    #: a bag's message of each sample: its 0-based number among the topic's pose messages
    #: in the order the bag stores them (samples are in stamp order); None for a CSV
    messages: npt.NDArray[np.int64] | None = field(default=None, compare=False)


class SampleColumns:
    """Where each cell of a CSV log's samples is written, for diagnostics: called with a
    sample's index and its cell (0 time, 1 x, 2 y), the column of that cell on the sample's
    line.  The log's lines are read again on the first call only: a log that has no problem
    never pays for it."""

    def __init__(self, path: Path, log: Log) -> None:
        self.path = path
        self.log = log
        self._lines: list[str] | None = None

    def __call__(self, index: int, cell: int) -> dict[str, int]:
        if self.log.layout is None or index >= len(self.log.lines):
            return {}
        if self._lines is None:
            self._lines = read_log_lines(self.path)
        separator, indices = self.log.layout
        raw = self._lines[self.log.lines[index] - 1]
        return {"col": _cell_column(raw, separator, indices[cell])}


class SampleMessages:
    """Where each sample of a bag's log came from, for diagnostics: called with a sample's
    index, its pose message in words — the topic, the message's number on it and its log
    time, as M065 names a message (:func:`message_words`).  The bag's log times are read again
    (without decoding a message) on the first call only: a log that has no problem never pays
    for it.  ``messages``: each sample's message number (:attr:`Log.messages`); without it,
    the samples are the messages in stamp order (``by_stamp``, a bag read whole and sorted:
    the order is found again on the first call) or in stored order (a bag read as a stream).
    """

    def __init__(
        self,
        path: Path,
        topic: str | None,
        messages: npt.NDArray[np.int64] | None = None,
        *,
        by_stamp: bool = False,
    ) -> None:
        self.path = path
        self.topic = topic
        self.messages = messages
        self.by_stamp = by_stamp
        self._log_times: array[int] | None = None  # 8 bytes a message
        self._chosen_topic = ""

    def __call__(self, index: int) -> str:
        if self.messages is None and self.by_stamp:
            self.messages = read_bag(self.path, self.topic).messages
        number = int(self.messages[index]) if self.messages is not None else index
        if self._log_times is None:
            self._log_times = array("q")
            with _opened_bag(self.path, self.topic, limit=False) as (reader, chosen, topic):
                self._chosen_topic = topic
                for _, log_time, _ in reader.messages(connections=chosen):
                    self._log_times.append(int(log_time))
        if not 0 <= number < len(self._log_times):
            return f"pose message {number + 1} on {self._chosen_topic}"
        return message_words(number, self._chosen_topic, self._log_times[number])


def message_words(number: int, topic: str, log_time: int, kind: str = "pose message") -> str:
    """A bag's message (a ``kind``) in words: the ``number`` th (0-based) stored on ``topic``,
    logged at ``log_time`` (ns) — what a diagnostic about it names."""
    return f"{kind} {number + 1} on {topic}, log time {log_time} ns"


def is_log(path: Path) -> bool:
    """Whether ``path`` is read by :func:`read_log` (a CSV, a bag file or a bag directory)."""
    suffix = path.suffix.lower()
    return suffix in CSV_SUFFIXES or suffix in BAG_SUFFIXES or path.is_dir()


def _fail(
    code: str,
    message: str,
    file: str,
    hint: str | None = None,
    line: int | None = None,
    col: int | None = None,
) -> UsageError:
    return UsageError(error(code, message, hint=hint, file=file, line=line, col=col))


def path_problem(path: Path) -> str | None:
    """Why ``path`` names nothing to read (None: it names a file or a folder), in words: no
    such file, a symbolic link loop (``ELOOP``, which :meth:`Path.exists` takes for a missing
    file), a link to nothing, or the system's reason."""
    import errno
    import os

    try:
        os.stat(path)
    except OSError as exc:
        if exc.errno == errno.ELOOP and path.is_symlink():
            return "it is a symbolic link loop (its links lead back to themselves)"
        if exc.errno == errno.ELOOP:
            return "its path runs into a symbolic link loop (links leading back to themselves)"
        if exc.errno == errno.ENOENT and path.is_symlink():
            with contextlib.suppress(OSError):
                return f"it is a symbolic link to {os.readlink(path)}, which does not exist"
        if exc.errno == errno.ENOENT:
            return "no such file or directory"
        return str(exc.strerror or exc)
    except ValueError as exc:  # a NUL in the path
        return str(exc)
    return None


def _path_hint(path: Path) -> str | None:
    """The hint for :func:`path_problem`: where the path is a link, to mend it."""
    if path.is_symlink():
        return "point the link at the log file or the bag directory"
    return None


def require_path(path: Path) -> None:
    """Refuse (M050) a log path that names nothing to read (see :func:`path_problem`)."""
    problem = path_problem(path)
    if problem is not None:
        raise _fail("M050", f"cannot read {path}: {problem}", str(path), hint=_path_hint(path))


def _apply(samples: FloatArray, transform: tuple[float, float, float] | None) -> FloatArray:
    if transform is None or len(samples) == 0:
        return samples
    tx, ty, yaw = transform
    c, s = math.cos(yaw), math.sin(yaw)
    out = samples.copy()
    out[:, 1] = c * samples[:, 1] - s * samples[:, 2] + tx
    out[:, 2] = s * samples[:, 1] + c * samples[:, 2] + ty
    return out


def read_log(
    path: Path,
    *,
    topic: str | None = None,
    columns: Sequence[str] | None = None,
    transform: tuple[float, float, float] | None = None,
    frame: str | None = None,
) -> Log:
    """Read a CSV log or a ROS bag; raise :class:`UsageError` (M050–M079, M102–M106) on bad
    input.  ``frame`` (bags): express the poses in that frame through the bag's tf."""
    file = str(path)
    require_path(path)
    if frame is not None and transform is not None:
        raise _fail(
            "M105",
            "--frame and --transform both given",
            file,
            hint="--frame takes the transform from the bag's tf; --transform gives a fixed one",
        )
    if path.suffix.lower() in CSV_SUFFIXES and not path.is_dir():
        if topic is not None:
            raise _fail("M058", "--topic applies to bags, not to CSV logs", file)
        if frame is not None:
            raise _fail(
                "M105",
                "--frame applies to bags, not to CSV logs (a CSV carries no frames)",
                file,
                hint="use --transform X,Y,YAW to move a CSV log into the mission's frame",
            )
        log = read_csv_log(path, columns)
    else:
        if columns is not None:
            raise _fail("M058", "--columns applies to CSV logs, not to bags", file)
        log = read_bag(path, topic, frame)
    if transform is None:
        return log
    return dataclasses.replace(log, samples=_apply(log.samples, transform))


# --- lines -----------------------------------------------------------------------------------

#: The longest line a log may have, in characters: a pose line is a few dozen, a logger's
#: widest row a few thousand; more is not a log (a file of NULs, a stray binary), and a reader
#: that waits for its end would hold it whole.
MAX_LINE_CHARS = 1 << 20


def split_lines(text: str) -> list[str]:
    """The lines of a log's text, split where an editor splits them: at ``\\n``, ``\\r\\n``
    and ``\\r`` only.

    :meth:`str.splitlines` also ends a line at a form feed, a record separator, U+2028 and
    more; in a log those are stray bytes inside a line.  Every reader of a log (whole,
    streamed, live) splits here, so they number its lines alike and read the same rows."""
    lines = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
    if lines[-1] == "":
        lines.pop()
    return lines


def _complete(data: bytes) -> int:
    """How many bytes of ``data`` are whole lines: up to its last ``\\n``, or its last
    ``\\r`` when more follows (a ``\\r`` at the very end may be the first half of
    ``\\r\\n``)."""
    return max(data.rfind(b"\n"), data.rfind(b"\r", 0, len(data) - 1)) + 1


class LogLines:
    """The lines of a log whose bytes come a block at a time (a file read in blocks, a pipe,
    a file that grows): split by :func:`split_lines`, decoded as UTF-8 with a byte-order mark
    at the start skipped, numbered from 1.

    A line that is not UTF-8 is refused (M050) at its line and column, a line longer than
    :data:`MAX_LINE_CHARS` (M053) as soon as it is known to be: memory stays one block and
    one line."""

    def __init__(self, file: str) -> None:
        self.file = file
        #: the lines given so far (the next one is line ``count + 1``)
        self.count = 0
        #: the bytes of a line whose end has not come yet
        self.rest = b""
        self._offset = 0  # bytes of the log before ``rest``

    def feed(self, data: bytes) -> list[str]:
        """The lines ``data`` completes, in order (the last is line :attr:`count`)."""
        data = self.rest + data if self.rest else data
        cut = _complete(data)
        self.rest = data[cut:]
        lines = self._lines(data[:cut])
        # Each character is at most 4 bytes: a rest longer than this is surely too long.
        if len(self.rest) > 4 * MAX_LINE_CHARS:
            raise self._too_long(self.count + 1)
        return lines

    def finish(self) -> list[str]:
        """The last line, when the log does not end with a line break."""
        rest, self.rest = self.rest, b""
        return self._lines(rest)

    def _lines(self, data: bytes) -> list[str]:
        start = 3 if self._offset == 0 and data.startswith(b"\xef\xbb\xbf") else 0
        try:
            text = data[start:].decode("utf-8")
        except UnicodeDecodeError as exc:
            before = split_lines(data[start : start + exc.start].decode("utf-8") + "|")
            raise _fail(
                "M050",
                f"the log {self.file} is not UTF-8 text ({exc.reason} at byte "
                f"{self._offset + start + exc.start})",
                self.file,
                hint="save it as UTF-8 text",
                line=self.count + len(before),
                col=len(before[-1]),
            ) from None
        self._offset += len(data)
        lines = split_lines(text)
        if len(text) > MAX_LINE_CHARS:
            for index, line in enumerate(lines):
                if len(line) > MAX_LINE_CHARS:
                    raise self._too_long(self.count + index + 1)
        self.count += len(lines)
        return lines

    def _too_long(self, number: int) -> UsageError:
        return _fail(
            "M053",
            f"line {number} is longer than {MAX_LINE_CHARS:,} characters: not a line of a log",
            self.file,
            hint="a log line holds one pose (t, x, y and a few more columns); is this the "
            "right file?",
            line=number,
        )


def read_log_lines(path: Path) -> list[str]:
    """The lines of the CSV log at ``path``, read whole (at most :data:`MAX_CSV_BYTES`; a
    regular file only, M050), as :class:`LogLines` reads them."""
    from tlmpc.io.inputs import read_bytes

    reader = LogLines(str(path))
    data = read_bytes(path, limit=MAX_CSV_BYTES, code="M050", what="log")
    return reader.feed(data) + reader.finish()


# --- CSV -------------------------------------------------------------------------------------

_SEPARATORS = (",", ";", "\t")


def _split(line: str, separator: str | None) -> list[str]:
    cells = line.split(separator) if separator else line.split()
    return [c.strip().strip('"').strip("'").strip() for c in cells]


def _number(cell: str) -> float:
    """``cell`` as a number, as numpy's reader takes it (ValueError otherwise): Python's
    ``float`` alone would also read ``1_0`` as 10."""
    if "_" in cell:
        raise ValueError(cell)
    return float(cell)


def _is_number(cell: str) -> bool:
    try:
        _number(cell)
    except ValueError:
        return False
    return True


#: The column (1-based) where cell i of a log's line starts, or None when not known.
CellColumn = Callable[[int], "int | None"]


def _unknown_column(_: int) -> int | None:
    return None


def _pick(
    names: list[str], wanted: str, file: str, line: int, column: CellColumn = _unknown_column
) -> int:
    if wanted.isdigit():
        index = int(wanted) - 1
        if not 0 <= index < len(names):
            raise _fail(
                "M052",
                f"column {wanted} does not exist: the log has {len(names)} columns",
                file,
                hint="--columns numbers count the columns from 1",
                line=line,
                col=column(0),
            )
        return index
    lowered = [n.lower() for n in names]
    if wanted.lower() in lowered:
        return lowered.index(wanted.lower())
    raise _fail(
        "M052",
        f"no column named {wanted!r}; the columns are {', '.join(names) or '(none)'}",
        file,
        hint="choose with --columns TIME,X,Y (names or 1-based numbers)",
        line=line,
        col=column(0),
    )


def _guess(
    names: list[str], file: str, line: int, column: CellColumn = _unknown_column
) -> tuple[int, int, int]:
    lowered = [n.lower() for n in names]

    def find(exact: tuple[str, ...], suffixes: tuple[str, ...], what: str) -> int:
        for name in exact:
            if name in lowered:
                return lowered.index(name)
        hits = [i for i, n in enumerate(lowered) if n.endswith(suffixes)]
        if len(hits) == 1:
            return hits[0]
        found = ", ".join(names)
        if hits:
            choices = ", ".join(names[i] for i in hits)
            message = f"several columns could be {what}: {choices}"
        else:
            message = f"no {what} column among: {found}"
        raise _fail(
            "M052",
            message,
            file,
            hint="name the columns t (or time), x, y, or choose them with --columns TIME,X,Y",
            line=line,
            col=column(hits[0] if hits else 0),
        )

    time_index = find(TIME_NAMES, ("_time", ".time", ".stamp", "_stamp"), "time")
    x_index = find(("x",), (".x", "_x"), "x")
    y_index = find(("y",), (".y", "_y"), "y")
    return time_index, x_index, y_index


def parse_columns(text: str) -> tuple[str, str, str]:
    """``--columns TIME,X,Y``: three names or 1-based numbers."""
    parts = [p.strip() for p in text.split(",")]
    if len(parts) != 3 or not all(parts):
        raise _fail(
            "M051",
            f"--columns needs three comma-separated names or numbers, got {text!r}",
            "<command line>",
            hint="for example --columns time,pos_x,pos_y or --columns 1,3,4",
        )
    return parts[0], parts[1], parts[2]


def _layout(
    cells: list[str],
    columns: Sequence[str] | None,
    file: str,
    number: int,
    column: CellColumn = _unknown_column,
) -> tuple[bool, tuple[int, int, int]]:
    """Whether the first data line (line ``number``, cut into ``cells``, whose starts are
    ``column``) is a header, and the columns of t, x, y."""
    header = not all(_is_number(c) for c in cells if c)
    if header:
        if columns is not None:
            chosen = tuple(_pick(cells, c, file, number, column) for c in columns)
            return True, (chosen[0], chosen[1], chosen[2])
        return True, _guess(cells, file, number, column)
    if columns is not None:
        if not all(c.isdigit() for c in columns):
            raise _fail(
                "M052",
                "the log has no header line, so --columns must give column numbers",
                file,
                hint="for example --columns 1,2,3",
                line=number,
                col=column(0),
            )
        chosen = tuple(_pick(cells, c, file, number, column) for c in columns)
        return False, (chosen[0], chosen[1], chosen[2])
    if len(cells) != 3:
        raise _fail(
            "M052",
            f"no header line and {len(cells)} columns: cannot tell which are t, x, y",
            file,
            hint="add a header line naming t (or time), x, y, or pass --columns",
            line=number,
            col=column(3 if len(cells) > 3 else 0),
        )
    return False, (0, 1, 2)


def _cell_column(raw: str, separator: str | None, index: int) -> int:
    """The 1-based column where cell ``index`` of the line ``raw`` (as :func:`_split` cuts
    it) shows its first character (past spaces and quotes)."""
    stripped = raw.strip()
    start = len(raw) - len(raw.lstrip())
    if separator:
        start += sum(len(cell) + len(separator) for cell in stripped.split(separator)[:index])
    else:
        start += [m.start() for m in re.finditer(r"\S+", stripped)][index]
    while start < len(raw) and (raw[start].isspace() or raw[start] in "\"'"):
        start += 1
    return start + 1


def _columns_of(raw: str, separator: str | None) -> CellColumn:
    """Where each cell of the line ``raw`` starts (see :func:`_cell_column`)."""
    return lambda index: _cell_column(raw, separator, index)


def _row(
    raw: str, separator: str | None, indices: tuple[int, int, int], file: str, number: int
) -> list[float]:
    """The ``t, x, y`` of the line ``raw`` (line ``number``); M053 for a short row or a cell
    that is not a number, at that cell."""
    cells = _split(raw.strip(), separator)
    if len(cells) <= max(indices):
        raise _fail(
            "M053",
            f"row has {len(cells)} columns, expected at least {max(indices) + 1}",
            file,
            hint="every row needs the time and position columns; is the line cut short? "
            "Complete or delete it",
            line=number,
            col=len(raw.rstrip()) + 1,
        )
    try:
        return [_number(cells[i]) for i in indices]
    except ValueError:
        bad = next(i for i in indices if not _is_number(cells[i]))
        raise _fail(
            "M053",
            f"not a number: {cells[bad]!r}",
            file,
            hint="the time and position columns hold a number on every row; correct or "
            "delete the line",
            line=number,
            col=_cell_column(raw, separator, bad),
        ) from None


def read_csv_log(path: Path, columns: Sequence[str] | None = None) -> Log:
    """A CSV/TSV/whitespace log; see the module docstring for the accepted forms."""
    file = str(path)
    separator: str | None = None
    indices: tuple[int, int, int] | None = None
    rows: list[list[float]] = []
    lines: list[int] = []
    first = True
    for number, raw in enumerate(read_log_lines(path), start=1):
        stripped = raw.strip()
        if not stripped or stripped.startswith("#"):
            continue
        if first:
            first = False
            separator = next((s for s in _SEPARATORS if s in stripped), None)
            header, indices = _layout(
                _split(stripped, separator), columns, file, number, _columns_of(raw, separator)
            )
            if header:
                continue
        assert indices is not None
        rows.append(_row(raw, separator, indices, file, number))
        lines.append(number)
        if len(rows) > MAX_LOG_SAMPLES:
            raise _fail(
                "M066",
                f"the log has more than {MAX_LOG_SAMPLES:,} samples",
                file,
                hint="verify a shorter stretch of the log, or thin it out",
                line=number,
            )
    samples = np.asarray(rows, dtype=np.float64).reshape(-1, 3)
    layout = (separator, indices) if indices is not None else None
    return Log(samples=samples, lines=tuple(lines), source=file, layout=layout)


#: Bytes read at a time by :func:`iter_csv_chunks`.
BLOCK_BYTES = 1 << 22


def _fast_rows(
    lines: list[str], separator: str | None, indices: tuple[int, int, int]
) -> FloatArray | None:
    """The rows of plain lines at C speed (numpy's reader, whose numbers are Python's
    ``float`` of the same text); None when any line needs the line-by-line parser's care
    (a quoted cell, a short row, a blank line, a number only ``float`` reads)."""
    try:
        rows = np.loadtxt(
            lines,
            delimiter=separator,
            usecols=indices,
            ndmin=2,
            comments=None,
            dtype=np.float64,
        )
    except ValueError:
        return None
    return rows if len(rows) == len(lines) else None


def iter_csv_chunks(
    path: Path, columns: Sequence[str] | None = None, block_bytes: int = BLOCK_BYTES
) -> Iterator[Log]:
    """The samples of a CSV log, ``block_bytes`` bytes at a time, never the whole file.

    Accepts exactly what :func:`read_csv_log` accepts and gives the same samples and line
    numbers, in order; a problem is raised when its block is reached.
    """
    from tlmpc.io.inputs import open_regular

    file = str(path)
    require_path(path)
    separator: str | None = None
    indices: tuple[int, int, int] | None = None
    reader = LogLines(file)
    try:
        with open_regular(path, code="M050", what="log") as stream:
            while True:
                data = stream.read(block_bytes)
                lines = reader.feed(data) if data else reader.finish()
                first_number = reader.count - len(lines) + 1
                if indices is None:
                    for offset, raw in enumerate(lines):
                        stripped = raw.strip()
                        if not stripped or stripped.startswith("#"):
                            continue
                        separator = next((s for s in _SEPARATORS if s in stripped), None)
                        header, indices = _layout(
                            _split(stripped, separator),
                            columns,
                            file,
                            first_number + offset,
                            _columns_of(raw, separator),
                        )
                        skip = offset + 1 if header else offset
                        lines, first_number = lines[skip:], first_number + skip
                        break
                if indices is not None and lines:
                    plain = all(line and "#" not in line for line in lines)
                    chunk = _chunk(lines, first_number, separator, indices, file, plain)
                    if len(chunk.samples):
                        yield chunk
                if not data:
                    return
    except OSError as exc:  # a read that fails (a disk error): the system's reason
        raise _fail("M050", f"cannot read {file}: {exc.strerror or exc}", file) from None


def _chunk(
    lines: list[str],
    first_number: int,
    separator: str | None,
    indices: tuple[int, int, int],
    file: str,
    plain: bool,
) -> Log:
    """The samples of consecutive lines (the first is line ``first_number``); ``plain``: no
    line is a comment or empty (for the fast parser)."""
    numbers = range(first_number, first_number + len(lines))
    samples = _fast_rows(lines, separator, indices) if plain and lines else None
    if samples is not None:
        return Log(samples=samples, lines=tuple(numbers), source=file)
    rows: list[list[float]] = []
    kept: list[int] = []
    for raw, number in zip(lines, numbers, strict=True):
        stripped = raw.strip()
        if not stripped or stripped.startswith("#"):
            continue
        rows.append(_row(raw, separator, indices, file, number))
        kept.append(number)
    return Log(
        samples=np.asarray(rows, dtype=np.float64).reshape(-1, 3),
        lines=tuple(kept),
        source=file,
    )


def apply_transform(
    samples: FloatArray, transform: tuple[float, float, float] | None
) -> FloatArray:
    """``samples`` moved by the rigid ``(x, y, yaw)`` (see :func:`read_log`)."""
    return _apply(samples, transform)


class CsvLines:
    """A CSV log read one line at a time (a live log): the same header rules, columns and
    numbers as :func:`read_csv_log`."""

    def __init__(self, file: str, columns: Sequence[str] | None = None) -> None:
        self.file = file
        self.columns = columns
        self.separator: str | None = None
        self.indices: tuple[int, int, int] | None = None

    def parse(self, raw: str, number: int) -> tuple[float, float, float] | None:
        """The sample on line ``number``; None for a blank, comment or header line."""
        stripped = raw.strip()
        if not stripped or stripped.startswith("#"):
            return None
        if self.indices is None:
            self.separator = next((s for s in _SEPARATORS if s in stripped), None)
            header, self.indices = _layout(
                _split(stripped, self.separator),
                self.columns,
                self.file,
                number,
                _columns_of(raw, self.separator),
            )
            if header:
                return None
        t, x, y = _row(raw, self.separator, self.indices, self.file, number)
        return t, x, y

    def column(self, raw: str, cell: int) -> int | None:
        """The column of cell ``cell`` (0 time, 1 x, 2 y) on the line ``raw`` (None before the
        columns are known)."""
        if self.indices is None:
            return None
        return _cell_column(raw, self.separator, self.indices[cell])


# --- ROS bags ---------------------------------------------------------------------------------


def _bag_paths(path: Path) -> Path:
    """The path rosbags opens: a ROS 2 ``.db3`` file opens through its bag directory."""
    if path.suffix.lower() == ".db3" and (path.parent / "metadata.yaml").is_file():
        return path.parent
    return path


def _listing(connections: Sequence[tuple[str, str, int]]) -> str:
    return "; ".join(f"{topic} ({kind}, {count} messages)" for topic, kind, count in connections)


def read_bag(path: Path, topic: str | None = None, frame: str | None = None) -> Log:
    """Poses from a ROS 1 bag, a ROS 2 bag directory or an MCAP file, sorted by stamp.

    With ``frame``, each pose is expressed in that frame through the bag's ``/tf`` and
    ``/tf_static`` at its stamp (see :mod:`tlmpc.importers.frames`).  The poses are gathered in
    flat arrays (24 bytes a message); :func:`iter_bag_chunks` reads in constant memory.
    """
    stamps = array("q")
    xs = array("d")
    ys = array("d")
    with _opened_bag(path, topic) as (reader, chosen, chosen_topic):
        for chunk in _pose_chunks(reader, chosen, frame, str(path), BAG_CHUNK):
            stamps.extend(chunk[0])
            xs.extend(chunk[1])
            ys.extend(chunk[2])
    samples, messages = _sorted_samples(stamps, xs, ys)
    return Log(samples=samples, source=str(path), topic=chosen_topic, messages=messages)


#: Poses per chunk of :func:`iter_bag_chunks` (and of the whole reader's gathering).
BAG_CHUNK = 8_192


#: Bags with more pose messages than this are verified as a stream (``tlmpc verify``): memory
#: constant in the number of messages instead of growing with it.
BAG_STREAM_FROM = 100_000


def bag_pose_count(path: Path, topic: str | None = None) -> int:
    """How many messages the bag's pose topic declares (its index; the reader's diagnostics)."""
    with _opened_bag(path, topic, limit=False) as (_, chosen, _):
        return sum(int(c.msgcount) for c in chosen)


class BagOutOfOrder(Exception):
    """The bag's pose stamps go back in time where it was read in order: it cannot be streamed
    (a stream cannot be sorted); read it whole with :func:`read_bag` instead."""


def iter_bag_chunks(
    path: Path,
    topic: str | None = None,
    frame: str | None = None,
    chunk: int = BAG_CHUNK,
) -> Iterator[FloatArray]:
    """The bag's poses ``[t, x, y]`` in chunks of at most ``chunk``, in the order the bag
    stores them, holding one chunk at a time (memory constant in the number of messages).

    Raises :class:`BagOutOfOrder` at the first stamp earlier than the one before it (a
    recording whose header stamps disagree with its log times); the diagnostics and the
    message limit (M060–M066, M102–M106) are :func:`read_bag`'s.
    """
    previous: tuple[int, float] | None = None  # the last stamp and its seconds
    with _opened_bag(path, topic) as (reader, chosen, _):
        for stamps, xs, ys in _pose_chunks(reader, chosen, frame, str(path), chunk):
            ordered = np.asarray(stamps, dtype=np.int64)
            if len(ordered) and (
                (previous is not None and ordered[0] < previous[0]) or np.any(np.diff(ordered) < 0)
            ):
                raise BagOutOfOrder(str(path))
            seconds = stamp_seconds(ordered, previous)
            if len(ordered):
                previous = int(ordered[-1]), float(seconds[-1])
            yield np.column_stack(
                [seconds, np.asarray(xs, dtype=np.float64), np.asarray(ys, dtype=np.float64)]
            ).reshape(-1, 3)


@contextlib.contextmanager
def _opened_bag(
    path: Path, topic: str | None, *, limit: bool = True
) -> Iterator[tuple[Any, list[Any], str]]:
    """The open reader, the chosen pose connections and their topic (diagnostics M060–M066;
    M066 for a declared count over the limit only with ``limit``).  A sqlite3 bag passes
    SQLite's ``quick_check`` first (M060): a damaged database can answer with fewer rows."""
    require("rosbags.highlevel", "reading a ROS bag or MCAP log", file=str(path))
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    file = str(path)
    _check_bag_path(path, file)
    try:
        reader = AnyReader([_bag_paths(path)], default_typestore=get_typestore(Stores.ROS2_HUMBLE))
        reader.open()
    except Exception as exc:
        problem, hint = reader_failure(exc, path)
        raise _fail(
            "M060",
            f"cannot open the bag: {problem}",
            file,
            hint=hint
            or "expected a ROS 1 .bag, a ROS 2 bag directory (sqlite3 or MCAP) or a .mcap file",
        ) from None
    try:
        damage = sqlite_damage(path)
        if damage is not None:
            raise _fail("M060", f"cannot open the bag: {damage[0]}", file, hint=damage[1])
        chosen, topic = _chosen_connections(reader, topic, file)
        declared = sum(int(c.msgcount) for c in chosen)
        if limit and declared > MAX_LOG_SAMPLES:
            raise _too_many(file)
        yield reader, chosen, topic
    finally:
        reader.close()


def _chosen_connections(reader: Any, topic: str | None, file: str) -> tuple[list[Any], str]:
    everything = [(c.topic, c.msgtype, c.msgcount) for c in reader.connections]
    poses = [c for c in reader.connections if c.msgtype in POSE_TYPES]
    if topic is not None:
        chosen = [c for c in reader.connections if c.topic == topic]
        if not chosen:
            raise _fail(
                "M062",
                f"the bag has no topic {topic!r}",
                file,
                hint=f"topics: {_listing(everything) or '(none)'}",
            )
        wrong = [c for c in chosen if c.msgtype not in POSE_TYPES]
        if wrong:
            listing = _listing([(c.topic, c.msgtype, c.msgcount) for c in poses])
            raise _fail(
                "M063",
                f"topic {topic!r} carries {wrong[0].msgtype}, not a pose",
                file,
                hint="pose topics carry "
                + ", ".join(POSE_TYPES)
                + (f"; this bag has {listing}" if poses else ""),
            )
        return chosen, topic
    topics = sorted({c.topic for c in poses})
    if not topics:
        raise _fail(
            "M061",
            "the bag has no pose topic (nav_msgs/Odometry, geometry_msgs/PoseStamped "
            "or PoseWithCovarianceStamped)",
            file,
            hint=f"topics: {_listing(everything) or '(none)'}",
        )
    if len(topics) > 1:
        listing = _listing([(c.topic, c.msgtype, c.msgcount) for c in poses])
        raise _fail(
            "M064",
            f"the bag has {len(topics)} pose topics; choose one with --topic",
            file,
            hint=listing,
        )
    return [c for c in poses if c.topic == topics[0]], topics[0]


def _pose_chunks(
    reader: Any, chosen: list[Any], frame: str | None, file: str, size: int
) -> Iterator[tuple[list[int], list[float], list[float]]]:
    """The poses (stamp ns, x, y) of ``chosen`` in stored order, ``size`` at a time, in
    ``frame`` when given; counts them against :data:`MAX_LOG_SAMPLES` as they come, and at the
    end against the counts the bag declares (M065, :func:`counted_messages`)."""
    tree: Any = None
    count = 0
    reading: str | None = None  # the message being read, in words
    try:
        batch: list[tuple[int, float, float, float, str]] = []
        for connection, log_time, raw in counted_messages(reader, chosen, Path(file)):
            reading = message_words(count, connection.topic, log_time)
            message: Any = reader.deserialize(raw, connection.msgtype)
            pose: Any = message
            for part in POSE_TYPES[connection.msgtype].split("."):
                pose = getattr(pose, part)
            stamp = message.header.stamp
            nanoseconds = int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)
            when = nanoseconds if nanoseconds else int(log_time)
            count += 1
            if count > MAX_LOG_SAMPLES:  # a bag whose index understates its messages
                raise _too_many(file)
            position = pose.position
            batch.append(
                (
                    when,
                    float(position.x),
                    float(position.y),
                    float(position.z),
                    str(message.header.frame_id) if frame is not None else "",
                )
            )
            if len(batch) == size:
                tree = yield from _emit(reader, batch, frame, tree, file)
                batch = []
        if batch:
            yield from _emit(reader, batch, frame, tree, file)
    except UsageError:
        raise
    except Exception as exc:
        raise unreadable_message(exc, Path(file), reading) from None


#: The hint of a message that does not decode, when the reader finds no damage in the file.
UNDECODABLE_HINT = (
    "the message's bytes do not decode as its type: the bag is damaged, or was recorded with "
    "another definition of the type; compare it with the robot's own copy"
)


def unreadable_message(exc: BaseException, path: Path, reading: str | None) -> UsageError:
    """M065 for a bag whose messages cannot be read (``exc``, raised by the reader while
    ``reading`` the message so described), with where the file is damaged when that is found."""
    problem, hint = reader_failure(exc, path)
    return _fail(
        "M065",
        f"cannot read the bag's messages: {problem}" + (f" ({reading})" if reading else ""),
        str(path),
        hint=hint or UNDECODABLE_HINT,
    )


def _emit(
    reader: Any,
    batch: list[tuple[int, float, float, float, str]],
    frame: str | None,
    tree: Any,
    file: str,
) -> Generator[tuple[list[int], list[float], list[float]], None, Any]:
    """One chunk of poses, in ``frame`` when given; returns the tf tree (read on first need,
    once per bag) for the next chunk."""
    from tlmpc.importers.frames import frame_name

    if frame is None or all(frame_name(f) == frame_name(frame) for *_, f in batch):
        yield [p[0] for p in batch], [p[1] for p in batch], [p[2] for p in batch]
        return tree
    if tree is None:
        tree = _tf_tree(reader, sorted({f for *_, f in batch}), frame, file)
    stamps = np.asarray([p[0] for p in batch], dtype=np.int64)
    positions = np.asarray([p[1:4] for p in batch], dtype=np.float64).reshape(-1, 3)
    sources = np.asarray([frame_name(p[4]) for p in batch])
    result = np.empty_like(positions)
    for source in sorted(set(sources.tolist())):
        picked = sources == source
        result[picked] = tree.express(frame, source, stamps[picked], positions[picked])
    yield stamps.tolist(), result[:, 0].tolist(), result[:, 1].tolist()
    return tree


def _too_many(file: str) -> UsageError:
    return _fail(
        "M066",
        f"the bag's pose topic has more than {MAX_LOG_SAMPLES:,} messages",
        file,
        hint="verify a shorter stretch of the recording (e.g. `ros2 bag convert` or "
        "`rosbag filter` by time)",
    )


def _check_bag_path(path: Path, file: str) -> None:
    """A bag is a regular file or a ROS 2 bag directory: never a device or a FIFO, which
    would be read without end or block."""
    import os
    import stat

    try:
        mode = os.stat(path).st_mode
    except OSError:
        problem = path_problem(path) or "it cannot be looked at"
        raise _fail("M050", f"cannot read {file}: {problem}", file, hint=_path_hint(path)) from None
    if not (stat.S_ISREG(mode) or stat.S_ISDIR(mode)):
        raise _fail(
            "M060",
            f"{file} is not a regular file or a bag directory",
            file,
            hint="tlmpc reads only regular files (no devices, pipes or sockets)",
        )


def _tf_tree(reader: Any, logged: list[str], frame: str, file: str) -> Any:
    """The transform tree of the bag's ``/tf`` and ``/tf_static`` (read in a pass of its own);
    M102 when it has none while poses are in ``logged`` frames other than ``frame``."""
    from tlmpc.importers.frames import TF_TYPE, TransformCollector

    connections = [c for c in reader.connections if c.msgtype == TF_TYPE]
    if not connections:
        raise _fail(
            "M102",
            f"--frame {frame}: the poses are in {', '.join(map(repr, logged))} and the bag has "
            "no /tf or /tf_static (tf2_msgs/TFMessage) to transform them with",
            file,
            hint="record /tf and /tf_static with the poses, or give a fixed transform with "
            "--transform X,Y,YAW instead of --frame",
        )
    collector = TransformCollector(file)
    for connection, _, raw in counted_messages(reader, connections, Path(file)):
        message: Any = reader.deserialize(raw, connection.msgtype)
        static = connection.topic.rstrip("/").endswith("tf_static")
        for transform in message.transforms:
            stamp = transform.header.stamp
            t, r = transform.transform.translation, transform.transform.rotation
            collector.add(
                parent=str(transform.header.frame_id),
                child=str(transform.child_frame_id),
                stamp=int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec),
                translation=(float(t.x), float(t.y), float(t.z)),
                rotation=(float(r.x), float(r.y), float(r.z), float(r.w)),
                static=static,
            )
    return collector.tree()


def _sorted_samples(
    stamps: array[int], xs: array[float], ys: array[float]
) -> tuple[FloatArray, npt.NDArray[np.int64]]:
    """Sorted by integer nanoseconds (exact, stable), then seconds; with the stored number of
    each sample's message (:attr:`Log.messages`).

    Repeated stamps are kept: the verifier refuses them (V020) as it does in a CSV log, since
    two poses at one instant are not a trajectory and keeping one would hide the other."""
    nanoseconds = np.frombuffer(stamps, dtype=np.int64) if len(stamps) else np.zeros(0, np.int64)
    order = np.argsort(nanoseconds, kind="stable")
    samples = np.empty((len(stamps), 3), dtype=np.float64)
    samples[:, 0] = stamp_seconds(nanoseconds[order])
    samples[:, 1] = np.frombuffer(xs, dtype=np.float64)[order] if len(xs) else 0.0
    samples[:, 2] = np.frombuffer(ys, dtype=np.float64)[order] if len(ys) else 0.0
    return samples, order.astype(np.int64, copy=False)


#: The bits of a float64 below its sign (see :func:`stamp_seconds`).
_MAGNITUDE = np.int64(0x7FFF_FFFF_FFFF_FFFF)


def _ordered(keys: npt.NDArray[np.int64]) -> npt.NDArray[np.int64]:
    """Float64 bit patterns to integers in the floats' order, and back (its own inverse):
    consecutive floats are consecutive integers."""
    return keys ^ ((keys >> 63) & _MAGNITUDE)


def stamp_seconds(
    nanoseconds: npt.NDArray[np.int64], previous: tuple[int, float] | None = None
) -> FloatArray:
    """Seconds of integer-nanosecond stamps in non-decreasing order, distinct where they are.

    Each is ``ns / 1e9``, as a CSV written from the log has it.  But a float64 second has a
    step of 238 ns at a ROS epoch (1.7e9 s), so stamps closer than that would round to one
    time, which the verifier refuses as a repeated stamp (V020): where a stamp is later than
    the one before and its seconds are not, they become the next float above the seconds
    before (off by a fraction of a microsecond, in the stamps' order).  Equal stamps stay
    equal.  ``previous``: the last stamp and seconds before these (a stream's chunk before).
    """
    stamps = np.asarray(nanoseconds, dtype=np.int64)
    if previous is not None:
        stamps = np.concatenate([np.asarray([previous[0]], dtype=np.int64), stamps])
    seconds = stamps / 1e9
    if previous is not None:
        seconds[0] = previous[1]
    rises = np.diff(stamps) > 0
    if np.any(rises & (np.diff(seconds) <= 0)):
        # k'[i] = max(k[i], k'[i-1] + rise[i]) on the ordered bit patterns k, in closed form:
        # with c the running count of rises, k'[i] = c[i] + max over j <= i of (k[j] - c[j]).
        count = np.concatenate([np.zeros(1, dtype=np.int64), np.cumsum(rises, dtype=np.int64)])
        keys = _ordered(seconds.view(np.int64))
        keys = count + np.maximum.accumulate(keys - count)
        seconds = _ordered(keys).view(np.float64)
    return seconds[1:] if previous is not None else seconds


_TRANSFORM = re.compile(r"^\s*(\S+)\s*,\s*(\S+)\s*,\s*(\S+)\s*$")


def parse_transform(text: str) -> tuple[float, float, float]:
    """``--transform X,Y,YAW`` (yaw in radians)."""
    match = _TRANSFORM.match(text)
    try:
        if match is None:
            raise ValueError
        values = tuple(float(v) for v in match.groups())
        if not all(math.isfinite(v) for v in values):
            raise ValueError
    except ValueError:
        raise _fail(
            "M051",
            f"--transform needs X,Y,YAW (numbers, yaw in radians), got {text!r}",
            "<command line>",
        ) from None
    return values[0], values[1], values[2]
