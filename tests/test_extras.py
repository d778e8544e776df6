"""Optional extras: the core install compiles and verifies; a missing extra is a diagnostic.

Each command that needs an optional package is run with that package made unimportable (as
on a plain ``pip install tlmpc``) and must answer with U060 naming the extra, exit 2, no
traceback.  The extras declared in ``pyproject.toml`` are the ones the code names.
"""

from __future__ import annotations

import io
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from tlmpc.base.extras import EXTRAS, require
from tlmpc.cli import main

ROOT = Path(__file__).resolve().parent.parent
EXAMPLE = ROOT / "specs" / "example1.yaml"
PROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out=out, err=err)
    return code, out.getvalue(), err.getvalue()


def hide(monkeypatch: pytest.MonkeyPatch, package: str) -> None:
    """Make ``package`` and its submodules unimportable, as if it were not installed."""
    for name in [n for n in sys.modules if n == package or n.startswith(package + ".")]:
        monkeypatch.setitem(sys.modules, name, None)
    monkeypatch.setitem(sys.modules, package, None)


def _names(requirements: list[str]) -> set[str]:
    return {
        r.split(";")[0].split("[")[0].split("<")[0].split(">")[0].split("=")[0].strip()
        for r in requirements
    }


def test_the_declared_extras_are_the_ones_the_code_names() -> None:
    optional = PROJECT["optional-dependencies"]
    core = _names(PROJECT["dependencies"])
    for extra, packages in EXTRAS.items():
        assert _names(optional[extra]) == set(packages), extra
        assert not core & set(packages), f"{extra} packages must not be in the core install"
    # [dev] brings every extra (the tests exercise them all)
    dev = " ".join(optional["dev"])
    assert all(extra in dev for extra in EXTRAS)
    assert "tlmpc[" in dev


@pytest.fixture(scope="module")
def compiled(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("extras") / "out"
    code, _, err = run_cli("compile", str(EXAMPLE), "-o", str(out), "-q")
    assert code == 0, err
    return out


def assert_names_extra(code: int, err: str, extra: str) -> None:
    assert code == 2, err
    assert "error[U060]" in err
    assert f"pip install 'tlmpc[{extra}]'" in err
    assert "Traceback" not in err


def test_png_without_matplotlib_names_the_png_extra(
    compiled: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    hide(monkeypatch, "matplotlib")
    code, _, err = run_cli("plot", str(compiled), "--format", "png")
    assert_names_extra(code, err, "png")
    assert not (compiled / "plan.png").exists()


def test_compile_png_without_matplotlib_stops_before_compiling(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    hide(monkeypatch, "matplotlib")
    stages: list[str] = []
    monkeypatch.setattr(
        "tlmpc.pipeline.stages.compile_mission", lambda *a, **k: stages.append("ran")
    )
    code, _, err = run_cli("compile", str(EXAMPLE), "-o", str(tmp_path / "out"), "--png")
    assert_names_extra(code, err, "png")
    assert "--png" in err
    assert stages == []
    assert not (tmp_path / "out").exists()


def test_a_bag_without_rosbags_names_the_ros_extra(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    hide(monkeypatch, "rosbags")
    bag = tmp_path / "run.mcap"
    bag.write_bytes(b"\x89MCAP0\r\n")
    code, _, err = run_cli("verify", str(bag), "--mission", str(EXAMPLE))
    assert_names_extra(code, err, "ros")
    assert err.startswith(f"{bag}: error[U060]")


@pytest.mark.parametrize("package", EXTRAS["ros"])
def test_an_mcap_plan_without_its_packages_names_the_ros_extra(
    compiled: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, package: str
) -> None:
    hide(monkeypatch, package)
    out = tmp_path / "plan.mcap"
    code, _, err = run_cli("export-plan", str(compiled), "--format", "path-mcap", "-o", str(out))
    assert_names_extra(code, err, "ros")
    assert not out.exists()


def test_require_imports_what_is_there_and_refuses_a_non_optional_package() -> None:
    assert require("rosbags.typesys", "a test").__name__ == "rosbags.typesys"
    with pytest.raises(ValueError, match="not an optional dependency"):
        require("numpy", "a test")


def test_the_core_install_checks_compiles_and_verifies(tmp_path: Path) -> None:
    # A fresh interpreter in which no optional package can be imported: the core commands
    # never reach for one.
    blocked = sorted({p for packages in EXTRAS.values() for p in packages})
    script = (
        "import sys\n"
        f"sys.modules.update(dict.fromkeys({blocked!r}))\n"
        "from tlmpc.cli import main\n"
        f"for argv in ({['check', str(EXAMPLE)]!r}, "
        f"{['compile', str(EXAMPLE), '-o', str(tmp_path / 'out'), '-q']!r}, "
        f"{['verify', str(tmp_path / 'out' / 'trace.json')]!r}):\n"
        "    code = main(argv)\n"
        "    assert code == 0, (argv, code)\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, check=False
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert (tmp_path / "out" / "plan.svg").exists()
