"""The yes/no schema checker agrees with jsonschema (the oracle) on every document it judges.

Documents: every shipped and test mission, the artifacts of a compiled mission, and random
mutations of them (a value replaced by any JSON value, a key dropped or added).
"""

from __future__ import annotations

import copy
import functools
import math
from pathlib import Path
from typing import Any

import jsonschema
import pytest
import yaml
from hypothesis import given
from hypothesis import strategies as st

from tlmpc.io.schema_check import is_valid, load_schema

ROOT = Path(__file__).resolve().parents[1]
ARTIFACT_SCHEMAS = {
    "mission.json": "mission-artifact",
    "abstraction.json": "abstraction",
    "witness.json": "witness",
    "controllers.json": "controllers",
    "trace.json": "trace",
}


@functools.cache
def _validator(name: str) -> Any:
    return jsonschema.Draft202012Validator(load_schema(name))


def _oracle(document: Any, name: str) -> bool:
    return bool(_validator(name).is_valid(document))


@functools.cache
def _missions(max_bytes: int = 10**8) -> list[Any]:
    files = sorted(ROOT.glob("specs/*.yaml")) + sorted(ROOT.glob("tests/**/*.yaml"))
    documents = []
    for file in files:
        if file.stat().st_size > max_bytes:
            continue
        try:
            document = yaml.safe_load(file.read_text(encoding="utf-8"))
        except (yaml.YAMLError, UnicodeDecodeError):
            continue
        if isinstance(document, dict) and "version" in document:
            documents.append(document)
    return documents


def _shrink(document: Any) -> Any:
    """The document with every list cut to its first items (the same shape, a cheap oracle)."""
    if isinstance(document, dict):
        return {key: _shrink(value) for key, value in document.items()}
    if isinstance(document, list):
        return [_shrink(value) for value in document[:4]]
    return document


@functools.cache
def _artifacts() -> dict[str, Any]:
    import tlmpc

    compiled = tlmpc.compile(ROOT / "specs" / "example1.yaml").artifacts
    return {name: _shrink(compiled[name]) for name in ARTIFACT_SCHEMAS}


def test_the_corpus_has_valid_and_invalid_missions() -> None:
    verdicts = [_oracle(m, "mission") for m in _missions()]
    assert verdicts.count(True) >= 5
    assert verdicts.count(False) >= 5


def test_agrees_on_every_mission_file() -> None:
    for mission in _missions():
        assert is_valid(mission, "mission") == _oracle(mission, "mission"), mission


@pytest.mark.parametrize(("file", "schema"), sorted(ARTIFACT_SCHEMAS.items()))
def test_agrees_on_artifacts(file: str, schema: str) -> None:
    document = _artifacts()[file]
    assert is_valid(document, schema) is True
    assert _oracle(document, schema)


json_values = st.recursive(
    st.none()
    | st.booleans()
    | st.integers(-3, 3)
    | st.floats(allow_nan=False, allow_infinity=False)
    | st.sampled_from([0.0, 1.0, -1.0, 1e9, 1e10, 2.5, 0, 1, 2, 4, 1e-12])
    | st.text(max_size=4)
    | st.sampled_from(["F", "true", "a", "p1", "hops", "length", "closed", "2x", "_a", ""]),
    lambda inner: (
        st.lists(inner, max_size=5)
        | st.dictionaries(
            st.sampled_from(["rect", "start", "x", "a", "boundary"]), inner, max_size=3
        )
    ),
    max_leaves=12,
)


def _paths(document: Any, prefix: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    found = [prefix]
    if isinstance(document, dict):
        for key, value in document.items():
            found.extend(_paths(value, (*prefix, key)))
    elif isinstance(document, list):
        for index, value in enumerate(document[:6]):
            found.extend(_paths(value, (*prefix, index)))
    return found


def _mutate(document: Any, data: st.DataObject) -> Any:
    document = copy.deepcopy(document)
    for _ in range(data.draw(st.integers(1, 3))):
        path = data.draw(st.sampled_from(_paths(document)))
        if not path:
            continue
        parent = document
        for key in path[:-1]:
            parent = parent[key]
        action = data.draw(st.sampled_from(["replace", "drop", "add"]))
        if action == "replace":
            parent[path[-1]] = data.draw(json_values)
        elif action == "drop":
            del parent[path[-1]]
        elif isinstance(parent, dict):
            parent[data.draw(st.sampled_from(["extra", "ltl", "task", "F", "2", "max_speed"]))] = (
                data.draw(json_values)
            )
        else:
            parent.append(data.draw(json_values))
    return document


@pytest.mark.slow
@given(st.data())
def test_agrees_on_mutated_missions(data: st.DataObject) -> None:
    mission = data.draw(st.sampled_from(_missions(20_000)))
    mutated = _mutate(mission, data)
    verdict = is_valid(mutated, "mission")
    assert verdict is None or verdict == _oracle(mutated, "mission")


@pytest.mark.slow
@given(st.data())
def test_agrees_on_mutated_artifacts(data: st.DataObject) -> None:
    file, schema = data.draw(st.sampled_from(sorted(ARTIFACT_SCHEMAS.items())))
    mutated = _mutate(_artifacts()[file], data)
    verdict = is_valid(mutated, schema)
    assert verdict is None or verdict == _oracle(mutated, schema)


def test_json_equality_keeps_true_apart_from_one() -> None:
    from tlmpc.io.schema_check import _equal

    assert not _equal(True, 1)
    assert not _equal(0, False)
    assert _equal(1, 1.0)
    assert _equal([1, {"a": None}], [1.0, {"a": None}])
    assert not _equal(math.nan, 0)


@pytest.mark.parametrize(
    ("value", "valid"),
    [(2, True), (2.0, True), (2.5, False), (True, False), (-1, False), ("2", False)],
)
def test_integer_items_as_jsonschema_reads_them(value: Any, valid: bool) -> None:
    witness = copy.deepcopy(_artifacts()["witness.json"])
    witness["cycle"] = [value]
    assert _oracle(witness, "witness") is valid
    assert is_valid(witness, "witness") is valid
