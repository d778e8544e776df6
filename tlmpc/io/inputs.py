"""The input policy every reader follows: regular files only, bounded reads, bounded YAML.

Every file a command reads (a mission, its ``map:`` file and image, a mask, a log, a bag, an
artifact) goes through here, so a hostile path cannot stall or exhaust the process:

* Only regular files are read (:func:`open_regular`): a device (``/dev/zero``), a FIFO (which
  would block until a writer comes), a socket or a directory is refused at once.  The file is
  opened without blocking and checked on the open descriptor, so a path swapped between the
  check and the read changes nothing.
* Reads are bounded (:func:`read_bytes`): at most ``limit`` bytes are read, in pieces; a larger
  file is refused without being read whole.
* YAML that is not a mission (maps, masks) is read by :func:`load_small_yaml`, which counts the
  values while parsing, aliases expanded, and the nesting depth, and stops at the limits before
  anything is built: a few hundred bytes of nested aliases cannot expand to gigabytes.
* Values echoed in messages go through :func:`brief`, a repr cut to a few dozen characters.

Each refusal is a :class:`~tlmpc.base.errors.UsageError` with the reader's own code, the file
and a hint.
"""

from __future__ import annotations

import bisect
import contextlib
import os
import re
import reprlib
import stat
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

from tlmpc.base.errors import Diagnostic, UsageError, error
from tlmpc.io.scalar_places import line_starts

#: Pieces in which files are read (a bounded read never asks for more than it may keep).
CHUNK = 4 * 1024 * 1024

#: Small YAML files (maps, masks) expand to at most this many values, nested this deep.
MAX_YAML_VALUES = 100_000
MAX_YAML_DEPTH = 64

#: How much of a value a message may quote.
_BRIEF = reprlib.Repr()
_BRIEF.maxstring = 40
_BRIEF.maxother = 40
_BRIEF.maxlist = 6
_BRIEF.maxdict = 6
_BRIEF.maxlevel = 3


def brief(value: Any) -> str:
    """A short repr of ``value`` for a message (long strings, lists and nests are cut)."""
    return _BRIEF.repr(value)


def _kind(mode: int) -> str:
    if stat.S_ISDIR(mode):
        return "a directory"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    if stat.S_ISFIFO(mode):
        return "a FIFO (named pipe)"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "not a regular file"


def _refuse(code: str, message: str, file: str, hint: str | None) -> UsageError:
    return UsageError(error(code, message, hint=hint, file=file))


@contextlib.contextmanager
def open_regular(
    path: Path, *, code: str, what: str = "file", hint: str | None = "check the path"
) -> Iterator[IO[bytes]]:
    """``path`` opened for binary reading, refused (``code``) unless it is a regular file.

    The open does not block (a FIFO without a writer would) and the check is made on the
    open descriptor, not on the path."""
    file = str(path)
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)
    try:
        fd = os.open(path, flags)
    except OSError as exc:
        raise _refuse(
            code, f"cannot read the {what} {file}: {exc.strerror or exc}", file, hint
        ) from None
    try:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            raise _refuse(
                code,
                f"the {what} {file} is {_kind(mode)}, not a regular file",
                file,
                "tlmpc reads only regular files (no devices, pipes or directories)",
            )
        if hasattr(os, "set_blocking"):
            os.set_blocking(fd, True)
        stream = os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise
    with stream:
        yield stream


def read_bytes(
    path: Path,
    *,
    limit: int,
    code: str,
    too_large_code: str | None = None,
    what: str = "file",
    hint: str | None = "check the path",
) -> bytes:
    """The bytes of the regular file ``path``, read in pieces and refused (``too_large_code``,
    default ``code``) as soon as more than ``limit`` bytes come."""
    file = str(path)
    raw = bytearray()
    try:
        with open_regular(path, code=code, what=what, hint=hint) as stream:
            while len(raw) <= limit:
                piece = stream.read(min(CHUNK, limit + 1 - len(raw)))
                if not piece:
                    break
                raw += piece
    except OSError as exc:
        raise _refuse(
            code, f"cannot read the {what} {file}: {exc.strerror or exc}", file, hint
        ) from None
    if len(raw) > limit:
        raise _refuse(
            too_large_code or code,
            f"the {what} {file} is larger than {_size(limit)}",
            file,
            "is this the right file?",
        )
    return bytes(raw)


def read_text(
    path: Path,
    *,
    limit: int,
    code: str,
    too_large_code: str | None = None,
    what: str = "file",
    encoding: str = "utf-8",
) -> str:
    """:func:`read_bytes` decoded (``code`` when it is not text in ``encoding``)."""
    raw = read_bytes(path, limit=limit, code=code, too_large_code=too_large_code, what=what)
    try:
        return raw.decode(encoding)
    except UnicodeDecodeError as exc:
        # placed at the first bad byte: its line, and its column in the characters before it
        before = raw[: exc.start].decode(encoding, errors="replace")
        line = before.count("\n") + 1
        raise UsageError(
            error(
                code,
                f"the {what} {path} is not {encoding} text ({exc.reason} at byte {exc.start})",
                hint="save it as UTF-8 text",
                file=str(path),
                line=line,
                col=len(before) - before.rfind("\n"),
            )
        ) from None


def _size(limit: int) -> str:
    if limit >= 2**20 and limit % 2**20 == 0:
        return f"{limit // 2**20} MiB"
    if limit >= 2**10 and limit % 2**10 == 0:
        return f"{limit // 2**10} KiB"
    return f"{limit} bytes"


class _YamlLimit(Exception):
    def __init__(self, message: str, line: int | None) -> None:
        super().__init__(message)
        self.message = message
        self.line = line


def _check_yaml_events(text: str, max_values: int, max_depth: int) -> None:
    """Walk the event stream of ``text``, counting values (an alias counts as the whole value
    it names) and depth; raise :class:`_YamlLimit` at the first limit passed."""
    import yaml

    sizes: dict[str, int] = {}
    stack: list[tuple[str | None, int]] = []  # (anchor, count when the collection opened)
    count = 0
    for event in yaml.parse(text, Loader=yaml.SafeLoader):
        line = event.start_mark.line + 1 if event.start_mark is not None else None
        if isinstance(event, yaml.AliasEvent):
            count += sizes.get(event.anchor or "", 1)
        elif isinstance(event, yaml.ScalarEvent):
            count += 1
            if event.anchor:
                sizes[event.anchor] = 1
        elif isinstance(event, yaml.CollectionStartEvent):
            count += 1
            stack.append((event.anchor, count))
            if len(stack) > max_depth:
                raise _YamlLimit(f"the YAML is nested more than {max_depth} levels deep", line)
        elif isinstance(event, yaml.CollectionEndEvent):
            anchor, opened = stack.pop()
            if anchor:
                sizes[anchor] = count - opened + 1
        if count > max_values:
            raise _YamlLimit(
                f"the YAML expands (aliases included) to more than {max_values:,} values", line
            )


#: The longest YAML parser problem quoted in a message.
MAX_YAML_PROBLEM = 200


def yaml_syntax_error(exc: Any, code: str, file: str) -> Diagnostic:
    """The diagnostic of a YAML parser's ``MarkedYAMLError``: at the parser's mark, its
    problem as the message, a hint on what usually breaks YAML."""
    mark = exc.problem_mark or exc.context_mark
    problem = str(exc.problem or "invalid YAML")
    if len(problem) > MAX_YAML_PROBLEM:  # it may quote the file
        problem = problem[: MAX_YAML_PROBLEM - 1] + "…"
    hint = "check indentation (spaces only, no tabs), quotes and brackets"
    if "\t" in problem or "tab" in problem:
        hint = "YAML does not allow tabs for indentation: use spaces"
    elif "escape" in problem or "hexdecimal" in problem or "hexadecimal" in problem:
        hint = (
            "a double-quoted string's backslash starts an escape (\\\\, \\\", \\n, \\t, "
            "\\xXX, \\uXXXX but no lone half of a surrogate pair, \\UXXXXXXXX): write a "
            "backslash as \\\\, or quote the text with single quotes"
        )
    return error(
        code,
        f"YAML syntax error: {problem}",
        hint=hint,
        file=file,
        line=mark.line + 1 if mark is not None else 1,
        col=mark.column + 1 if mark is not None else 1,
    )


def yaml_error(exc: Any, code: str, file: str, text: str) -> Diagnostic:
    """The diagnostic of any error a YAML parser raised reading ``text``: at the parser's mark,
    or, for a character YAML does not allow (a reader error, which has no mark and whose
    offset libyaml counts in bytes, PyYAML in characters), at that character."""
    import yaml

    if isinstance(exc, yaml.MarkedYAMLError):
        return yaml_syntax_error(exc, code, file)
    found = None
    if isinstance(exc, yaml.reader.ReaderError):
        found = yaml.reader.Reader.NON_PRINTABLE.search(text)
    if found is None:
        return error(
            code,
            f"YAML syntax error: {brief(str(exc))}",
            hint="check the file is YAML text",
            file=file,
            line=1,
            col=1,
        )
    starts = line_starts(text)
    line = bisect.bisect_right(starts, found.start())
    return error(
        code,
        f"YAML syntax error: the character U+{ord(found.group()):04X} is not allowed in YAML",
        hint="delete it: YAML text holds no control characters but tab and line breaks, "
        'nor U+FFFE or U+FFFF; a double-quoted string can hold one as an escape ("\\x07")',
        file=file,
        line=line,
        col=found.start() - starts[line - 1] + 1,
    )


#: The characters YAML 1.1 (PyYAML, libyaml) reads as line breaks that YAML 1.2, JSON and text
#: editors read as ordinary characters: a comment would end at one and the rest of its line be
#: read as keys and values nobody sees, and every later line number would differ from the
#: editor's.
_FOREIGN_BREAK = re.compile("[\x85\u2028\u2029]")


def foreign_line_break(text: str, code: str, file: str) -> Diagnostic | None:
    """The diagnostic (``code``) of the first U+0085, U+2028 or U+2029 in the YAML ``text``,
    or None.  Its line and column are the editor's: every line break before it is one that
    both YAML and editors count."""
    found = _FOREIGN_BREAK.search(text)
    if found is None:
        return None
    starts = line_starts(text[: found.start()])
    return error(
        code,
        f"YAML syntax error: the character U+{ord(found.group()):04X} is a line break to YAML "
        "1.1 but not to editors or YAML 1.2",
        hint="delete it or write a newline; a double-quoted string can hold one as an escape "
        '("\\u2028", "\\N" for U+0085)',
        file=file,
        line=len(starts),
        col=found.start() - starts[-1] + 1,
    )


def load_small_yaml(
    text: str,
    file: str,
    *,
    code: str,
    max_values: int = MAX_YAML_VALUES,
    max_depth: int = MAX_YAML_DEPTH,
) -> Any:
    """The data of a small YAML file (a map, a mask), refused (``code``) when it is not YAML
    or when it nests or expands past the limits; found while parsing, before any value is
    built."""
    import yaml

    foreign = foreign_line_break(text, code, file)
    if foreign is not None:
        raise UsageError(foreign)
    try:
        _check_yaml_events(text, max_values, max_depth)
        return yaml.safe_load(text)
    except _YamlLimit as limit:
        raise UsageError(
            error(
                code,
                limit.message,
                hint="a map file is a handful of keys; no YAML aliases are needed",
                file=file,
                line=limit.line,
            )
        ) from None
    except yaml.YAMLError as exc:
        raise UsageError(yaml_error(exc, code, file, text)) from None
    except (RecursionError, ValueError) as exc:  # a tagged value that does not read
        mark = _unreadable_value(text)
        raise UsageError(
            error(
                code,
                f"not valid YAML: {brief(str(exc))}",
                hint="write plain values, without YAML tags such as !!float or !!binary",
                file=file,
                line=mark.line + 1 if mark is not None else None,
                col=mark.column + 1 if mark is not None else None,
            )
        ) from None


def _unreadable_value(text: str) -> Any:
    """The start mark of the first scalar of the YAML ``text``, in document order, that
    YAML cannot construct (a tagged value such as ``!!float abc``), or None."""
    import yaml

    loader = yaml.SafeLoader(text)
    try:
        root = loader.get_single_node()
        stack = [root] if root is not None else []
        while stack:
            node = stack.pop()
            if isinstance(node, yaml.ScalarNode):
                try:
                    loader.construct_object(node, deep=True)
                except (ValueError, yaml.YAMLError):
                    return node.start_mark
            elif isinstance(node, yaml.SequenceNode):
                stack.extend(reversed(node.value))
            elif isinstance(node, yaml.MappingNode):
                stack.extend(reversed([part for pair in node.value for part in pair]))
    except (RecursionError, ValueError, yaml.YAMLError):
        return None
    finally:
        loader.dispose()
    return None
