"""Render a scene into one self-contained HTML page (inline script and style, no network)."""

from __future__ import annotations

import json
from importlib import resources
from typing import Any

from tlmpc.base.errors import UNSAFE_RANGES


def render_html(scene: dict[str, Any]) -> str:
    """The page for ``scene``: the template with the scene embedded as JSON.

    ``<``, ``>`` and ``&`` are escaped inside the JSON so that no region name or message can
    close the script element or start markup; JSON.parse reads the escapes back.  The page
    shows every name and message with the characters of
    :data:`~tlmpc.base.errors.UNSAFE_RANGES` escaped, as :func:`~tlmpc.base.errors.printable`
    does: the ranges are written into the page as a regular expression's character class.
    """
    template = (resources.files("tlmpc.view") / "page.html").read_text(encoding="utf-8")
    template = template.replace("/*UNSAFE*/", json.dumps(unsafe_class()), 1)
    data = json.dumps(scene, separators=(",", ":"), allow_nan=False)
    data = data.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")
    return template.replace("/*SCENE*/", data, 1)


def unsafe_class() -> str:
    """:data:`~tlmpc.base.errors.UNSAFE_RANGES` as a JavaScript regular expression's character
    class (for the ``u`` flag, which reads a lone surrogate as one code point)."""
    return "[" + "".join(f"\\u{{{first:x}}}-\\u{{{last:x}}}" for first, last in UNSAFE_RANGES) + "]"
