"""The verifier's answer: verdict, per-conjunct progress, violations, robustness, certificate."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Literal

from tlmpc.base.content import ContentEquality

#: ``satisfied``: every continuation satisfies the task (for a lasso or a stay: the trace does);
#: ``violated``: no continuation can; ``inconclusive``: some may and some may not.
Outcome = Literal["satisfied", "violated", "inconclusive"]

#: How the end of the trace is read: ``loop`` (a declared repeating part), ``stay`` (the robot
#: stays at its last point forever) or ``open`` (the log simply ends; the future is unknown).
Ending = Literal["loop", "stay", "open"]


@dataclass(frozen=True, slots=True, kw_only=True)
class Counterexample:
    """One violation: which conjunct it breaks (or ``workspace``), when and where, in words."""

    conjunct: str
    time: float | None
    position: tuple[float, float] | None
    message: str


#: Every violation is reported as one of these.
Violation = Counterexample


@dataclass(frozen=True, slots=True, kw_only=True)
class ConjunctReport:
    """A top-level conjunct of the task: its own verdict and a line of progress."""

    conjunct: str
    outcome: Outcome
    progress: str
    visits: int | None = None
    last_visit: float | None = None
    longest_gap: float | None = None
    #: By how many seconds its time bounds held (> 0) or failed (< 0); None without bounds.
    time_robustness: float | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class Certificate:
    """Whether the verdict carries over to the real robot between the samples.

    Assumes the robot's speed never exceeds ``max_speed``; checks it against the samples
    (``observed_speed``: the largest distance over time between consecutive samples, a lower
    bound on the true top speed).  ``margin`` is the robustness of the verdict when every
    sample may be off by ``max_speed`` times half the neighbouring gaps (``bound``: the largest
    such radius); ``margin > 0`` certifies.
    """

    certified: bool
    max_speed: float | None
    observed_speed: float
    max_gap: float
    bound: float | None
    margin: float | None
    reason: str


#: Who broke a reactive run: the environment (an assumption) or the robot (a guarantee).
Blame = Literal["environment", "robot"]


@dataclass(frozen=True, slots=True, kw_only=True)
class PartVerdict:
    """One assumption or guarantee part: its own verdict on the run and when it broke."""

    part: str
    outcome: Outcome
    #: the earliest instant (seconds from the log's first sample) at which the run's prefix was
    #: bad for the part; None when it never was (it holds, is undecided, or fails only in the
    #: limit)
    broken: float | None


@dataclass(frozen=True, slots=True, kw_only=True)
class AssumeGuarantee:
    """The assume-guarantee verdict of a reactive run."""

    outcome: Outcome
    blame: Blame | None
    assumptions: tuple[PartVerdict, ...]
    guarantees: tuple[PartVerdict, ...]
    #: the assumption the environment broke first (at the earliest instant, else in the
    #: limit), whoever is to blame; None when it kept every assumption (or may have)
    environment: PartVerdict | None
    #: the guarantee part the robot broke first, likewise
    robot: PartVerdict | None


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class Verdict(ContentEquality):
    """The verifier's answer for one trace."""

    outcome: Outcome
    formula: str
    convention: str
    ending: Ending
    robustness: float
    certificate: Certificate
    #: By how many seconds the task's time bounds held (> 0) or failed (< 0), None without
    #: bounds or for an inconclusive verdict (see tlmpc.verify.time_robustness).
    time_robustness: float | None = None
    pieces: int
    conjuncts: tuple[ConjunctReport, ...] = ()
    violations: tuple[Violation, ...] = ()
    stats: Mapping[str, Any] = field(default_factory=dict)
    #: A reactive run's assume-guarantee verdict (``outcome`` is its outcome); None else.
    reactive: AssumeGuarantee | None = None

    @property
    def satisfied(self) -> bool:
        """True only for ``satisfied``."""
        return self.outcome == "satisfied"

    @property
    def certified(self) -> bool:
        """The certificate holds."""
        return self.certificate.certified

    @property
    def certificate_bound(self) -> float | None:
        """The largest per-sample radius the certificate allows for."""
        return self.certificate.bound

    @property
    def max_gap(self) -> float:
        """The largest time between consecutive samples."""
        return self.certificate.max_gap

    @property
    def counterexample(self) -> Counterexample | None:
        """The first violation of the task itself (not of the workspace)."""
        return next((v for v in self.violations if v.conjunct != "workspace"), None)

    @property
    def workspace_violation(self) -> Counterexample | None:
        """The first time the robot left the workspace or entered a hole."""
        return next((v for v in self.violations if v.conjunct == "workspace"), None)
