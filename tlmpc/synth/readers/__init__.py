"""Readers of the community's GR(1) formats: gr1c ``.spc``, slugs ``.slugsin`` and
``.structuredslugs``, and TLSF.

Each reader follows its source tool's semantics (docs/synthesis.md) and returns a
:class:`~tlmpc.synth.spec.GameSpec`; what it refuses is a located diagnostic (codes ``Q0xx``).
"""

from __future__ import annotations

from pathlib import Path

from tlmpc.base.errors import UsageError, error
from tlmpc.synth.spec import GameSpec, InitMode

#: file suffix -> format name
FORMATS = {
    ".spc": "gr1c",
    ".slugsin": "slugsin",
    ".structuredslugs": "structuredslugs",
    ".tlsf": "tlsf",
}


def format_of(path: str) -> str | None:
    """The format a file name's suffix names, or None."""
    return FORMATS.get(Path(path).suffix.lower())


def read_text(path: str) -> str:
    """The file's text, or a U001 diagnostic (exit 2)."""
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        raise UsageError(
            error(
                "U001",
                f"cannot read the specification: {exc.strerror or exc}",
                hint="check the path",
                file=path,
            )
        ) from None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line_start = data.rfind(b"\n", 0, exc.start) + 1
        # the column counts the characters before the byte, as a reader of the text would
        col = len(data[line_start : exc.start].decode("utf-8", errors="replace")) + 1
        raise UsageError(
            error(
                "Q001",
                "the specification is not UTF-8 text",
                hint=f"byte {exc.start} cannot be decoded; save the file as UTF-8",
                file=path,
                line=data.count(b"\n", 0, exc.start) + 1,
                col=col,
            )
        ) from None


def read_spec(path: str, *, fmt: str | None = None, init_mode: InitMode | None = None) -> GameSpec:
    """Read a specification file in ``fmt`` (default: by its suffix)."""
    fmt = fmt or format_of(path)
    if fmt is None:
        raise UsageError(
            error(
                "Q002",
                "cannot tell the specification's format from its name",
                hint="name it .spc (gr1c), .slugsin (slugs) or .tlsf, or pass --input-format",
                file=path,
            )
        )
    text = read_text(path)
    return parse_spec(text, fmt, file=path, init_mode=init_mode)


def parse_spec(
    text: str, fmt: str, *, file: str = "<input>", init_mode: InitMode | None = None
) -> GameSpec:
    """Parse specification text in one of the formats."""
    if fmt == "gr1c":
        from tlmpc.synth.readers.gr1c import parse_gr1c

        return parse_gr1c(text, file=file, init_mode=init_mode or "forall_env_exists_sys")
    if fmt == "slugsin":
        from tlmpc.synth.readers.slugsin import parse_slugsin

        return parse_slugsin(text, file=file, init_mode=init_mode or "forall_env_exists_sys")
    if fmt == "structuredslugs":
        from tlmpc.synth.readers.structuredslugs import parse_structuredslugs

        return parse_structuredslugs(
            text, file=file, init_mode=init_mode or "forall_env_exists_sys"
        )
    if fmt == "tlsf":
        from tlmpc.synth.readers.tlsf import parse_tlsf

        return parse_tlsf(text, file=file, init_mode=init_mode or "forall_env_exists_sys")
    raise ValueError(f"unknown format {fmt!r}")
