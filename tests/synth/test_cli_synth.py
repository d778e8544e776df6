"""``tlmpc synth``: answers, exit codes, strategy files, explanations, located refusals."""

from __future__ import annotations

import io
import json
from pathlib import Path

import jsonschema
import pytest

from tlmpc.cli import main
from tlmpc.io.schema_check import load_schema

REALIZABLE = """\
# the system copies the request one step later and must grant infinitely often
ENV: r;
SYS: g;
ENVINIT: !r;
SYSINIT: !g;
ENVGOAL: []<> r;
SYSTRANS: [](g' <-> r);
SYSGOAL: []<> g;
"""

UNREALIZABLE = """\
ENV: x;
SYS: y;
ENVINIT: x;
ENVGOAL: []<> x;
SYSTRANS: [](x' -> !y')
        & [](True);
SYSGOAL: []<> (y & x);
"""


def run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out=out, err=err)
    return code, out.getvalue(), err.getvalue()


def write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_realizable_writes_a_strategy_that_follows_the_schema(tmp_path: Path) -> None:
    spec = write(tmp_path, "copy.spc", REALIZABLE)
    target = tmp_path / "strategy.json"
    code, out, _err = run("synth", str(spec), "-o", str(target))
    assert (code, out) == (0, "realizable\n")
    document = json.loads(target.read_text())
    jsonschema.validate(document, load_schema("strategy"))
    assert [v["name"] for v in document["inputs"]] == ["r"]
    assert document["initial"], "the first input !r needs an initial node"
    # every transition keeps the rule g' <-> r, and both inputs are answered in every node
    states = {n["id"]: n["state"] for n in document["nodes"]}
    answered: dict[int, set[bool]] = {}
    for source, target_node in document["transitions"]:
        assert states[target_node]["g"] == states[source]["r"]
        answered.setdefault(source, set()).add(states[target_node]["r"])
    assert all(answered[n] == {False, True} for n in states)


def test_dot_output(tmp_path: Path) -> None:
    spec = write(tmp_path, "copy.spc", REALIZABLE)
    target = tmp_path / "strategy.dot"
    code, _, err = run("synth", str(spec), "-o", str(target), "--format", "dot")
    assert code == 0
    text = target.read_text()
    assert text.startswith("digraph strategy {")
    assert "start -> n0;" in text
    assert f"wrote {target}" in err


def test_unrealizable_explains_with_a_located_core(tmp_path: Path) -> None:
    spec = write(tmp_path, "un.spc", UNREALIZABLE)
    code, out, _ = run("synth", str(spec))
    assert code == 1
    assert out.startswith("unrealizable\ncore: these 2 guarantees are unrealizable")
    # the core is the safety rule and the goal; the trivial rule [](True) is not in it
    assert f"{spec}:5:13: sys safety: (x' -> !y')" in out
    assert f"{spec}:7:15: sys liveness: (y & x)" in out
    assert "(True)" not in out.split("counterstrategy")[0]
    assert "counterstrategy (" in out
    assert "first inputs: x" in out


def test_unrealizable_json_carries_core_and_counterstrategy(tmp_path: Path) -> None:
    spec = write(tmp_path, "un.spc", UNREALIZABLE)
    code, out, _ = run("synth", str(spec), "--json")
    assert code == 1
    result = json.loads(out)["result"]
    assert result["realizable"] is False
    assert [(c["line"], c["part"]) for c in result["core"]] == [
        (5, "sys safety"),
        (7, "sys liveness"),
    ]
    assert result["counterstrategy"]["initial_inputs"] == {"x": True}


def test_all_init_changes_the_answer(tmp_path: Path) -> None:
    # every start must win under --all-init; y true at the start cannot be answered
    spec = write(
        tmp_path,
        "partwin.spc",
        "ENV: x;\nSYS: y;\nSYSTRANS: [](!y');\nSYSGOAL: []<> !y;\nSYSINIT: True;\n",
    )
    assert run("synth", str(spec))[0] == 0
    spec2 = write(
        tmp_path, "stuck.spc", "ENV: x;\nSYS: y;\nSYSTRANS: [](y -> y') & [](x -> !y');\n"
    )
    assert run("synth", str(spec2))[0] == 0
    assert run("synth", str(spec2), "--all-init", "--no-explain")[0] == 1


@pytest.mark.parametrize(
    ("name", "text", "where", "code"),
    [
        ("a.spc", "ENV: x;\nSYS: y;\nSYSGOAL: []<> z;\n", ":3:15:", "Q018"),
        ("b.spc", "ENV: x;\nSYS: y;\nSYSINIT: y';\n", ":3:11:", "Q019"),
        ("c.spc", "ENV: x;\nSYS: y;\nENVTRANS: [](y');\n", ":3:13:", "Q017"),
        ("d.spc", "ENV: x [1,3];\n", ":1:9:", "Q014"),
        ("e.spc", "ENV: x;\nSYS: y;\nSYSGOAL: <> y;\n", ":3:10:", "Q015"),
        ("f.slugsin", "[INPUT]\nx\n[OUTPUT]\ny\n[SYS_TRANS]\n& x\n", ":6:4:", "Q030"),
        ("g.slugsin", "[INPUT]\nx\n[OUTPUT]\ny\n[ENV_TRANS]\n| x y'\n", ":6:5:", "Q035"),
        ("h.slugsin", "[INPUT]\nx\n[SYS_INIT]\n$ 2 ? 1 x\n", ":4:5:", "Q033"),
        # a buffer announcing more formulas than its line holds ends early at its '$'
        ("h2.slugsin", "[INPUT]\nx\n[SYS_INIT]\n& x $ 4 x ? 0\n", ":4:5:", "Q030"),
        ("h3.slugsin", "[INPUT]\nx\n[SYS_INIT]\n$ 99999999999999 x\n", ":4:1:", "Q030"),
        # longer than int() reads
        ("h4.slugsin", f"[INPUT]\nx\n[SYS_INIT]\n$ 2 x ? {'9' * 5000}\n", ":4:7:", "Q033"),
        ("h5.slugsin", f"[INPUT]\nx\n[SYS_INIT]\n$ {'9' * 5000} x\n", ":4:1:", "Q030"),
        # 0 and 1 are the constants in a formula: such a variable could never be read
        ("h6.slugsin", "[INPUT]\nx\n[OUTPUT]\n1\n[SYS_LIVENESS]\n! 1\n", ":4:1:", "Q032"),
        ("h7.slugsin", "[INPUT]\n0\n[SYS_LIVENESS]\n0\n", ":2:1:", "Q032"),
        (
            "i.tlsf",
            "INFO { SEMANTICS: Mealy,Strict; }\nMAIN { INPUTS { a; } OUTPUTS { b; }\n"
            "GUARANTEE { G (a -> F b); } }\n",
            ":3:13:",
            "Q044",
        ),
        (
            "j.tlsf",
            "INFO { SEMANTICS: Moore; }\nMAIN { INPUTS { a; } OUTPUTS { b; } }\n",
            ":1:19:",
            "Q043",
        ),
        (
            "k.tlsf",
            "INFO { SEMANTICS: Mealy; }\nMAIN { INPUTS { a; } OUTPUTS { b; }\n"
            "REQUIRE { a -> X a; } ASSERT { b -> X b; } }\n",
            ":3:32:",
            "Q047",
        ),
        # no MAIN (an empty file is not the trivial game), no SEMANTICS (strict or not?)
        ("l.tlsf", "", ":1:1:", "Q041"),
        ("m.tlsf", "// only a comment\n", ":2:1:", "Q041"),
        ("n.tlsf", "INFO { SEMANTICS: Mealy,Strict }\n", ":2:1:", "Q041"),
        (
            "o.tlsf",
            "MAIN { INPUTS { a; } OUTPUTS { b; }\nREQUIRE { a; } ASSERT { b; } }\n",
            ":1:1:",
            "Q041",
        ),
        (
            "p.tlsf",
            'INFO { TITLE: "t" }\nMAIN { INPUTS { a; } OUTPUTS { b; }\n'
            "REQUIRE { a; } ASSERT { b; } }\n",
            ":1:1:",
            "Q041",
        ),
    ],
)
def test_a_refusal_is_located_and_exits_2(
    tmp_path: Path, name: str, text: str, where: str, code: str
) -> None:
    spec = write(tmp_path, name, text)
    exit_code, out, err = run("synth", str(spec))
    assert exit_code == 2
    assert out == ""
    assert f"{spec}{where} error[{code}]" in err
    assert "hint:" in err


def test_one_side_init_refuses_both_initial_conditions(tmp_path: Path) -> None:
    spec = write(tmp_path, "both.spc", "ENV: e;\nSYS: s;\nENVINIT: e;\nSYSINIT: s;\n")
    code, out, err = run("synth", str(spec), "--one-side-init")
    assert (code, out) == (2, "")
    assert f"{spec}:4:10: error[Q016]" in err


def test_a_tlsf_core_names_whole_conjuncts(tmp_path: Path) -> None:
    spec = write(
        tmp_path,
        "core.tlsf",
        "INFO { SEMANTICS: Mealy,Strict }\nMAIN { INPUTS { r; } OUTPUTS { g; }\n"
        "ASSERT { (g && r) || (!g && !r) -> X(!g); }\n"
        "GUARANTEE { G F ((g || r) && (g || !r)); }\n}\n",
    )
    code, out, _ = run("synth", str(spec), "--json")
    assert code == 1
    core = json.loads(out)["result"]["core"]
    assert [(p["line"], p["col"], p["text"]) for p in core] == [
        (3, 10, "(g && r) || (!g && !r) -> X(!g)"),
        (4, 17, "((g || r) && (g || !r))"),
    ]


def test_all_init_is_refused_for_tlsf(tmp_path: Path) -> None:
    spec = write(tmp_path, "x.tlsf", "INFO { SEMANTICS: Mealy; }\nMAIN { INPUTS { a; } }\n")
    code, _, err = run("synth", str(spec), "--all-init")
    assert code == 2
    assert "error[Q063]" in err


def test_a_counterstrategy_too_large_to_show_keeps_the_answer(tmp_path: Path) -> None:
    # the environment never gives x: unrealizable, and the counterstrategy visits each of the
    # 25,001 values of n, more than are shown; the answer and the core still stand
    spec = tmp_path / "wide.structuredslugs"
    spec.write_text("[INPUT]\nx\n[OUTPUT]\nn: 0...25000\n[SYS_LIVENESS]\nx\n")
    code, out, err = run("synth", str(spec))
    assert code == 1, err
    assert out.startswith("unrealizable\ncore: this guarantee is unrealizable")
    assert f"{spec}:6:1: sys liveness: x" in out
    assert err.startswith(f"{spec}: note[Q062]"), err
    code, out, _ = run("synth", str(spec), "--json")
    assert code == 1
    document = json.loads(out)
    jsonschema.validate(document, load_schema("cli-output"))
    assert document["result"]["realizable"] is False
    assert "counterstrategy" not in document["result"]
    assert [d["code"] for d in document["diagnostics"]] == ["Q062"]
