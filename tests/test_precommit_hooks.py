"""pre-commit, end to end: the README's hook blocks a broken `mission.yaml` in a fresh repository.

Runs the real `pre-commit` (from PyPI) in a temporary git repository, offline: the README's
`repo: local` hook needs no download, and the remote form clones this repository from its path.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parent.parent

GOOD = """\
version: 1
workspace:
  boundary: {rect: [0, 0, 10, 10]}
regions:
  dock: {rect: [8, 8, 9.5, 9.5]}
  home: {rect: [0.5, 0.5, 2, 2]}
robot: {start: [1, 1]}
task:
  - visit dock then return to home
"""
BROKEN = GOOD.replace("visit dock", "visit dok")

MISSION_FILES = [
    "mission.yaml",
    "mission.yml",
    "robots/kitchen.mission.yaml",
    "warehouse-mission.yaml",
    "night_mission.yaml",
    "missions.yaml",
    "missions/night.yaml",
    "missions/site-map.yaml",  # a map beside its mission: check reads it as a map
    "deploy/missions/a/b.yaml",
    "-x.mission.yaml",
]
# `mission` inside a longer word is no mission
OTHER_FILES = [
    "config/settings.yaml",
    ".github/workflows/ci.yml",
    "emission.txt",
    "mission.json",
    "config/permissions.yaml",
    ".github/permissions.yml",
    "transmission.yaml",
    "emissions.yaml",
    "docs/submission.yaml",
    "missionary.yml",
    "submissions/a.yaml",
]


def _readme_hook_config() -> str:
    readme = (ROOT / "README.md").read_text()
    section = readme[readme.index("## Use as a pre-commit hook") :]
    match = re.search(r"```yaml\n(.*?)```", section, flags=re.DOTALL)
    assert match is not None
    return match.group(1)


def _hooks() -> list[dict[str, object]]:
    hooks = yaml.safe_load((ROOT / ".pre-commit-hooks.yaml").read_text())
    assert isinstance(hooks, list)
    return hooks


def test_published_hooks_match_mission_files() -> None:
    readme_hook = yaml.safe_load(_readme_hook_config())["repos"][0]["hooks"][0]
    patterns = [re.compile(str(h["files"])) for h in _hooks()]
    patterns.append(re.compile(readme_hook["files"]))
    for pattern in patterns:
        for name in MISSION_FILES:
            assert pattern.search(name), (pattern.pattern, name)
        for name in OTHER_FILES:
            assert not pattern.search(name), (pattern.pattern, name)
    for hook in [*_hooks(), readme_hook]:
        # `--`: a file named like a flag (`-x.mission.yaml`) is still a file
        assert hook["entry"] == "tlmpc check --"


def test_repository_checks_its_own_specs() -> None:
    config = yaml.safe_load((ROOT / ".pre-commit-config.yaml").read_text())
    hook = next(h for repo in config["repos"] for h in repo["hooks"] if h["id"] == "tlmpc-check")
    pattern = re.compile(hook["files"])
    for spec in (ROOT / "specs").glob("*.yaml"):
        assert pattern.search(f"specs/{spec.name}")
    # the deliberately broken fixtures under tests/mission/bad/ are left out
    exclude = re.compile(hook["exclude"])
    fixtures = sorted((ROOT / "tests" / "mission" / "bad").glob("*.yaml"))
    assert fixtures
    for fixture in fixtures:
        name = fixture.relative_to(ROOT).as_posix()
        assert pattern.search(name)
        assert exclude.search(name)


def _environment(tmp_path: Path) -> dict[str, str]:
    tlmpc = shutil.which("tlmpc", path=str(Path(sys.executable).parent)) or shutil.which("tlmpc")
    if tlmpc is None:
        pytest.skip("the tlmpc console script is not installed")
    pytest.importorskip("pre_commit")
    if shutil.which("git") is None:
        pytest.skip("git is not installed")
    env = dict(os.environ)
    env.update(
        PATH=os.pathsep.join([str(Path(tlmpc).parent), env.get("PATH", "")]),
        PYTHONPATH=os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")]),
        PRE_COMMIT_HOME=str(tmp_path / "cache"),
        HOME=str(tmp_path / "home"),
        GIT_AUTHOR_NAME="t",
        GIT_AUTHOR_EMAIL="t@example.org",
        GIT_COMMITTER_NAME="t",
        GIT_COMMITTER_EMAIL="t@example.org",
        GIT_CONFIG_NOSYSTEM="1",
        # offline: nothing may be fetched from an index
        PIP_NO_INDEX="1",
    )
    (tmp_path / "home").mkdir()
    return env


def _git(repo: Path, env: dict[str, str], *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        ["git", *args], cwd=repo, env=env, capture_output=True, text=True, check=False
    )


def _fresh_repository(tmp_path: Path, env: dict[str, str], config: str) -> Path:
    repo = tmp_path / "user-repo"
    repo.mkdir()
    assert _git(repo, env, "init", "-q").returncode == 0
    (repo / ".pre-commit-config.yaml").write_text(config)
    installed = subprocess.run(
        [sys.executable, "-m", "pre_commit", "install"],
        cwd=repo,
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )
    assert installed.returncode == 0, installed.stdout + installed.stderr
    assert _git(repo, env, "add", ".pre-commit-config.yaml").returncode == 0
    return repo


def _commit_blocks_broken_and_passes_good(repo: Path, env: dict[str, str], name: str) -> None:
    path = repo / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(BROKEN)
    _git(repo, env, "add", "-A")
    blocked = _git(repo, env, "commit", "-m", "broken mission")
    assert blocked.returncode != 0
    output = blocked.stdout + blocked.stderr
    assert f"{name}:9:11: error[L010]: unknown region 'dok'" in output, output
    path.write_text(GOOD)
    _git(repo, env, "add", "-A")
    passed = _git(repo, env, "commit", "-m", "good mission")
    assert passed.returncode == 0, passed.stdout + passed.stderr
    assert "tlmpc mission check" in passed.stdout + passed.stderr


@pytest.mark.slow
def test_readme_instructions_block_a_broken_mission_in_a_fresh_repository(
    tmp_path: Path,
) -> None:
    env = _environment(tmp_path)
    repo = _fresh_repository(tmp_path, env, _readme_hook_config())
    _commit_blocks_broken_and_passes_good(repo, env, "mission.yaml")
    _commit_blocks_broken_and_passes_good(repo, env, "robots/kitchen.mission.yaml")
    # a YAML file that is not a mission is left alone
    (repo / "settings.yaml").write_text("a: [1\n")
    (repo / "config").mkdir()
    (repo / "config" / "permissions.yaml").write_text("users: [a]\n")
    _git(repo, env, "add", "-A")
    assert _git(repo, env, "commit", "-m", "other yaml").returncode == 0
    # `tlmpc new map` writes a map beside the mission, under missions/: checked as a map
    (repo / "missions").mkdir()
    made = subprocess.run(
        ["tlmpc", "new", "map", "-o", "missions/site.yaml"],
        cwd=repo,
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )
    assert made.returncode == 0, made.stderr
    _git(repo, env, "add", "-A")
    mapped = _git(repo, env, "commit", "-m", "a mission on a map")
    assert mapped.returncode == 0, mapped.stdout + mapped.stderr
    # a file named like a flag is a file
    _commit_blocks_broken_and_passes_good(repo, env, "-x.mission.yaml")


@pytest.mark.slow
def test_remote_form_from_a_clone_at_a_commit(tmp_path: Path) -> None:
    env = _environment(tmp_path)
    head = _git(ROOT, env, "rev-parse", "HEAD")
    if head.returncode != 0:
        pytest.skip("not a git checkout")
    committed = _git(ROOT, env, "show", "HEAD:.pre-commit-hooks.yaml")
    if committed.stdout != (ROOT / ".pre-commit-hooks.yaml").read_text():
        pytest.skip(".pre-commit-hooks.yaml has uncommitted changes")
    config = (
        "repos:\n"
        f"  - repo: {ROOT}\n"
        f"    rev: {head.stdout.strip()}\n"
        "    hooks:\n"
        "      - id: tlmpc-check\n"
    )
    repo = _fresh_repository(tmp_path, env, config)
    _commit_blocks_broken_and_passes_good(repo, env, "mission.yaml")


def test_check_runs_with_only_its_light_dependencies(tmp_path: Path) -> None:
    """The light install: `check` works when the compiler's heavy packages are missing."""
    path = tmp_path / "mission.yaml"
    path.write_text(BROKEN)
    script = (
        "import sys\n"
        "class Block:\n"
        "    def find_spec(self, name, path=None, target=None):\n"
        "        if name.split('.')[0] in ('scipy', 'clarabel', 'triangle', 'matplotlib',"
        " 'cvxpy'):\n"
        "            raise ImportError(name + ' is not installed')\n"
        "sys.meta_path.insert(0, Block())\n"
        "from tlmpc.cli import main\n"
        f"sys.exit(main(['check', {str(path)!r}]))\n"
    )
    result = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, check=False
    )
    assert result.returncode == 1, result.stderr
    assert "error[L010]" in result.stderr
