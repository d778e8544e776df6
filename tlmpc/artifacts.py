"""Reading, writing and validating the JSON artifacts every stage produces.

Schemas live in the top-level ``schemas/`` folder of the repository (one source of truth);
the wheel carries them as ``tlmpc/schemas/``.  Artifacts are written canonically: sorted
keys and a trailing newline; small documents indented, large ones (meshes, traces) compact.
"""

from __future__ import annotations

import functools
import json
import math
from importlib import resources
from pathlib import Path
from typing import Any

from tlmpc.errors import UsageError, error


def schema_dir() -> Path:
    """The folder holding the JSON Schemas (packaged copy first, then the source tree)."""
    packaged = resources.files("tlmpc") / "schemas"
    if packaged.is_dir():
        return Path(str(packaged))
    return Path(__file__).resolve().parent.parent / "schemas"


@functools.cache
def load_schema(name: str) -> dict[str, Any]:
    """The schema ``schemas/<name>.schema.json`` (e.g. ``"mission"``, ``"abstraction"``)."""
    path = schema_dir() / f"{name}.schema.json"
    with path.open(encoding="utf-8") as handle:
        schema: dict[str, Any] = json.load(handle)
    return schema


def validation_errors(document: Any, name: str) -> list[str]:
    """Messages for every way ``document`` violates schema ``name`` (empty when valid)."""
    import jsonschema

    validator = jsonschema.Draft202012Validator(load_schema(name))
    return [
        f"{err.json_path}: {err.message}"
        for err in sorted(validator.iter_errors(document), key=lambda e: list(e.path))
    ]


def _finite(value: Any) -> Any:
    """Replace non-finite floats (JSON has none) by strings ``"inf"``/``"-inf"``/``"nan"``."""
    if isinstance(value, float) and not math.isfinite(value):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_finite(v) for v in value]
    return value


#: Documents shorter than this (in compact form) are written indented, for people to read;
#: larger ones (meshes, traces) compactly, which is several times faster to write.
INDENT_BELOW = 20_000


def dumps(document: Any) -> str:
    """Canonical JSON text of ``document``: sorted keys, non-finite floats as strings."""
    try:
        text = json.dumps(document, sort_keys=True, separators=(",", ":"), allow_nan=False)
    except ValueError:  # a non-finite float somewhere: JSON has none
        document = _finite(document)
        text = json.dumps(document, sort_keys=True, separators=(",", ":"), allow_nan=False)
    if len(text) < INDENT_BELOW:
        text = json.dumps(document, indent=2, sort_keys=True, allow_nan=False)
    return text + "\n"


def json_text(document: Any) -> str:
    """Indented JSON for ``--json`` output: strict JSON (non-finite floats as strings)."""
    return json.dumps(_finite(document), indent=2, sort_keys=True, allow_nan=False) + "\n"


#: Artifacts larger than this are refused while reading (the largest real ones, traces of
#: long missions, are a few MB; a parsed sample costs ~200 bytes, so memory stays < 1 GB).
MAX_ARTIFACT_BYTES = 64 * 1024 * 1024


def read_json(path: Path, expected_format: str | None = None) -> dict[str, Any]:
    """Read an artifact, checking its ``format`` prefix (e.g. ``"tlmpc.trace/"``).

    Raises :class:`UsageError` (exit 2) for unreadable files, bad JSON or another format.
    """
    try:
        with open(path, "rb") as stream:  # bounded: never read() a device or a huge file whole
            raw = stream.read(MAX_ARTIFACT_BYTES + 1)
        text = raw.decode("utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise UsageError(
            error("U001", f"cannot read {path}: {exc}", hint="check the path", file=str(path))
        ) from None
    if len(raw) > MAX_ARTIFACT_BYTES:
        raise UsageError(
            error(
                "U040",
                f"{path} is larger than {MAX_ARTIFACT_BYTES // 2**20} MiB",
                hint="artifacts are written by `tlmpc compile`; is this the right file?",
                file=str(path),
            )
        )
    try:
        document = json.loads(text)
    except RecursionError:
        raise UsageError(
            error(
                "U040",
                "the JSON is nested too deeply to read",
                hint="artifacts are written by `tlmpc compile`; was this file edited?",
                file=str(path),
            )
        ) from None
    except ValueError as exc:  # e.g. an integer of more than 4,300 digits
        if not isinstance(exc, json.JSONDecodeError):
            raise UsageError(
                error("U002", f"not readable JSON: {exc}", file=str(path), line=1, col=1)
            ) from None
        raise UsageError(
            error(
                "U002",
                f"not valid JSON: {exc.msg}",
                file=str(path),
                line=exc.lineno,
                col=exc.colno,
                hint="artifacts are written by `tlmpc compile`; was this file edited?",
            )
        ) from None
    if not isinstance(document, dict):
        raise UsageError(error("U003", "expected a JSON object", file=str(path)))
    if expected_format is not None:
        fmt = document.get("format")
        if not isinstance(fmt, str) or not fmt.startswith(expected_format):
            raise UsageError(
                error(
                    "U003",
                    f"expected a {expected_format}* document, found format {fmt!r}",
                    file=str(path),
                    hint="pass the artifact this command expects",
                )
            )
    return document
