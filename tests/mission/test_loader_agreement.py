"""libyaml's parser and PyYAML's pure-Python one give the same reading.

The reader uses libyaml when PyYAML was built with it (ten times faster on large maps) and the
pure-Python parser otherwise: a mission must read the same on either machine, its data, the
positions of its values and keys, and every diagnostic's code, line and column.
"""

from __future__ import annotations

from typing import Any
from unittest import mock

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from tlmpc.mission import yamlpos
from tlmpc.mission.yamlpos import load_positioned

pytestmark = pytest.mark.skipif(not yaml.__with_libyaml__, reason="PyYAML without libyaml")

_SCALARS = (
    st.integers(-(10**6), 10**6)
    | st.floats(allow_nan=False, allow_infinity=False, width=32)
    | st.booleans()
    | st.none()
    | st.text(alphabet="ab1.-e :#[]{},'\"", max_size=6)
)
_NAMES = st.text(alphabet="abcxyz_0123", min_size=1, max_size=5)
_VALUES = st.recursive(
    _SCALARS,
    lambda inner: st.lists(inner, max_size=5) | st.dictionaries(_NAMES, inner, max_size=4),
    max_leaves=25,
)


def _reading(text: str, loader: type, lazy: bool) -> Any:
    with mock.patch.object(yamlpos, "_LOADER", loader):
        doc, problems = load_positioned(text, "m.yaml", lazy=lazy)
        located = [(p.code, p.line, p.col, p.path) for p in problems]
        if doc is None:
            return None, located
        paths = sorted(doc.values, key=repr)
        return (
            doc.data,
            [(path, doc.value_at(path)) for path in paths],
            sorted(doc.keys.items(), key=repr),
            located,
        )


@st.composite
def _texts(draw: st.DrawFn) -> str:
    """A document as yaml.dump writes it (block or flow style), now and then with a key
    given twice (Y002) or a number YAML 1.1 reads as text (Y010): the diagnostics the reader
    makes of well-formed YAML must be located alike too.  (Broken YAML is not drawn: there the
    parsers' own messages and marks differ, e.g. a tab before a key's colon is refused by
    the pure-Python parser only.)"""
    value = draw(st.dictionaries(_NAMES, _VALUES, min_size=1, max_size=4))
    text = yaml.safe_dump(value, default_flow_style=draw(st.sampled_from([False, True, None])))
    if draw(st.booleans()):
        text += f"{next(iter(value))}: 1\n"  # a duplicate key
    if draw(st.booleans()):
        text += "written: 1e5\n"
    return text


@settings(max_examples=300, deadline=None)
@given(_texts(), st.booleans())
def test_libyaml_and_the_pure_parser_read_alike(text: str, lazy: bool) -> None:
    fast = _reading(text, yaml.CSafeLoader, lazy)
    pure = _reading(text, yaml.SafeLoader, lazy)
    assert fast == pure


@pytest.mark.parametrize("escape", ["\\U0011FFFF", "\\UFFFFFFFF", "\\U00110000"])
def test_a_bad_escape_is_refused_alike(escape: str) -> None:
    """An escape past U+10FFFF makes PyYAML's pure-Python scanner raise from chr():
    both readers refuse it as Y001 at the same place, never an internal error."""
    text = f'version: 1\nname: "a {escape} b"\n'
    fast = _reading(text, yaml.CSafeLoader, False)
    pure = _reading(text, yaml.SafeLoader, False)
    assert fast == pure
    assert fast[1][0][:2] == ("Y001", 2)
