"""The interactive view: one self-contained HTML page of a compile output or a verified log."""

from tlmpc.view.html import render_html
from tlmpc.view.scene import scene_from_log, scene_from_output

__all__ = ["render_html", "scene_from_log", "scene_from_output"]
