"""Hostile names through every exporter: nothing executes, every model still parses.

The mission name is free text, so it reaches the models only inside comments that cannot be
closed; region names must be identifiers.  Each format is checked by an independent reader:
SPIN's own parser (``spin -a``) for Promela, a strict DOT tokenizer written here, and the
NuSMV identifier grammar for SMV.
"""

from __future__ import annotations

import io
import json
import re
import shutil
import subprocess
from pathlib import Path

import pytest
from ci_oracles import oracle_required
from hypothesis import given
from hypothesis import strategies as st

from tlmpc.abstraction import abstraction_from_json
from tlmpc.base.errors import UsageError
from tlmpc.cli import main
from tlmpc.ltl import parse_ltl
from tlmpc.planning.export import comment_text, to_dot_graph, to_promela, to_smv

ROOT = Path(__file__).resolve().parents[2]

HOSTILE_NAMES = [
    '*/ init { c_code { system("touch PWNED") } } /*',
    "x\nMODULE evil\nVAR pwned : boolean; -- ",
    'a" ]; evil [label="pwned',
    "x */ } digraph { a -> b /*",
    "\x1b[31mred\x1b[0m \x07 bell",
    "caf\u00e9 \u202e \U0001f600 \u200b",
    "-- \r\n#define p_a false\n",
    "\\\\ \\n \\\" '",
]


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    return main(list(argv), out=out, err=err), out.getvalue(), err.getvalue()


MISSION = """\
version: 1
name: {name}
workspace:
  boundary: {{rect: [0, 0, 4, 4]}}
regions:
  a: {{rect: [0.5, 0.5, 1.5, 1.5]}}
  b: {{rect: [2.5, 2.5, 3.5, 3.5]}}
robot: {{start: [2, 0.3]}}
task: [visit a then b]
"""


@pytest.fixture(scope="module", params=range(len(HOSTILE_NAMES)))
def hostile_output(
    request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory
) -> Path:
    name = HOSTILE_NAMES[request.param]
    base = tmp_path_factory.mktemp("hostile")
    spec = base / "mission.yaml"
    spec.write_text(MISSION.format(name=json.dumps(name, ensure_ascii=False)), encoding="utf-8")
    out = base / "out"
    code, _, err = run_cli("compile", str(spec), "-o", str(out), "--until", "abstraction", "-q")
    assert code == 0, err
    assert json.loads((out / "mission.json").read_text())["name"] == name
    return out


# --- independent readers -------------------------------------------------------------------

_DOT_TOKEN = re.compile(
    r"""\s+|/\*.*?\*/|//[^\n]*|"(?:[^"\\]|\\.)*"|[A-Za-z_][A-Za-z0-9_]*|-?(?:\.\d+|\d+(?:\.\d*)?)|--|->|[{}\[\];,=]""",
    re.DOTALL,
)


def dot_tokens(text: str) -> list[str]:
    """Tokens of a DOT file (comments and blanks dropped); fails on any stray character."""
    tokens: list[str] = []
    position = 0
    while position < len(text):
        match = _DOT_TOKEN.match(text, position)
        assert match is not None, f"DOT: unexpected {text[position : position + 20]!r}"
        token = match.group()
        if not token.isspace() and not token.startswith(("/*", "//")):
            tokens.append(token)
        position = match.end()
    return tokens


def check_dot(text: str) -> None:
    """A strict reading of the one graph the exporter writes: ``graph ID { stmt* }``."""
    tokens = dot_tokens(text)
    assert tokens[:3] == ["graph", "D", "{"]
    assert tokens[-1] == "}"
    assert tokens.count("{") == 1
    assert tokens.count("}") == 1
    assert "digraph" not in tokens
    assert "->" not in tokens
    body = tokens[3:-1]
    statements: list[list[str]] = [[]]
    for token in body:
        if token == ";":
            statements.append([])
        else:
            statements[-1].append(token)
    assert statements[-1] == []
    for statement in statements[:-1]:
        head = statement[0]
        assert head == "node" or re.fullmatch(r"\d+", head), statement
        if len(statement) == 3:
            assert statement[1] == "--", statement
            assert re.fullmatch(r"\d+", statement[2]), statement
        else:
            assert statement[1] == "[", statement
            assert statement[-1] == "]", statement


_SMV_IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_$#\-]*")
_SMV_KEYWORDS = {
    "MODULE",
    "VAR",
    "ASSIGN",
    "init",
    "next",
    "case",
    "esac",
    "TRUE",
    "FALSE",
    "TRANS",
    "DEFINE",
    "LTLSPEC",
    "in",
    "G",
    "F",
    "X",
    "U",
    "V",
    "main",
    "t",
    "prev",
}


def check_smv(text: str) -> None:
    """Every line is a comment or code whose words are SMV identifiers we wrote."""
    lines = text.splitlines()
    assert lines[1] == "MODULE main"
    assert sum(line.split("--", 1)[0].count("MODULE") for line in lines) == 1
    for line in lines:
        code = line.split("--", 1)[0]
        assert re.fullmatch(r"[A-Za-z0-9_ :.;,{}()=!&|<>\-\[\]]*", code), line
        for word in re.findall(r"[A-Za-z_][A-Za-z0-9_]*", code):
            assert _SMV_IDENTIFIER.fullmatch(word)
            assert word in _SMV_KEYWORDS or word.startswith("p_"), word


# --- the tests -----------------------------------------------------------------------------


def test_dot_reads_back_strictly(hostile_output: Path) -> None:
    code, dot, _ = run_cli("export", str(hostile_output), "--format", "dot")
    assert code == 0
    check_dot(dot)


def test_smv_has_only_generated_identifiers(hostile_output: Path) -> None:
    code, smv, _ = run_cli("export", str(hostile_output), "--format", "smv")
    assert code == 0
    check_smv(smv)


@oracle_required(shutil.which("spin") is not None, "SPIN")
def test_spin_parses_the_promela_and_nothing_runs(hostile_output: Path, tmp_path: Path) -> None:
    code, model, _ = run_cli("export", str(hostile_output), "--format", "promela")
    assert code == 0
    assert "c_code" not in model.split("*/", 1)[1]  # only inside the first comment, if at all
    (tmp_path / "model.pml").write_text(model, encoding="utf-8")
    result = subprocess.run(
        ["spin", "-a", "model.pml"], cwd=tmp_path, capture_output=True, text=True
    )
    assert result.returncode == 0, result.stdout + result.stderr
    assert (tmp_path / "pan.c").exists()
    assert "touch PWNED" not in (tmp_path / "pan.c").read_text(errors="replace")
    if "c_code" in model and shutil.which("gcc") is not None:  # run the verifier as a user would
        subprocess.run(["gcc", "-o", "pan", "pan.c"], cwd=tmp_path, check=True)
        subprocess.run(["./pan", "-a"], cwd=tmp_path, capture_output=True)
    assert not (tmp_path / "PWNED").exists()
    assert not (hostile_output / "PWNED").exists()
    # Promela comments have exactly the structure we wrote: one opener and one closer each.
    for line in model.splitlines():
        assert line.count("/*") == line.count("*/") <= 1, line


@given(st.text(max_size=200))
def test_comment_text_cannot_end_a_comment(name: str) -> None:
    safe = comment_text(name)
    for dangerous in ("*/", "/*", "--", "\n", "\r", '"', "\\"):
        assert dangerous not in safe
    assert all(" " <= ch <= "~" for ch in safe)


def test_tampered_region_name_is_refused(hostile_output: Path, tmp_path: Path) -> None:
    tampered = tmp_path / "tampered"
    shutil.copytree(hostile_output, tampered)
    path = tampered / "abstraction.json"
    text = path.read_text(encoding="utf-8").replace('"a"', '"a\\" ]; x [label=\\"y"')
    path.write_text(text, encoding="utf-8")
    for fmt in ("promela", "smv", "dot"):
        code, model, err = run_cli("export", str(tampered), "--format", fmt)
        assert code == 2, (fmt, err)
        assert model == ""
        assert re.search(r"error\[(U03\d|U04\d|S0[23]\d)\]", err), err


def test_exporters_refuse_non_identifier_regions_themselves(hostile_output: Path) -> None:
    document = json.loads((hostile_output / "abstraction.json").read_text())
    document["regions"]['x"];evil'] = document["regions"].pop("a")
    document["letters"] = [
        ['x"];evil' if n == "a" else n for n in letter] for letter in document["letters"]
    ]
    abstraction = abstraction_from_json(document)
    for export in (to_promela, to_smv):
        with pytest.raises(UsageError) as caught:
            export(abstraction, parse_ltl("F b"))
        assert caught.value.diagnostics[0].code == "U039"
    with pytest.raises(UsageError):
        to_dot_graph(abstraction)
