"""A shape that is wrong is told about in its own kind's terms.

A shape is a list of points or ``{rect: [...]}``.  The schema tries both; the diagnostic is
about the kind the value is (a list: its points; a mapping with ``rect``: the rectangle), and
a value of neither kind is told what a shape is (S004), never "is not of type 'object'" for a
list or "is not of type 'array'" for a mapping.
"""

from __future__ import annotations

import pytest

from tlmpc.base.errors import TlmpcError
from tlmpc.mission.load import load_mission_text

MISSION = """\
version: 1
workspace:
  boundary: {boundary}
regions:
  a: {{rect: [1, 1, 2, 2]}}
robot: {{start: [3, 3]}}
task: [visit a]
"""


@pytest.mark.parametrize(
    ("boundary", "code", "says"),
    [
        ("{polygon: [[0, 0], [4, 0], [4, 4], [0, 4]]}", "S004", "is not a shape"),
        ("{circle: 3}", "S004", "is not a shape"),
        ("7", "S004", "is not a shape"),
        ("{rect: [0, 0, 4]}", "S009", "boundary.rect: [0, 0, 4] is too short"),
        ("{rect: [0, 0, 4, x]}", "S005", "'x' is not of type 'number'"),
        ("[[0, 0], [4, 0]]", "S009", "[[0, 0], [4, 0]] is too short"),
        ("[[0, 0], [4, 0], 5]", "S005", "5 is not of type 'array'"),
    ],
)
def test_a_bad_shape_is_described_in_its_own_kind(boundary: str, code: str, says: str) -> None:
    with pytest.raises(TlmpcError) as caught:
        load_mission_text(MISSION.format(boundary=boundary), "bad.yaml")
    (diagnostic,) = caught.value.diagnostics
    assert diagnostic.code == code
    assert says in diagnostic.message
    assert diagnostic.line == 3
    if code == "S004":
        assert diagnostic.hint is not None
        assert "{rect:" in diagnostic.hint
