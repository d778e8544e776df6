"""Reading, writing and validating the JSON artifacts every stage produces.

Schemas live in the top-level ``schemas/`` folder of the repository (one source of truth);
the wheel carries them as ``tlmpc/schemas/``.  Artifacts are written canonically: sorted
keys and a trailing newline; small documents indented, large ones (meshes, traces) compact.
"""

from __future__ import annotations

import json
import marshal
import math
import re
from collections import Counter
from collections.abc import Iterable, Iterator, Mapping
from pathlib import Path
from typing import Any

from tlmpc.base.errors import UsageError, error
from tlmpc.io.arrays import ArrayList, TableList, encoded_pieces, has_standins, plain
from tlmpc.io.schema_check import validation_errors


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


def dumps(document: Any, shared: SharedTexts | None = None) -> str:
    """Canonical JSON text of ``document``: sorted keys, non-finite floats as strings.

    ``shared``: texts of large top-level values already encoded for another document of the
    same write (see :func:`artifact_texts`).
    """
    try:
        text = _compact(document, shared)
    except ValueError:  # a non-finite float somewhere: JSON has none
        document = _finite(plain(document))
        text = json.dumps(document, sort_keys=True, separators=(",", ":"), allow_nan=False)
    if len(text) < INDENT_BELOW:
        text = json.dumps(plain(document), indent=2, sort_keys=True, allow_nan=False)
    return text + "\n"


def artifact_pieces(
    artifacts: Mapping[str, Any],
) -> Iterator[tuple[str, str | bytes | Iterator[str]]]:
    """``(name, content)`` of each artifact as :func:`artifact_texts` gives it, except that a
    document holding arrays comes as the pieces of its text (:func:`dump_pieces`), to be
    written one after the other."""
    shared = SharedTexts.among(artifacts.values())
    for name, content in artifacts.items():
        if isinstance(content, str | bytes):
            yield name, content
        elif has_standins(content):
            yield name, dump_pieces(content, shared)
        else:
            yield name, dumps(content, shared)


def artifact_texts(artifacts: Mapping[str, Any]) -> Iterator[tuple[str, str | bytes]]:
    """``(name, text)`` of each artifact, one at a time: texts and bytes as they are, JSON
    documents by :func:`dumps`, a large value that several documents hold under the same
    top-level key (the regions of ``mission.json``, ``abstraction.json`` and ``trace.json``)
    encoded once."""
    shared = SharedTexts.among(artifacts.values())
    for name, content in artifacts.items():
        yield name, content if isinstance(content, str | bytes) else dumps(content, shared)


#: Top-level values with fewer items than this are encoded again rather than looked up.
_SHARED_FROM = 64

#: Without the encoder's bookkeeping of open containers (a fifth of the time on meshes): a
#: document holding itself fails all the same, with RecursionError, as it did with the
#: bookkeeping (its ValueError sent the document to ``_finite``, which recursed forever).
_COMPACT = json.JSONEncoder(
    sort_keys=True, separators=(",", ":"), allow_nan=False, check_circular=False
)


class SharedTexts:
    """Compact texts of top-level values by key, for the values that several documents hold.

    A value is found again when it is the very object encoded before under that key (the
    stages share the regions' document among their artifacts), else by its ``marshal``
    bytes, which tell every type apart (``1``, ``1.0`` and ``True``; ``0.0`` and ``-0.0``)
    and fix the order of every dict and list: equal bytes, equal data, the same JSON text.
    The bytes are taken only when a key holds a value that is not one encoded before (a
    hundred thousand regions take a tenth of a second to marshal).  A value ``marshal``
    refuses (a subclass, say) is simply encoded again.
    """

    def __init__(self, keys: set[str]) -> None:
        self.keys = keys
        #: per key, the values encoded so far (held, so that their ids stay theirs), their
        #: texts, and their marshal bytes once some other value needed them
        self.encoded: dict[str, list[tuple[Any, str, bytes | None]]] = {}

    @classmethod
    def among(cls, documents: Iterable[Any]) -> SharedTexts:
        """For the large values that several of ``documents`` hold under the same key."""
        names = Counter(
            key
            for document in documents
            if type(document) is dict
            for key, value in document.items()
            if type(value) in (dict, list) and len(value) >= _SHARED_FROM
        )
        return cls({key for key, count in names.items() if count > 1})

    def text(self, key: str, value: Any) -> str:
        """The compact JSON text of ``value``, held at ``key`` of a document."""
        if key not in self.keys or type(value) not in (dict, list):
            return _COMPACT.encode(value)
        encoded = self.encoded.setdefault(key, [])
        for held, text, _ in encoded:
            if held is value:
                return text
        if not encoded:  # the first value under this key: no bytes to compare with yet
            text = _COMPACT.encode(value)
            encoded.append((value, text, None))
            return text
        try:
            fingerprint = marshal.dumps(value)
        except ValueError:
            return _COMPACT.encode(value)
        for number, (held, text, known) in enumerate(encoded):
            if known is None:  # encoded before without its bytes: take them now
                try:
                    known = marshal.dumps(held)
                except ValueError:
                    continue
                encoded[number] = (held, text, known)
            if known == fingerprint:
                return text
        text = _COMPACT.encode(value)
        encoded.append((value, text, fingerprint))
        return text


def _compact(document: Any, shared: SharedTexts | None) -> str:
    """What ``json.dumps(document, sort_keys=True, separators=(",", ":"), allow_nan=False)``
    returns, with the top-level values of a dict holding a shared key taken from ``shared``."""
    if not has_standins(document) and (
        shared is None or type(document) is not dict or shared.keys.isdisjoint(document)
    ):
        return _COMPACT.encode(document)
    return "".join(_compact_pieces(document, shared))  # the texts of a mesh, copied once


def _compact_pieces(document: dict[Any, Any], shared: SharedTexts | None) -> Iterator[str]:
    """The pieces of :func:`_compact`'s text of a dict, its stand-ins a block at a time.

    Every value the encoder could refuse is encoded (or checked) here, before the first
    piece: the pieces that follow cannot fail.
    """
    # The encoder sorts the items of a dict by key and writes each value independently of
    # its surroundings: the same text, piece by piece.  (The document has a text key, the
    # shared one: a key of another type beside it fails to sort here as in the encoder.)
    order = sorted(document)
    texts: list[str | Iterator[str]] = []
    for key in order:
        value = document[key]
        if isinstance(value, ArrayList | TableList):
            texts.append(encoded_pieces(value, _COMPACT))
        elif shared is not None:
            texts.append(shared.text(key, value))
        else:
            texts.append(_COMPACT.encode(value))
    keys = [_COMPACT.encode(key) for key in order]
    return _pieces(keys, texts)


def _pieces(keys: list[str], texts: list[str | Iterator[str]]) -> Iterator[str]:
    yield "{"
    for number, (key, text) in enumerate(zip(keys, texts, strict=True)):
        yield ("," if number else "") + key + ":"
        if isinstance(text, str):
            yield text
        else:
            yield from text
    yield "}"


def dump_pieces(document: Any, shared: SharedTexts | None = None) -> Iterator[str]:
    """The pieces of :func:`dumps`'s text, a large document's arrays a block of rows at a
    time (the whole text of a mesh is never held)."""
    if not has_standins(document):
        yield dumps(document, shared)
        return
    try:
        pieces = _compact_pieces(document, shared)
    except ValueError:  # a non-finite float: the whole document the slow way
        yield dumps(document, shared)
        return
    head: list[str] = []
    length = 0
    for piece in pieces:
        head.append(piece)
        length += len(piece)
        if length >= INDENT_BELOW:
            break
    else:  # short: written indented, as dumps writes it
        yield json.dumps(plain(document), indent=2, sort_keys=True, allow_nan=False) + "\n"
        return
    yield from head
    yield from pieces
    yield "\n"


def json_text(document: Any) -> str:
    """Indented JSON for ``--json`` output: strict JSON (non-finite floats as strings)."""
    return json.dumps(_finite(document), indent=2, sort_keys=True, allow_nan=False) + "\n"


#: Artifacts larger than this are refused while reading (the largest real ones, traces of
#: long missions, are a few MB; a parsed sample costs ~200 bytes, so memory stays < 1 GB).
MAX_ARTIFACT_BYTES = 64 * 1024 * 1024


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not a JSON number (tlmpc writes non-finite numbers as strings)")


#: A number that may overflow to infinity when read: an exponent of three digits or more, or
#: more than 308 digits before its point (no exponent at all).
_HUGE_NUMBER = re.compile(r"[0-9][eE]\+?[0-9]{3}|[0-9]{309}")


def _huge_number_place(text: str) -> tuple[int, int]:
    """Line and column of the first number of ``text`` that overflows (or has more digits than
    Python reads, 4,300); 1, 1 when there is none."""
    for found in _HUGE_NUMBER.finditer(text):
        start, end = found.start(), found.end()
        while start > 0 and text[start - 1] in _NUMBER_CHARACTERS:
            start -= 1
        while end < len(text) and text[end] in _NUMBER_CHARACTERS:
            end += 1
        try:
            finite = math.isfinite(float(text[start:end]))
        except ValueError:
            finite = False
        if not finite or end - start > 4300:
            return text.count("\n", 0, start) + 1, start - text.rfind("\n", 0, start)
    return 1, 1


_NUMBER_CHARACTERS = frozenset("0123456789.-+eE")


def _has_non_finite(document: Any) -> bool:
    stack = [document]
    while stack:
        value = stack.pop()
        if isinstance(value, float):
            if not math.isfinite(value):
                return True
        elif isinstance(value, dict):
            stack.extend(value.values())
        elif isinstance(value, list):
            stack.extend(value)
    return False


def read_json(
    path: Path, expected_format: str | None = None, *, finite: bool = True
) -> dict[str, Any]:
    """Read an artifact, checking its ``format`` prefix (e.g. ``"tlmpc.trace/"``).

    Raises :class:`UsageError` (exit 2) for unreadable files, bad JSON or another format, and
    (``finite``) for ``NaN``/``Infinity``, which tlmpc never writes; a user's trace is read
    with ``finite=False`` so that the verifier reports a non-finite sample where it is.
    """
    from tlmpc.io.inputs import read_text

    # bounded, regular files only: never read() a device, a FIFO or a huge file whole
    text = read_text(
        path, limit=MAX_ARTIFACT_BYTES, code="U001", too_large_code="U040", what="artifact"
    )
    return parse_json(text, path, expected_format, finite=finite)


def parse_json(
    text: str, path: Path, expected_format: str | None = None, *, finite: bool = True
) -> dict[str, Any]:
    """The artifact whose text (read from ``path``) is ``text``: :func:`read_json` for a
    caller that keeps the text, to place its own diagnostics in it."""
    try:
        document = json.loads(text, parse_constant=_no_constant if finite else None)
        if finite and _HUGE_NUMBER.search(text) and _has_non_finite(document):
            raise ValueError("a number too large for a float (it reads as infinity)")
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
            number_line, number_col = _huge_number_place(text)
            raise UsageError(
                error(
                    "U002",
                    f"not readable JSON: {exc}",
                    hint="artifacts are written by `tlmpc compile`; was this file edited?",
                    file=str(path),
                    line=number_line,
                    col=number_col,
                )
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
        from tlmpc.io.json_places import json_place

        line, col = json_place(text, "$") or (None, None)
        raise UsageError(
            error(
                "U003",
                "expected a JSON object, found "
                + ("an array" if isinstance(document, list) else json.dumps(document)[:40]),
                hint='an artifact is a JSON object {"format": ..., ...}',
                file=str(path),
                line=line,
                col=col,
            )
        )
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


#: The schema each artifact read back from an output folder is checked against.
ARTIFACT_SCHEMAS = {
    "mission.json": ("tlmpc.mission/", "mission-artifact"),
    "abstraction.json": ("tlmpc.abstraction/", "abstraction"),
    "automaton.json": ("tlmpc.automaton/", "automaton"),
    "witness.json": ("tlmpc.witness/", "witness"),
    "controllers.json": ("tlmpc.controllers/", "controllers"),
    "trace.json": ("tlmpc.trace/", "trace"),
    "verdict.json": ("tlmpc.verdict/", "verdict"),
    "summary.json": ("tlmpc.summary/", "summary"),
    "strategy.json": ("tlmpc.strategy/", "strategy"),
    "counterstrategy.json": ("tlmpc.counterstrategy/", "counterstrategy"),
}


def read_artifact(path: Path, schema: str) -> dict[str, Any]:
    """The artifact at ``path``, checked against ``schema`` (U071, exit 2, when it fails);
    another kind of artifact under its name is U003."""
    expected = next((fmt for fmt, name in ARTIFACT_SCHEMAS.values() if name == schema), None)
    document = read_json(path, expected)
    problems = validation_errors(document, schema)
    if problems:
        raise UsageError(
            error(
                "U071",
                f"{path.name} does not match its schema: {_cut(problems[0])}",
                file=str(path),
                hint="artifacts are written by `tlmpc compile`; was this file edited?",
            )
        )
    return document


def _cut(text: str, limit: int = 300) -> str:
    """A schema message cut short: it may quote a whole (edited, huge) value."""
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _tampered(path: Path, message: str, code: str = "U042") -> UsageError:
    return UsageError(
        error(
            code,
            f"{message}",
            hint="this output was edited or damaged; compile the mission again",
            file=str(path),
        )
    )


def read_artifacts(directory: Path, names: tuple[str, ...]) -> dict[str, dict[str, Any]]:
    """The artifacts ``names`` that exist in the output ``directory``, each checked against
    its schema (U041) and against each other (U042: indices in range, the task's regions
    defined), so ``plot`` and ``export`` never work on a tampered or mixed-up output."""
    documents: dict[str, dict[str, Any]] = {}
    for name in names:
        path = directory / name
        if not path.is_file():
            if path.exists() or path.is_symlink():
                raise _tampered(path, f"{name} is not a regular file", "U041")
            continue
        fmt, schema = ARTIFACT_SCHEMAS[name]
        document = read_json(path, fmt)
        problems = validation_errors(_skeleton(path, document), schema)
        if problems:
            shown = "; ".join(map(_cut, problems[:3])) + (" ..." if len(problems) > 3 else "")
            raise _tampered(path, f"{name} does not match its schema: {shown}", "U041")
        documents[name] = document
    cross_check(directory, documents)
    return documents


def _skeleton(path: Path, document: dict[str, Any]) -> dict[str, Any]:
    """``document`` with each long numeric array cut to one representative item.

    jsonschema descends into every item (seconds on a large mesh); numpy checks instead that
    an array is rectangular, numeric and finite, and the schema then sees one item of the
    same kind (an integer row if all are integers, else a float row)."""
    import numpy as np  # here, not at the top: `tlmpc check` never reads artifacts

    small = dict(document)
    for key, value in document.items():
        if not isinstance(value, list) or len(value) < 2:
            continue
        try:
            array = np.asarray(value)
        except ValueError:  # ragged: let the schema report it
            continue
        if array.dtype.kind not in "iuf" or array.ndim == 0:
            continue
        if array.dtype.kind == "f" and not np.all(np.isfinite(array)):
            raise _tampered(path, f"{path.name}: {key} holds a non-finite number", "U041")
        small[key] = array[:1].tolist()
    return small


def _indices(values: Any, bound: int, low: int = 0) -> bool:
    """True when ``values`` (nested lists) are all integers in ``[low, bound)``."""
    stack = [values]
    while stack:
        value = stack.pop()
        if isinstance(value, list):
            stack.extend(value)
        elif isinstance(value, bool) or not isinstance(value, int) or not low <= value < bound:
            return False
    return True


def _mesh_problem(abstraction: Mapping[str, Any]) -> str | None:
    """What makes the (index-checked) triangles of ``abstraction`` not one mesh, or None: a
    triangle not counter-clockwise, or a neighbour that does not share the edge opposite the
    vertex it stands for, or does not name the triangle back."""
    import numpy as np  # here, not at the top: `tlmpc check` never reads artifacts

    vertices = np.asarray(abstraction["vertices"], dtype=np.float64).reshape(-1, 2)
    triangles = np.asarray(abstraction["triangles"], dtype=np.int64).reshape(-1, 3)
    neighbors = np.asarray(abstraction["neighbors"], dtype=np.int64).reshape(-1, 3)
    a, b, c = (vertices[triangles[:, corner]] for corner in range(3))
    twice_area = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (
        c[:, 0] - a[:, 0]
    )
    flat = np.flatnonzero(~(twice_area > 0.0))
    if flat.size:
        return f"triangle {int(flat[0])} is not counter-clockwise with a positive area"
    for corner in range(3):  # facet `corner` is the edge opposite that vertex
        inner = np.flatnonzero(neighbors[:, corner] >= 0)
        outer = neighbors[inner, corner]
        back = neighbors[outer] == inner[:, None]
        facet = np.argmax(back, axis=1)
        rows = np.arange(inner.size)
        mine = np.sort(triangles[inner][:, [(corner + 1) % 3, (corner + 2) % 3]], axis=1)
        theirs = np.sort(
            np.stack(
                [
                    triangles[outer, (facet + 1) % 3],
                    triangles[outer, (facet + 2) % 3],
                ],
                axis=1,
            ),
            axis=1,
        )
        wrong = np.flatnonzero(~back[rows, facet] | np.any(mine != theirs, axis=1))
        if wrong.size:
            triangle = int(inner[wrong[0]])
            return (
                f"triangle {triangle}'s neighbour {int(outer[wrong[0]])} across facet {corner} "
                "does not share that edge with it"
            )
    return None


def cross_check(directory: Path, documents: Mapping[str, Mapping[str, Any]]) -> None:
    """Refuse (U042) artifacts of ``directory`` that contradict each other: indices out of
    range, a task naming a region the output lacks, a trace or controllers of another
    mission or abstraction.  ``documents`` have passed their schemas."""
    from tlmpc.base.errors import TlmpcError
    from tlmpc.ltl.parser import parse_ltl

    identifier = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
    abstraction = documents.get("abstraction.json")
    regions: set[str] | None = None
    triangles = 0
    if abstraction is not None:
        path = directory / "abstraction.json"
        vertices = abstraction["vertices"]
        triangles = len(abstraction["triangles"])
        letters = abstraction["letters"]
        regions = set(abstraction["regions"])
        checks = [
            (all(isinstance(v, list) and len(v) == 2 for v in vertices), "vertices are [x, y]"),
            (
                all(len(t) == 3 for t in abstraction["triangles"])
                and _indices(abstraction["triangles"], len(vertices)),
                "triangles index vertices",
            ),
            (
                len(abstraction["neighbors"]) == triangles
                and all(len(n) == 3 for n in abstraction["neighbors"])
                and _indices(abstraction["neighbors"], triangles, -1),
                "neighbors index triangles",
            ),
            (
                len(abstraction["letter_of"]) == triangles
                and _indices(abstraction["letter_of"], len(letters)),
                "letter_of indexes letters",
            ),
            (
                len(abstraction["components"]) == triangles
                and _indices(abstraction["components"], triangles + 1),
                "components has one entry per triangle",
            ),
            (_indices(abstraction["start"], triangles), "start is a triangle"),
            (
                all(isinstance(n, str) and n in regions for letter in letters for n in letter),
                "letters name declared regions",
            ),
            (all(identifier.fullmatch(n) for n in regions), "region names are identifiers"),
        ]
        for ok, what in checks:
            if not ok:
                raise _tampered(path, f"abstraction.json is inconsistent: not every {what}")
        problem = _mesh_problem(abstraction)
        if problem is not None:
            raise _tampered(path, f"abstraction.json is not one mesh: {problem}")
    automaton = documents.get("automaton.json")
    if automaton is not None:
        state_count = len(automaton["states"])
        sets = automaton["acceptance"]["sets"]
        if not (
            _indices(automaton["initial"], state_count)
            and all(
                _indices([edge["src"], edge["dst"]], state_count) and _indices(edge["marks"], sets)
                for edge in automaton["edges"]
            )
        ):
            raise _tampered(
                directory / "automaton.json",
                "automaton.json is inconsistent: not every initial state and edge names one "
                "of its states (and acceptance sets)",
            )
    mission = documents.get("mission.json")
    if mission is not None:
        path = directory / "mission.json"
        try:
            formula = parse_ltl(mission["formula"])
        except TlmpcError as exc:
            raise _tampered(path, f"mission.json has an unreadable formula: {exc}") from None
        names = set(mission["regions"]) if isinstance(mission["regions"], dict) else set()
        known = names if regions is None else regions
        reactive = mission.get("reactive") or {}
        signals = {*reactive.get("sensors", {}), *reactive.get("actions", [])}
        unknown = sorted(formula.props() - known - signals)
        if unknown:
            raise _tampered(
                path, f"the formula names regions the output does not have: {', '.join(unknown)}"
            )
    witness = documents.get("witness.json")
    if witness is not None:
        # a run of the product: one automaton state and one letter per plan step
        steps = {"prefix": len(witness["prefix"]), "cycle": len(witness["cycle"])}
        for key, count in steps.items():
            states = witness.get(f"{key}_states")
            if states is not None and len(states) != count:
                raise _tampered(
                    directory / "witness.json",
                    f"witness.json: {key}_states has {len(states)} states for {count} steps",
                )
        word = witness.get("word")
        if word is not None and len(word) != sum(steps.values()):
            raise _tampered(
                directory / "witness.json",
                f"witness.json: the word has {len(word)} letters for {sum(steps.values())} steps",
            )
    if witness is not None and abstraction is not None:
        for key in ("prefix", "cycle"):
            if not _indices(witness[key], triangles):
                raise _tampered(
                    directory / "witness.json", f"witness.json: {key} names a missing triangle"
                )
        length = len(witness["prefix"]) + len(witness["cycle"])
        passages = witness.get("passages", [])
        if not all(
            0 <= index < length and 0 <= vertex < len(abstraction["vertices"])
            for index, vertex in passages
        ):
            raise _tampered(
                directory / "witness.json", "witness.json: a passage names a missing step or vertex"
            )
    _cross_check_results(directory, documents, triangles if abstraction is not None else None)


def _cross_check_results(
    directory: Path, documents: Mapping[str, Mapping[str, Any]], triangles: int | None
) -> None:
    """The controllers and the trace against the plan, the mesh and the mission."""
    controllers = documents.get("controllers.json")
    if controllers is not None:
        path = directory / "controllers.json"
        steps = controllers["steps"]
        if not all(s["step"] == k for k, s in enumerate(steps)):
            raise _tampered(path, "controllers.json: the steps are not numbered 0, 1, 2, ...")
        loop = controllers["loop_start"]
        if loop is not None and not 0 <= loop < len(steps):
            raise _tampered(path, "controllers.json: loop_start is not a step")
        # a stay never leaves: it ends the plan, which then has no moving cycle
        if any(s["stay"] for s in steps[:-1]) or (loop is not None and steps[-1]["stay"]):
            raise _tampered(
                path, "controllers.json: a stay that is not the plan's end (no step follows one)"
            )
        if triangles is not None and not all(
            _indices([s["triangle"], s["next_triangle"] or 0], triangles) for s in steps
        ):
            raise _tampered(path, "controllers.json: a step names a missing triangle")
        # the steps are one path: each leaves into the triangle of the next (the last into
        # the loop's first, unless it is a final stay)
        # (a cell step leaves into any triangle of the next step's cell)
        following = [*steps[1:], None]
        if loop is not None:
            following[-1] = steps[loop]
        if any(
            s["next_triangle"] is not None
            and (
                after is None
                or (
                    s["next_triangle"] not in after["cell"]["triangles"]
                    if "cell" in after
                    else s["next_triangle"] != after["triangle"]
                )
            )
            for s, after in zip(steps, following, strict=True)
        ) or (loop is None and not steps[-1]["stay"]):
            raise _tampered(path, "controllers.json: the steps do not follow one another")
        witness = documents.get("witness.json")
        on_cells = any("cell" in s for s in steps)  # cell steps group the witness's triangles
        if (
            witness is not None
            and not on_cells
            and len(steps) != len(witness["prefix"]) + len(witness["cycle"])
        ):
            raise _tampered(
                path, "controllers.json and witness.json have different numbers of steps"
            )
    trace = documents.get("trace.json")
    if trace is not None:
        path = directory / "trace.json"
        points = trace["points"]
        if not all(isinstance(p, list) and len(p) == 3 for p in points):
            raise _tampered(path, "trace.json: not every point is [t, x, y]")
        loop = trace["loop_start"]
        if loop is not None and not (isinstance(loop, int) and 0 <= loop < len(points)):
            raise _tampered(path, "trace.json: loop_start is not the index of a point")
        mission = documents.get("mission.json")
        if (
            mission is not None
            and isinstance(mission.get("regions"), dict)
            and isinstance(trace.get("regions"), dict)
            and set(trace["regions"]) != set(mission["regions"])
        ):
            raise _tampered(
                path, "trace.json and mission.json name different regions (two missions mixed)"
            )
