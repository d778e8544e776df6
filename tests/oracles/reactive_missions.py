"""Reactive missions several test folders share.

``GUARD_UNREALIZABLE``: a guard must visit ``home`` and ``lab`` infinitely often but never
enter ``lab`` while ``alarm``; nothing stops the environment from raising ``alarm`` forever,
so no strategy exists (Q110), and its counterstrategy holds the alarm up.
"""

from __future__ import annotations

GUARD_UNREALIZABLE = """\
version: 1
name: guard-unrealizable
workspace:
  boundary: {rect: [0, 0, 10, 6]}
  holes: [{rect: [4, 2, 6, 4]}]
regions:
  home: {rect: [0.5, 0.5, 2, 2]}
  lab: {rect: [4, 4.5, 6, 6]}
sensors:
  alarm: null
robot: {start: [1, 1], max_speed: 1.0}
task:
  - visit home infinitely often
  - never enter lab while alarm
  - visit lab infinitely often
"""
