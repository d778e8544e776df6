"""Render a scene into one self-contained HTML page (inline script and style, no network)."""

from __future__ import annotations

import json
from importlib import resources
from typing import Any


def render_html(scene: dict[str, Any]) -> str:
    """The page for ``scene``: the template with the scene embedded as JSON.

    ``<``, ``>`` and ``&`` are escaped inside the JSON so that no region name or message can
    close the script element or start markup; JSON.parse reads the escapes back.
    """
    template = (resources.files("tlmpc.view") / "page.html").read_text(encoding="utf-8")
    data = json.dumps(scene, separators=(",", ":"), allow_nan=False)
    data = data.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")
    return template.replace("/*SCENE*/", data, 1)
