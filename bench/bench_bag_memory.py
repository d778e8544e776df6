"""Peak memory of reading and verifying a long bag: 10^6 odometry messages (10 ms apart).

Writes one MCAP bag (the first message serialised by rosbags, the others copies with their
stamp and position patched in place, so writing takes seconds), then measures in fresh
processes the peak resident memory (``ru_maxrss``) and the wall time of

* ``tlmpc verify BAG --mission specs/patrol.yaml`` (a bag this long is streamed), and
* the whole reader, ``tlmpc.importers.logs.read_bag`` (what ``plot --log`` and ``view --log``
  use),

for the code in this checkout and, with ``--before SRC`` (a folder holding another version's
``tlmpc`` package, e.g. ``git archive main | tar x -C SRC``), for that version too.

Run: ``python bench/bench_bag_memory.py [--messages N] [--before SRC]``.
"""

from __future__ import annotations

import argparse
import json
import os
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from bench.tables import markdown_table  # noqa: E402

MISSION = ROOT / "specs" / "patrol.yaml"

_MEASURE = """
import json, resource, subprocess, sys, time
started = time.perf_counter()
done = subprocess.run(sys.argv[1:], capture_output=True, text=True)
print(json.dumps({"code": done.returncode, "seconds": time.perf_counter() - started,
    "peak_kib": resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss,
    "answer": (done.stdout.strip().splitlines() or done.stderr.strip().splitlines() or [""])[0]}))
"""

_READ_WHOLE = """
import sys
from pathlib import Path
from tlmpc.importers.logs import read_bag
print(len(read_bag(Path(sys.argv[1])).samples))
"""


def write_long_bag(path: Path, messages: int) -> Path:
    """An MCAP bag with ``messages`` odometry poses walking along the patrol's corridor."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE)
    types = store.types
    zero = types["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0)
    marker_x, marker_y = 1234.5678, 8765.4321
    message = types["nav_msgs/msg/Odometry"](
        header=types["std_msgs/msg/Header"](
            stamp=types["builtin_interfaces/msg/Time"](sec=0x11223344, nanosec=0x05667788),
            frame_id="odom",
        ),
        child_frame_id="base_link",
        pose=types["geometry_msgs/msg/PoseWithCovariance"](
            pose=types["geometry_msgs/msg/Pose"](
                position=types["geometry_msgs/msg/Point"](x=marker_x, y=marker_y, z=0.0),
                orientation=types["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
            ),
            covariance=__import__("numpy").zeros(36),
        ),
        twist=types["geometry_msgs/msg/TwistWithCovariance"](
            twist=types["geometry_msgs/msg/Twist"](linear=zero, angular=zero),
            covariance=__import__("numpy").zeros(36),
        ),
    )
    template = bytearray(store.serialize_cdr(message, "nav_msgs/msg/Odometry"))
    at_sec = template.index(struct.pack("<I", 0x11223344))
    at_nsec = template.index(struct.pack("<I", 0x05667788))
    at_x = template.index(struct.pack("<d", marker_x))
    at_y = template.index(struct.pack("<d", marker_y))
    with Writer(path, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        connection = writer.add_connection("/odom", "nav_msgs/msg/Odometry", typestore=store)
        for k in range(messages):
            ns = 1_000_000_000 + k * 10_000_000
            struct.pack_into("<I", template, at_sec, ns // 1_000_000_000)
            struct.pack_into("<I", template, at_nsec, ns % 1_000_000_000)
            struct.pack_into("<d", template, at_x, 2.0 + 6.0 * (k % 10_000) / 10_000)
            struct.pack_into("<d", template, at_y, 5.0)
            writer.write(connection, ns, bytes(template))
    return path


def measure(source: Path, argv: list[str], cwd: Path) -> dict[str, object]:
    """Run ``argv`` with ``source`` first on the import path, from ``cwd`` (not this checkout:
    ``python -m`` and ``-c`` put the working directory before ``PYTHONPATH``)."""
    env = {**os.environ, "PYTHONPATH": str(source)}
    done = subprocess.run(
        [sys.executable, "-c", _MEASURE, *argv],
        capture_output=True,
        text=True,
        env=env,
        check=True,
        cwd=cwd,
    )
    result: dict[str, object] = json.loads(done.stdout)
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--messages", type=int, default=1_000_000)
    parser.add_argument("--before", type=Path, default=None)
    args = parser.parse_args()
    versions = [("this checkout", ROOT)]
    if args.before is not None:
        versions.insert(0, ("before", args.before))
    rows: list[dict[str, object]] = []
    with tempfile.TemporaryDirectory() as scratch:
        started = time.perf_counter()
        bag = write_long_bag(Path(scratch) / "long.mcap", args.messages)
        print(f"wrote {args.messages:,} messages in {time.perf_counter() - started:.1f} s")
        for label, source in versions:
            for what, argv in (
                ("verify", [sys.executable, "-m", "tlmpc", "verify", str(bag), "--mission",
                            str(MISSION)]),
                ("read whole", [sys.executable, "-c", _READ_WHOLE, str(bag)]),
            ):  # fmt: skip
                result = measure(source, argv, Path(scratch))
                peak = int(str(result["peak_kib"])) / 1024
                rows.append(
                    {
                        "code": label,
                        "run": what,
                        "messages": f"{args.messages:,}",
                        "exit": str(result["code"]),
                        "peak memory": f"{peak:,.0f} MiB",
                        "wall time": f"{float(str(result['seconds'])):.1f} s",
                        "answer": str(result["answer"])[-48:],
                    }
                )
    print(markdown_table(rows))


if __name__ == "__main__":
    main()
