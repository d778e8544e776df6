"""Bounded additive velocity disturbances for closed-loop simulation: |w| <= bound always.

* ``random``: piecewise-constant noise from a seeded generator, a new value every ``hold``
  seconds, uniform over the disk of radius ``bound``;
* ``adversarial``: at every instant the w of norm ``bound`` that works against the current
  plan step's guarantee — pushed outward through the nearest facet the step must not cross
  when that facet is nearer than the exit facet (or always, in a stay), else straight
  against the exit facet's normal (slowing the exit the most).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Literal

import numpy as np

from tlmpc.abstraction.model import FloatArray
from tlmpc.runtime.executor import Executor

DisturbanceModel = Literal["random", "adversarial"]
#: w(t, reference point, executor) -> velocity added to the reference point's motion.
Disturbance = Callable[[float, FloatArray, Executor], FloatArray]


class _RandomNoise:
    """Seeded piecewise-constant noise (see :func:`random_disturbance`)."""

    def __init__(self, bound: float, seed: int, hold: float) -> None:
        self.bound, self.hold = bound, hold
        self.generator = np.random.default_rng(seed)
        self.until = -math.inf
        self.value: FloatArray = np.zeros(2)

    def __call__(self, t: float, point: FloatArray, executor: Executor) -> FloatArray:
        del point, executor
        if t >= self.until:
            angle = self.generator.uniform(0.0, 2.0 * math.pi)
            radius = self.bound * math.sqrt(self.generator.uniform(0.0, 1.0))
            self.value = radius * np.array([math.cos(angle), math.sin(angle)])
            self.until = t + self.hold
        return self.value


def random_disturbance(bound: float, seed: int, hold: float) -> Disturbance:
    """Seeded piecewise-constant noise of norm at most ``bound``, redrawn every ``hold`` s."""
    return _RandomNoise(bound, seed, hold)


def adversarial_direction(executor: Executor, point: FloatArray) -> FloatArray:
    """The unit direction that most threatens the current step at ``point`` (see the
    module doc); zero when the executor has stopped."""
    if executor.progress.status in ("no_plan", "violated"):
        return np.zeros(2)
    controller = executor.controller
    if controller.is_vertex and controller.target is not None:
        # A vertex passage: straight against the pursuit, which slows the arrival most.
        away = point - np.asarray(controller.target, dtype=np.float64)
        length = float(np.hypot(away[0], away[1]))
        unit: FloatArray = away / length if length > 0.0 else np.zeros(2)
        return unit
    normals = executor.locator.normals[controller.triangle]
    distances = executor.locator.offsets[controller.triangle] - normals @ point  # to each facet
    exit_edge = controller.exit_edge
    guarded = [facet for facet in range(3) if facet != exit_edge]
    nearest = min(guarded, key=lambda facet: float(distances[facet]))
    if exit_edge is None or distances[nearest] < distances[exit_edge]:
        direction: FloatArray = normals[nearest].copy()
        return direction
    against: FloatArray = -normals[exit_edge]
    return against


def adversarial_disturbance(bound: float) -> Disturbance:
    """The worst-case push of norm ``bound`` at every instant (see the module doc)."""

    def disturbance(t: float, point: FloatArray, executor: Executor) -> FloatArray:
        del t
        direction: FloatArray = bound * adversarial_direction(executor, point)
        return direction

    return disturbance


def make_disturbance(model: DisturbanceModel, bound: float, seed: int, hold: float) -> Disturbance:
    """The disturbance ``model`` with norm at most ``bound``."""
    if model == "adversarial":
        return adversarial_disturbance(bound)
    return random_disturbance(bound, seed, hold)
