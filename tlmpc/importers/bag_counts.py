"""Whether reading a bag found every message the bag says it holds.

A bag states how many messages each topic has, in records of its own: a ROS 1 bag in its
index (the index data of each chunk, and the chunk infos), an MCAP file in its statistics and
its chunk indexes, a ROS 2 bag directory in ``metadata.yaml`` (and its storage files in
theirs; a sqlite3 file's messages table counts its rows).  A damaged recording can lose
messages without an error: the reader skips an MCAP message whose log time lies outside its
chunk's range or whose channel id is garbled, and a sqlite3 file whose pages are damaged
answers its query with fewer rows.  :func:`counted_messages` reads the messages of some
connections and, when they are all read, compares how many came on each topic with every
count the bag states; a difference is M065, with the place where the file is damaged when
:mod:`tlmpc.importers.bag_damage` finds one.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

from tlmpc.base.errors import UsageError, error
from tlmpc.importers.bag_damage import storage_damage


def counted_messages(
    reader: Any, connections: Sequence[Any], path: Path
) -> Iterator[tuple[Any, int, bytes]]:
    """``reader.messages(connections=...)`` of an open ``rosbags`` reader, then (when they
    have all been read) a check that they are as many, topic by topic, as the bag declares:
    :class:`UsageError` M065 where they are not (see the module docstring)."""
    read: Counter[str] = Counter()
    for connection, log_time, raw in reader.messages(connections=connections):
        read[connection.topic] += 1
        yield connection, log_time, raw
    for source, declared in declared_counts(reader, connections):
        for topic in sorted(declared):
            if declared[topic] != read[topic]:
                raise _count_mismatch(path, topic, declared[topic], read[topic], source)


def declared_counts(reader: Any, connections: Sequence[Any]) -> list[tuple[str, Counter[str]]]:
    """Each message count the open ``rosbags`` reader's bag states for the topics of
    ``connections``, by the record that states it (e.g. ``"metadata.yaml"``)."""
    topics = {c.topic for c in connections}
    chosen = {id(c) for c in connections}
    # a storage file counts a topic's messages whatever their type: compare it on topics whose
    # every connection is read
    whole = {t for t in topics if all(id(c) in chosen for c in reader.connections if c.topic == t)}
    found: list[tuple[str, Counter[str]]] = []
    for bag in getattr(reader, "readers", []):
        listed: Counter[str] = Counter()
        for connection in connections:
            if connection.owner in (bag, getattr(bag, "storage", None)):
                listed[connection.topic] += int(connection.msgcount)
        storage = getattr(bag, "storage", None)
        found.append((_index_name(bag, storage), _with_topics(listed, topics)))
        if storage is None:  # a ROS 1 bag: its chunk infos count each connection's messages
            infos = Counter[str]()
            names = {c.id: c.topic for c in getattr(bag, "connections", [])}
            for info in getattr(bag, "chunk_infos", []):
                for connection_id, count in info.connection_counts.items():
                    infos[names.get(connection_id, "")] += int(count)
            found.append(("its chunk infos", _with_topics(infos, whole)))
            continue
        for part in getattr(storage, "storages", [storage]):
            found.extend(_storage_counts(part, whole))
    return found


def _index_name(bag: Any, storage: Any) -> str:
    """What the reader's own connection counts come from, in words."""
    if storage is None:
        return "its index"
    if hasattr(storage, "storages"):
        return "metadata.yaml"
    if hasattr(storage, "statistics"):
        return "its MCAP summary"
    return "its messages table"


def _storage_counts(storage: Any, topics: set[str]) -> list[tuple[str, Counter[str]]]:
    """The counts a ROS 2 storage file states: an MCAP file's statistics and chunk indexes, a
    sqlite3 file's rows per topic."""
    name = Path(str(getattr(storage, "path", ""))).name
    channels = {c.id: c.topic for c in getattr(storage, "connections", [])}
    found: list[tuple[str, Counter[str]]] = []
    statistics = getattr(storage, "statistics", None)
    if statistics is not None:
        stated: Counter[str] = Counter()
        for channel, count in statistics.channel_message_counts.items():
            stated[channels.get(channel, "")] += int(count)
        found.append((f"the MCAP statistics of {name}", _with_topics(stated, topics)))
        chunks = getattr(storage, "chunks", [])
        if chunks:
            indexed: Counter[str] = Counter()
            for chunk in chunks:
                for channel, count in chunk.channel_count.items():
                    indexed[channels.get(channel, "")] += int(count)
            found.append((f"the MCAP chunk indexes of {name}", _with_topics(indexed, topics)))
    elif channels:
        rows: Counter[str] = Counter()
        for connection in getattr(storage, "connections", []):
            rows[connection.topic] += int(connection.msgcount)
        found.append((f"the messages table of {name}", _with_topics(rows, topics)))
    return found


def _with_topics(counts: Counter[str], topics: set[str]) -> Counter[str]:
    """``counts`` on ``topics`` only, a topic it lacks counting 0."""
    return Counter({topic: counts[topic] for topic in topics})


def _count_mismatch(path: Path, topic: str, declared: int, read: int, source: str) -> UsageError:
    message = (
        f"the bag declares {declared:,} messages on {topic} ({source}), but {read:,} could be read"
    )
    damage = storage_damage(path)
    if damage is not None:
        message += f": {damage[0]}"
        hint = damage[1]
    elif source == "metadata.yaml":
        hint = (
            "metadata.yaml does not match its storage files (edited, or left from another "
            "recording): `ros2 bag reindex` writes it again from them"
        )
    else:
        hint = "it may have been damaged in a copy: compare it with the robot's own"
    return UsageError(error("M065", message, hint=hint, file=str(path)))
