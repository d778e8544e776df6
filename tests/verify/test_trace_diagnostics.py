"""A trace.json's problems: diagnostics at the line and column of the value at fault, with a
hint, exit 2 — never a traceback (exit 3), whatever the values' types and sizes."""

from __future__ import annotations

import copy
import io
import json
import random
import re
from pathlib import Path
from typing import Any

import pytest

from tlmpc.cli import main
from tlmpc.io.json_places import json_path, string_char_places, value_offset

BASE: dict[str, Any] = {
    "format": "tlmpc.trace/1",
    "ltl": "F a & G !b & G(s -> F a)",
    "regions": {"a": [[2, 2], [4, 2], [4, 4], [2, 4]], "b": [[6, 6], [8, 6], [8, 8], [6, 8]]},
    "workspace": {
        "boundary": [[0, 0], [10, 0], [10, 10], [0, 10]],
        "holes": [[[5, 1], [5.5, 1], [5.5, 1.5]]],
        "components": [{"boundary": [[20, 20], [30, 20], [30, 30]], "holes": []}],
    },
    "boundary": "right",
    "max_speed": 100,
    "loop_start": None,
    "radius": 0.1,
    "sensors": ["s"],
    "actions": [],
    "assumptions": ["G F s"],
    "signals": {"s": [[0, True], [1, False]]},
    "points": [[0, 1, 1], [1, 3, 3], [2, 5, 5]],
}

#: Hostile values: wrong types, non-finite and huge numbers (10**400 overflows a float).
HOSTILE: list[Any] = [
    None,
    True,
    -1,
    10**400,
    -(10**30),
    1e308,
    "x",
    [],
    {},
    [[0, 0]],
    [[1, 2, 3]],
    3.5,
    [None],
    [[0, "x"]],
    [[10**400, 1]],
]


#: Codes placed inside a formula's string (at the unknown name), as the L-codes of its syntax.
INSIDE = ("V007", "V034")


def run(path: Path) -> tuple[int, dict[str, Any], str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(["verify", str(path), "--json"], out=out, err=err)
    return code, json.loads(out.getvalue()), err.getvalue()


def value_paths(value: Any, keys: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    found = [keys]
    if isinstance(value, dict):
        for key, item in value.items():
            found += value_paths(item, (*keys, key))
    elif isinstance(value, list):
        for index, item in enumerate(value[:2]):
            found += value_paths(item, (*keys, index))
    return found


def offset_of(text: str, line: int, col: int) -> int:
    """Lines end at \\n and columns count characters, as the json module counts them."""
    return sum(len(part) + 1 for part in text.split("\n")[: line - 1]) + col - 1


def walk(document: Any, path: str) -> tuple[bool, Any]:
    """The value at ``path`` (my own reading of the path), and whether the document has it."""
    value = document
    for name, index, quoted in re.findall(
        r'\.([A-Za-z_]\w*)|\[(\d+)\]|\[("(?:[^"\\]|\\.)*")\]', path[1:]
    ):
        key: Any = name or (int(index) if index else json.loads(quoted))
        try:
            value = value[key]
        except (KeyError, IndexError, TypeError):
            return False, None
    return True, value


def check_placed(text: str, diagnostic: dict[str, Any]) -> None:
    """The diagnostic has a hint and a line:col, and json itself reads the value its path
    names at that place (or, inside a formula, the formula's string starts before it)."""
    assert diagnostic.get("hint"), diagnostic
    assert "line" in diagnostic, diagnostic
    assert "col" in diagnostic, diagnostic
    offset = offset_of(text, diagnostic["line"], diagnostic["col"])
    assert 0 <= offset <= len(text)
    if "path" not in diagnostic:
        return
    present, value = walk(json.loads(text), diagnostic["path"])
    if not present:
        return  # a key the document lacks: placed at a parent
    if isinstance(value, str) and (diagnostic["code"][0] == "L" or diagnostic["code"] in INSIDE):
        start = text.rindex('"', 0, offset + 1)
        assert text[start:].startswith(json.dumps(value)[:1])
        return
    found, _ = json.JSONDecoder().raw_decode(text, offset)
    assert json.dumps(found) == json.dumps(value), (diagnostic, found)


@pytest.mark.parametrize(
    ("keys", "value", "code"),
    [
        (("workspace", "holes"), 3.5, "V004"),
        (("workspace", "holes"), True, "V004"),
        (("workspace", "components", 0, "holes"), -1, "V004"),
        (("regions", "a", 1, 0), 1e308, "V004"),
        (("workspace", "boundary", 1, 0), 1e308, "V004"),
        (("workspace", "holes", 0, 1, 1), 1e308, "V004"),
        (("radius",), 10**30 * 10**400, "V004"),
        (("signals", "s", 1, 0), 10**400, "V031"),
        (("points",), 10**400, "V002"),
        (("points", 1, 2), 10**400, "V024"),
        (("max_speed",), 10**400, None),  # vouches for nothing: no certificate, no error
    ],
    ids=lambda value: "huge-int" if isinstance(value, int) and abs(value) > 10**20 else None,
)
def test_hostile_values_are_diagnostics_not_crashes(
    tmp_path: Path, keys: tuple[Any, ...], value: Any, code: str | None
) -> None:
    document = copy.deepcopy(BASE)
    parent = document
    for key in keys[:-1]:
        parent = parent[key]
    parent[keys[-1]] = value
    path = tmp_path / "trace.json"
    text = json.dumps(document, indent=1)
    path.write_text(text)
    status, envelope, err = run(path)
    assert "Traceback" not in err
    if code is None:
        assert status in (0, 1, 4)
        assert envelope["result"]["certificate"]["max_speed"] is None
        return
    assert status == 2
    first = envelope["diagnostics"][0]
    assert first["code"] == code
    assert first["path"].startswith(json_path(*keys[:2]))
    check_placed(text, first)


def test_every_hostile_value_is_placed_with_a_hint(tmp_path: Path) -> None:
    """Each value of a trace replaced by each hostile value, written in one of three layouts:
    exit 0, 1, 2 or 4 (never 3), and every diagnostic where json reads the value at fault."""
    rng = random.Random(5)
    path = tmp_path / "trace.json"
    runs = 0
    for keys in value_paths(BASE)[1:]:
        for value in rng.sample(HOSTILE, 5):
            document = copy.deepcopy(BASE)
            parent = document
            for key in keys[:-1]:
                parent = parent[key]
            parent[keys[-1]] = copy.deepcopy(value)
            text = json.dumps(document, indent=rng.choice([None, 1, 2]))
            path.write_text(text)
            status, envelope, err = run(path)
            runs += 1
            assert status in (0, 1, 2, 4), (keys, value, err[-300:])
            for diagnostic in envelope["diagnostics"]:
                if diagnostic["severity"] == "error":
                    check_placed(text, diagnostic)
    assert runs > 300


def test_samples_of_a_trace_are_placed_at_their_numbers(tmp_path: Path) -> None:
    document = copy.deepcopy(BASE)
    document["points"] = [[0, 1, 1], [2, 3, 3], [1, 5, 5], [1, 6, float("nan")]]
    text = json.dumps(document, indent=2, allow_nan=True)
    path = tmp_path / "trace.json"
    path.write_text(text)
    status, envelope, _ = run(path)
    assert status == 2
    (diagnostic,) = envelope["diagnostics"]
    assert diagnostic["code"] == "V003"
    assert diagnostic["path"] == "$.points[3][2]"
    check_placed(text, diagnostic)
    document["points"][3][2] = 7
    text = json.dumps(document, indent=2)
    path.write_text(text)
    _, envelope, _ = run(path)
    assert [(d["code"], d["path"]) for d in envelope["diagnostics"]] == [
        ("V005", "$.points[2][0]"),
        ("V020", "$.points[3][0]"),
    ]
    for diagnostic in envelope["diagnostics"]:
        check_placed(text, diagnostic)


def test_a_formula_error_is_placed_inside_its_string_in_the_file(tmp_path: Path) -> None:
    """L002 at the end of `F (a & "b"` written with escapes, on line 5 of the file: the
    column is counted in the file's characters, not in the formula's."""
    document = copy.deepcopy(BASE)
    document["ltl"] = 'F (a & "b" &'
    body = json.dumps(document, indent=1).replace('"F (a', '"F (\\u0061', 1)
    path = tmp_path / "trace.json"
    path.write_text(body)
    status, envelope, _ = run(path)
    assert status == 2
    (diagnostic,) = envelope["diagnostics"]
    assert diagnostic["code"].startswith("L")
    # the formula ends at the string's closing quote, which is where json's scanner ends it
    start = body.index('"ltl": ') + len('"ltl": ')
    _, end = json.JSONDecoder().raw_decode(body, start)
    assert offset_of(body, diagnostic["line"], diagnostic["col"]) == end - 1
    assert diagnostic["path"] == "$.ltl"


def test_an_unknown_region_is_placed_at_its_name(tmp_path: Path) -> None:
    document = copy.deepcopy(BASE)
    document["ltl"] = "F a & G !missing"
    text = json.dumps(document, indent=2)
    path = tmp_path / "trace.json"
    path.write_text(text)
    _, envelope, _ = run(path)
    (diagnostic,) = envelope["diagnostics"]
    assert diagnostic["code"] == "V007"
    assert text[offset_of(text, diagnostic["line"], diagnostic["col"]) :].startswith("missing")


def test_a_trace_that_is_not_utf8_is_placed_at_the_bad_byte(tmp_path: Path) -> None:
    text = json.dumps(BASE, indent=1)
    line = 7
    col = 4
    cut = offset_of(text, line, col)
    path = tmp_path / "trace.json"
    path.write_bytes(text[:cut].encode() + b"\xff" + text[cut:].encode())
    status, envelope, _ = run(path)
    assert status == 2
    (diagnostic,) = envelope["diagnostics"]
    assert (diagnostic["code"], diagnostic["line"], diagnostic["col"]) == ("U001", line, col)
    assert diagnostic["hint"]


def random_document(rng: random.Random, depth: int = 0) -> Any:
    roll = rng.random()
    if depth > 3 or roll < 0.3:
        return rng.choice([1, -2.5, 'é\\"', None, True, 1e300, "\U0001f600", "a\nb"])
    if roll < 0.65:
        return [random_document(rng, depth + 1) for _ in range(rng.randint(0, 3))]
    return {
        rng.choice(["a", "b c", "d.e", "é", '"q"']): random_document(rng, depth + 1)
        for _ in range(rng.randint(0, 3))
    }


def test_json_places_find_every_value_and_string_character() -> None:
    rng = random.Random(11)
    checked = 0
    for _ in range(300):
        document = random_document(rng)
        text = json.dumps(
            document, indent=rng.choice([None, 1, "\t"]), ensure_ascii=rng.random() < 0.5
        )
        for keys in value_paths(document):
            present, value = walk(document, json_path(*keys))
            assert present
            offset = value_offset(text, keys)
            assert offset is not None
            found, _ = json.JSONDecoder().raw_decode(text, offset)
            assert json.dumps(found) == json.dumps(value)
            if isinstance(value, str):
                places = string_char_places(text, offset)
                assert places is not None
                assert len(places) == len(value) + 1
                for index, char in enumerate(value):
                    written = text[places[index] : places[index + 1]]
                    assert json.loads(f'"{written}"') == char
            checked += 1
    assert checked > 1000
    # a key written twice: json keeps the last, and so is the last found
    twice = '{"a": 1, "a": [2, 3]}'
    assert value_offset(twice, ["a", 1]) == twice.index("3")
