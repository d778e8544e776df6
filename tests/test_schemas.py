"""Every JSON Schema is a valid draft 2020-12 schema with a versioned identifier."""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import pytest

from tlmpc.io.schema_check import load_schema, schema_dir

ROOT = Path(__file__).resolve().parent.parent
SCHEMAS = sorted((ROOT / "schemas").glob("*.schema.json"))


def test_schemas_are_shipped() -> None:
    names = {p.name.removesuffix(".schema.json") for p in SCHEMAS}
    assert {
        "mission",
        "abstraction",
        "automaton",
        "witness",
        "controllers",
        "trace",
        "verdict",
        "summary",
        "mission-artifact",
    } <= names


@pytest.mark.parametrize("path", SCHEMAS, ids=lambda p: p.name)
def test_schema_is_valid_2020_12(path: Path) -> None:
    schema = json.loads(path.read_text())
    jsonschema.Draft202012Validator.check_schema(schema)
    assert schema["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    name = path.name.removesuffix(".schema.json")
    assert schema["$id"] == f"urn:tlmpc:schema:{name}:1"


def test_runtime_reads_the_one_source_of_truth() -> None:
    # In a source checkout the loader must read the top-level schemas/ folder itself.
    assert (schema_dir() / "summary.schema.json").read_text() == (
        ROOT / "schemas" / "summary.schema.json"
    ).read_text()
    assert load_schema("summary")["$id"] == "urn:tlmpc:schema:summary:1"


def test_wheel_packages_the_schema_folder() -> None:
    pyproject = (ROOT / "pyproject.toml").read_text()
    assert '"schemas" = "tlmpc/schemas"' in pyproject
