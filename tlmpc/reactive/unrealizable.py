"""The answer "no robot strategy exists" of a reactive mission, as an exception.

Its own module, importing nothing of the game or the solver: ``tlmpc compile`` catches it on
every run, and a mission without sensors should not load the BDD library to do so.
"""

from __future__ import annotations

from collections.abc import Collection
from typing import Any

from tlmpc.base.errors import Diagnostic, NoPlanError


class UnrealizableError(NoPlanError):
    """An unrealizable reactive mission (exit 1): its diagnostics, and the artifacts that show
    how the environment wins (``mission.json``, ``abstraction.json``,
    ``counterstrategy.json``), which ``tlmpc compile`` writes before it reports; ``produced``
    names those the failing stage made itself, which ``tlmpc stage`` writes."""

    def __init__(
        self,
        diagnostics: list[Diagnostic],
        artifacts: dict[str, Any],
        produced: Collection[str] = (),
    ) -> None:
        super().__init__(diagnostics)
        self.artifacts = artifacts
        self.produced = frozenset(produced)
