"""The pre-commit hook definition: present, pointing at `tlmpc check`, matching the specs."""

from __future__ import annotations

import re
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parent.parent


def test_hook_definition() -> None:
    hooks = yaml.safe_load((ROOT / ".pre-commit-hooks.yaml").read_text())
    hook = next(h for h in hooks if h["id"] == "tlmpc-check")
    assert hook["entry"] == "tlmpc check"
    assert hook["language"] == "python"
    pattern = re.compile(hook["files"])
    for spec in (ROOT / "specs").glob("*.yaml"):
        assert pattern.search(f"specs/{spec.name}")
    assert pattern.search("robots/kitchen.mission.yaml")
    assert not pattern.search("config/settings.yaml")


def test_repository_checks_its_own_specs() -> None:
    config = yaml.safe_load((ROOT / ".pre-commit-config.yaml").read_text())
    ids = [h["id"] for repo in config["repos"] for h in repo["hooks"]]
    assert "tlmpc-check" in ids
