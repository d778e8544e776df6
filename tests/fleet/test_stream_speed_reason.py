"""A streamed log whose samples move faster than max_speed writes where, as the whole-log
verifier does: times from the first sample with the stamp beside (docs/verify.md "Times").

Oracles: the whole-log verifier's reason on the same samples, and the jump's own times (its
stamps less the first one), written independently here."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from robot_data import write_bag

from tlmpc.fleet.stream import verify_log
from tlmpc.verify import verify_document

DOCUMENT: dict[str, Any] = {
    "format": "tlmpc.trace/1",
    "ltl": "F a",
    "regions": {"a": [[5.0, 5.0], [6.0, 5.0], [6.0, 6.0], [5.0, 6.0]]},
    "workspace": {"boundary": [[-20.0, -20.0], [20.0, -20.0], [20.0, 20.0], [-20.0, 20.0]]},
    "boundary": "right",
    "max_speed": 1.0,
    "radius": 0.0,
    "points": [],
    "loop_start": None,
}


def _samples(start_ns: int) -> np.ndarray:
    """One pose every 10 ms for 5 s, standing still but for a 10 m jump after 2.5 s."""
    stamps = start_ns + np.arange(501, dtype=np.int64) * 10_000_000
    x = np.where(np.arange(501) > 250, 10.0, 0.0)
    return np.column_stack([stamps / 1e9, x, np.zeros(501)])


def _written(relative: float, stamp: float, stamped: bool) -> str:
    text = f"t={relative:.4g} s"
    return text + (f" (stamp {stamp:.3f}".rstrip("0").rstrip(".") + ")" if stamped else "")


@pytest.mark.parametrize("start_ns", [1_700_000_000_000_000_000, 0])
@pytest.mark.parametrize("kind", ["csv", "mcap"])
def test_the_streamed_speed_reason_writes_times_from_the_first_sample(
    tmp_path: Path, start_ns: int, kind: str
) -> None:
    samples = _samples(start_ns)
    if kind == "csv":
        path = tmp_path / "log.csv"
        with open(path, "w", encoding="utf-8") as stream:
            stream.write("t,x,y\n")
            np.savetxt(stream, samples, fmt="%.17g", delimiter=",")
    else:
        stamps = [start_ns + k * 10_000_000 for k in range(len(samples))]
        rows = [(ns, float(x), 0.0) for ns, x in zip(stamps, samples[:, 1], strict=True)]
        path = write_bag(tmp_path / "bag", "mcap", {"/odom": ("nav_msgs/msg/Odometry", rows)})

    streamed = verify_log(path, DOCUMENT).verdict.certificate.reason
    whole = verify_document({**DOCUMENT, "points": samples.tolist()}).certificate.reason
    assert streamed == whole

    start = samples[0, 0]
    begin, end = samples[250, 0], samples[251, 0]
    expected = (
        f"between {_written(begin - start, begin, start != 0)} and "
        f"{_written(end - start, end, start != 0)}"
    )
    assert expected in streamed
