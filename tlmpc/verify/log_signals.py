"""Sensor and action values from a robot log, for verifying a reactive mission's run.

Each sensor's samples come from its binding in the mission (docs/robot-data.md):

* a CSV log: the column ``column``, else the column named like the sensor, with the log's time
  column; an empty cell is no sample (the value holds);
* a bag: the field ``field`` (default ``data``, as in ``std_msgs/Bool``) of the messages on
  ``topic``, else on the topic named like the sensor (``/alarm`` or ``alarm``); each sample
  is stamped with its header stamp when the message has a non-zero one, else its log time.

Values are booleans: true/false or 1/0 (V030 for anything else, at its line or message).  A
sensor missing from the log is refused (V032): its values decide the verdict.  An action
missing from the log is left unknown (the verdict may then be inconclusive).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from tlmpc.base.errors import UsageError, error
from tlmpc.verify.signals import Signal, Where, make_signal

if TYPE_CHECKING:
    from tlmpc.mission.model import Reactive, Sensor

#: The field read from a sensor's bag messages when its binding names none.
DEFAULT_FIELD = "data"


def read_signals(
    path: Path, reactive: Reactive, columns: Sequence[str] | None = None
) -> dict[str, Signal]:
    """The sensors' (and the logged actions') signals in the log at ``path``."""
    from tlmpc.importers.logs import CSV_SUFFIXES

    if path.suffix.lower() in CSV_SUFFIXES and not path.is_dir():
        return _csv_signals(path, reactive, columns)
    return _bag_signals(path, reactive)


def _missing(file: str, what: str, hint: str) -> UsageError:
    return UsageError(error("V032", what, hint=hint, file=file))


# --- CSV ----------------------------------------------------------------------------------


def _csv_signals(
    path: Path, reactive: Reactive, columns: Sequence[str] | None
) -> dict[str, Signal]:
    from tlmpc.importers.logs import _SEPARATORS, _layout, _split, read_log_lines

    file = str(path)
    rows = [
        (number, raw.strip())
        for number, raw in enumerate(read_log_lines(path), start=1)
        if raw.strip() and not raw.strip().startswith("#")
    ]
    if not rows:
        return {}
    number, first = rows[0]
    separator = next((s for s in _SEPARATORS if s in first), None)
    header = _split(first, separator)
    has_header, indices = _layout(header, columns, file, number)
    if not has_header:
        raise _missing(
            file,
            "the log has no header line, so its sensor columns cannot be found",
            "add a header line naming the columns (t, x, y and one per sensor)",
        )
    lowered = [name.lower() for name in header]
    wanted: list[tuple[str, str, bool]] = [
        (s.name, s.column or s.name, True) for s in reactive.sensors
    ] + [(a, a, False) for a in reactive.actions]
    found: dict[str, Signal] = {}
    body = [(n, _split(line, separator)) for n, line in rows[1:]]
    for name, column, needed in wanted:
        if column.lower() not in lowered:
            if needed:
                raise _missing(
                    file,
                    f"sensor {name!r}: the log has no column {column!r}",
                    f"the columns are {', '.join(header)}; bind the sensor to its column "
                    "in the mission (sensors: {" + f"{name}: {{column: NAME}}" + "})",
                )
            continue
        index = lowered.index(column.lower())
        times: list[Any] = []
        values: list[Any] = []
        lines: list[int] = []
        for line, cells in body:
            cell = cells[index] if index < len(cells) else ""
            if not cell:
                continue  # no sample of this signal on this row: the value holds
            times.append(float(cells[indices[0]]))
            values.append(cell)
            lines.append(line)
        found[name] = make_signal(name, times, values, Where(file, lines=lines))
    return found


# --- bags ---------------------------------------------------------------------------------


def _topic_for(sensor: Sensor | str, topics: Sequence[str]) -> str | None:
    if not isinstance(sensor, str) and sensor.topic is not None:
        return sensor.topic if sensor.topic in topics else None
    name = sensor if isinstance(sensor, str) else sensor.name
    for topic in topics:
        if topic.strip("/") == name:
            return topic
    return None


def _field(message: Any, dotted: str) -> Any:
    value = message
    for part in dotted.split("."):
        value = getattr(value, part)
    return value


def _stamp(message: Any, log_time: int) -> int:
    header = getattr(message, "header", None)
    stamp = getattr(header, "stamp", None)
    if stamp is not None:
        nanoseconds = int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)
        if nanoseconds:
            return nanoseconds
    return int(log_time)


def _origin(samples: Sequence[tuple[int, Any, int, int]], topic: str) -> Callable[[int], str]:
    """The message of each of a topic's ``samples`` (stamp, value, stored number, log time),
    in words, as the pose samples name theirs."""
    from tlmpc.importers.logs import message_words

    return lambda index: message_words(samples[index][2], topic, samples[index][3], "message")


def _bag_signals(path: Path, reactive: Reactive) -> dict[str, Signal]:
    # the pose reader has already opened this bag (and said why, if it could not)
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    from tlmpc.importers.bag_counts import counted_messages
    from tlmpc.importers.logs import (
        MAX_LOG_SAMPLES,
        _bag_paths,
        message_words,
        stamp_seconds,
        unreadable_message,
    )

    file = str(path)
    reading: str | None = None  # the message being read, in words
    reader = AnyReader([_bag_paths(path)], default_typestore=get_typestore(Stores.ROS2_HUMBLE))
    reader.open()
    try:
        topics = sorted({c.topic for c in reader.connections})
        listing = ", ".join(
            f"{c.topic} ({c.msgtype})" for c in sorted(reader.connections, key=lambda c: c.topic)
        )
        wanted: list[tuple[str, Sensor | str, str, bool]] = [
            (s.name, s, s.field or DEFAULT_FIELD, True) for s in reactive.sensors
        ] + [(a, a, DEFAULT_FIELD, False) for a in reactive.actions]
        found: dict[str, Signal] = {}
        for name, binding, dotted, needed in wanted:
            topic = _topic_for(binding, topics)
            if topic is None:
                if needed:
                    asked = binding.topic if not isinstance(binding, str) else None
                    raise _missing(
                        file,
                        f"sensor {name!r}: the bag has no topic "
                        + (repr(asked) if asked else f"named {name!r} (or '/{name}')"),
                        f"topics: {listing or '(none)'}; bind the sensor in the mission "
                        "(sensors: {" + f"{name}: {{topic: /TOPIC, field: data}}" + "})",
                    )
                continue
            chosen = [c for c in reader.connections if c.topic == topic]
            if sum(int(c.msgcount) for c in chosen) > MAX_LOG_SAMPLES:
                raise UsageError(
                    error(
                        "M066",
                        f"topic {topic} has more than {MAX_LOG_SAMPLES:,} messages",
                        file=file,
                    )
                )
            # (stamp, value, stored number, log time): the last two name a refused sample
            samples: list[tuple[int, Any, int, int]] = []
            for connection, log_time, raw in counted_messages(reader, chosen, path):
                reading = message_words(len(samples), connection.topic, log_time, "message")
                message: Any = reader.deserialize(raw, connection.msgtype)
                try:
                    value = _field(message, dotted)
                except AttributeError:
                    raise UsageError(
                        error(
                            "V035",
                            f"signal {name!r}: the messages on {topic} "
                            f"({connection.msgtype}) have no field {dotted!r}",
                            hint="name the boolean field with `field:` in the sensor's "
                            "binding (e.g. data for std_msgs/Bool)",
                            file=file,
                        )
                    ) from None
                samples.append((_stamp(message, log_time), value, len(samples), int(log_time)))
            samples.sort(key=lambda sample: sample[0])  # stable: repeated stamps stay, refused
            stamps = np.asarray([sample[0] for sample in samples], dtype=np.int64)
            found[name] = make_signal(
                name,
                stamp_seconds(stamps).tolist(),  # stamps 1 ns apart stay apart, as poses do
                [sample[1] for sample in samples],
                Where(file, path=topic, origin=_origin(samples, topic)),
            )
    except UsageError:
        raise
    except Exception as exc:
        raise unreadable_message(exc, path, reading) from None
    finally:
        reader.close()
    return found
