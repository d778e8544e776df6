"""Reproducible installs and a releasable package: the lock covers what pyproject declares, CI
runs the README's test command, the metadata a release needs is there."""

from __future__ import annotations

import os
import re
import tomllib
from pathlib import Path

from packaging.requirements import Requirement
from packaging.utils import canonicalize_name
from packaging.version import Version

ROOT = Path(__file__).resolve().parent.parent
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())
PROJECT = PYPROJECT["project"]
LOCK = (ROOT / "requirements" / "dev.lock").read_text()

#: ``name==version [; marker]`` at the start of a lock entry, then its ``--hash`` lines.
_PIN = re.compile(
    r"^([A-Za-z0-9._-]+)==([^\s;\\]+)(?:\s*;[^\\\n]*)?\s*\\\n((?:\s+--hash=\S+.*\n)+)", re.M
)


def locked() -> dict[str, list[tuple[Version, int]]]:
    """Each locked package's versions (one per Python range) and their numbers of hashes."""
    pins: dict[str, list[tuple[Version, int]]] = {}
    for name, version, hashes in _PIN.findall(LOCK):
        pins.setdefault(canonicalize_name(name), []).append(
            (Version(version), hashes.count("--hash="))
        )
    return pins


def declared() -> list[Requirement]:
    """Every requirement pyproject.toml declares: core, every extra, the build backend."""
    texts = [*PROJECT["dependencies"], *PYPROJECT["build-system"]["requires"]]
    for requirements in PROJECT["optional-dependencies"].values():
        texts += requirements
    return [Requirement(text) for text in texts if not text.startswith("tlmpc[")]


def test_the_lock_pins_every_declared_requirement_within_its_range() -> None:
    pins = locked()
    assert len(pins) >= len(declared())
    for requirement in declared():
        versions = pins.get(canonicalize_name(requirement.name))
        assert versions, f"{requirement.name} is declared but not locked: run tools/lock"
        for version, _ in versions:
            assert requirement.specifier.contains(version, prereleases=True), (
                f"{requirement.name}=={version} is outside the declared {requirement.specifier}"
            )


def test_every_pin_carries_hashes() -> None:
    entries = re.findall(r"^[A-Za-z0-9._-]+==", LOCK, re.M)
    pins = locked()
    assert sum(len(versions) for versions in pins.values()) == len(entries)
    assert all(count >= 1 for versions in pins.values() for _, count in versions)


def readme_test_command() -> str:
    readme = (ROOT / "README.md").read_text()
    section = readme[readme.index("Run the whole test suite") :]
    match = re.search(r"```sh\n(.*?)\n```", section, flags=re.DOTALL)
    assert match is not None
    return match.group(1)


def test_ci_runs_the_readmes_test_command_from_the_lock() -> None:
    command = readme_test_command()
    assert "\n" not in command
    assert "-r requirements/dev.lock" in command
    assert "--require-hashes" in command
    assert "ruff format --check ." in command
    ci = (ROOT / ".ci" / "run").read_text()
    assert f"\n    {command}\n" in ci
    assert "twine check --strict" in ci
    assert os.access(ROOT / ".ci" / "run", os.X_OK)
    assert os.access(ROOT / "tools" / "lock", os.X_OK)


def test_the_try_it_command_installs_the_newest_releases() -> None:
    readme = (ROOT / "README.md").read_text()
    section = readme[readme.index("## Try it") : readme.index("Run the whole test suite")]
    assert "pip install -e . &&" in section
    assert "lock" not in section.split("```")[1]


def test_release_metadata() -> None:
    assert PROJECT["license"] == "MIT"
    assert PROJECT["license-files"] == ["LICENSE"]
    license_text = (ROOT / "LICENSE").read_text()
    assert license_text.startswith("MIT License")
    assert "the tlmpc authors" in license_text
    assert PROJECT["authors"]
    assert PROJECT["keywords"]
    classifiers = PROJECT["classifiers"]
    supported = re.fullmatch(r">=3\.(\d+)", PROJECT["requires-python"])
    assert supported is not None
    assert f"Programming Language :: Python :: 3.{supported.group(1)}" in classifiers
    assert "Typing :: Typed" in classifiers
    assert (ROOT / "tlmpc" / "py.typed").exists()
    changelog = (ROOT / "CHANGELOG.md").read_text()
    assert "## [Unreleased]" in changelog
