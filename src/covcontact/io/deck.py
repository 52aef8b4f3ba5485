"""Abaqus and CalculiX input decks, read as cards (docs/input.md, "Abaqus and CalculiX decks").

A deck is a sequence of keyword lines (``*NAME, PARAM=VALUE, FLAG``) each followed by its data lines; ``**`` starts
a comment line, ``*INCLUDE, INPUT=file`` reads another file in place (relative to the including file) anywhere, also
inside a keyword's data: the data lines of an included file that come before its first keyword continue the card
in force, and so do the data lines after the *INCLUDE (as CalculiX reads it: the include is transparent). Keywords,
parameter names and set names are case-insensitive: they are kept upper-case. A keyword line that ends with a comma
continues on the next line only when that line starts with a parameter (``NAME=...``) or holds parameter flags
only (``GENERATE``): Abaqus continues keyword lines so, CalculiX never does (its ``*NODE FILE,`` followed by ``U``
is a keyword and a data line). Data lines are
kept as text with their file and line number, so that the model layer (:mod:`covcontact.io.deck_model`) parses
large blocks (nodes, elements) in one vectorised pass and still names the file and line of a malformed entry.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .validate import InputError


class DeckError(InputError):
    """A deck that cannot be read: the message names the file and line, what is wrong and the likely fix."""


@dataclass
class Card:
    """One keyword with its data lines.

    Attributes:
        name: the keyword, upper-case, single spaces ("SOLID SECTION").
        params: parameter name -> value (upper-case names; a flag without ``=`` maps to "").
        data: the data lines (stripped text).
        lines: the line number of each data line.
        file, line: where the keyword line is.
        sources: (first data index, file) of each run of data lines read from one file, when the data continue
            across an *INCLUDE (empty: all in ``file``).
        text: the keyword line as written.
    """

    name: str
    params: dict[str, str]
    file: Path
    line: int
    text: str
    data: list[str] = field(default_factory=list)
    lines: list[int] = field(default_factory=list)
    sources: list[tuple[int, Path]] = field(default_factory=list)

    def where(self, k: int | None = None) -> str:
        """"file:line" of the keyword line, or of data line ``k``."""
        if k is None:
            return f"{self.file}:{self.line}"
        return f"{self.file_of(k)}:{int(self.lines[k])}"

    def file_of(self, k: int) -> Path:
        """The file data line ``k`` was read from."""
        f = self.file
        for start, src in self.sources:
            if start > k:
                break
            f = src
        return f

    def fail(self, problem: str, k: int | None = None) -> DeckError:
        return DeckError(f"{self.where(k)}: *{self.name}: {problem}")

    def param(self, name: str, default: str | None = None, required: bool = False) -> str | None:
        """The value of parameter ``name`` (upper-case); a DeckError when required and missing."""
        if name in self.params:
            return self.params[name]
        if required:
            raise self.fail(f"missing parameter {name}= (e.g. *{self.name}, {name}=...)")
        return default

    def rows(self) -> list[list[str]]:
        """The data lines split at commas, fields stripped, trailing empty fields dropped."""
        out = []
        for text in self.data:
            fields = [f.strip() for f in text.split(",")]
            while fields and fields[-1] == "":
                fields.pop()
            out.append(fields)
        return out

    def number(self, k: int, j: int, fields: list[str], what: str, default: float | None = None) -> float:
        """Field ``j`` of data line ``k`` as a number (``default`` when empty or missing)."""
        if j >= len(fields) or fields[j] == "":
            if default is not None:
                return default
            raise self.fail(f"{what} is missing (field {j + 1})", k)
        try:
            return float(fields[j].replace("d", "e").replace("D", "E"))
        except ValueError:
            raise self.fail(f"{what} must be a number, got {fields[j]!r} (field {j + 1})", k) from None


#: keyword and parameter names of several words, by their letters alone: CalculiX drops every blank of a keyword
#: line, so *NODEPRINT is *NODE PRINT and TIMEPOINTS= is TIME POINTS= there; they are read so here too
_SPACED = {n.replace(" ", ""): n for n in (
    "NODE PRINT", "EL PRINT", "NODE FILE", "EL FILE", "CONTACT PRINT", "CONTACT FILE", "NODE OUTPUT",
    "ELEMENT OUTPUT", "CONTACT OUTPUT", "SECTION PRINT", "SOLID SECTION", "SURFACE INTERACTION", "SURFACE BEHAVIOR",
    "CONTACT PAIR", "END STEP", "CHANGE FRICTION", "RIGID BODY", "TIME POINTS", "REF NODE", "ROT NODE",
    "POSITION TOLERANCE", "SMALL SLIDING", "REMOVE ALL", "TIME DELAY", "CONSTRAINT NAME", "CONTACT ELEMENTS",
    "LAST ITERATIONS", "SECTION FORCES", "TIME INCREMENTATION", "STEP TIME", "TOTAL TIME", "NODE TO SURFACE",
    "SURFACE TO SURFACE", "SHELL SECTION", "BEAM SECTION", "INITIAL CONDITIONS", "END PART", "END ASSEMBLY",
    "END INSTANCE")}


def _canonical(word: str) -> str:
    """A keyword or parameter name upper-case with single blanks, the blanks CalculiX ignores restored."""
    w = " ".join(word.upper().split())
    return _SPACED.get(w.replace(" ", ""), w)


def _params(text: str, file: Path, line: int) -> tuple[str, dict[str, str]]:
    parts = [p.strip() for p in text[1:].split(",")]
    name = _canonical(parts[0])
    params: dict[str, str] = {}
    for p in parts[1:]:
        if not p:
            continue
        if "=" in p:
            k, v = p.split("=", 1)
            params[_canonical(k)] = v.strip()
        else:
            params[_canonical(p)] = ""
    if not name:
        raise DeckError(f"{file}:{line}: a keyword line without a keyword (a lone '*')")
    return name, params


def read_deck(path: str | Path) -> list[Card]:
    """The cards of the deck at ``path``, with ``*INCLUDE`` files read in place."""
    cards: list[Card] = []
    _read(Path(path), cards, [])
    return cards


def _read(path: Path, cards: list[Card], stack: list[Path], card: Card | None = None) -> Card | None:
    """Read ``path`` into ``cards``; its data lines before its first keyword continue ``card`` (the card in force
    where it is included). Returns the card in force at its end."""
    if not path.is_file():
        where = f"{stack[-1]}: " if stack else ""
        raise DeckError(f"{where}{path}: no such deck file")
    if path.resolve() in stack:
        raise DeckError(f"{path}: *INCLUDE of a file that includes it (a cycle)")
    stack.append(path.resolve())
    try:
        text = path.read_text(errors="replace")
    except OSError as exc:
        raise DeckError(f"{path}: cannot read ({exc})") from None
    raw = text.splitlines()
    # keyword and comment lines (a '*' first, after blanks); the data lines between them are taken in bulk
    marks = [i for i, ln in enumerate(raw) if ln[:1] == "*" or (ln[:1] in (" ", "\t") and ln.lstrip()[:1] == "*")]
    marks.append(len(raw))
    _data(card, raw, 0, marks[0], path)
    k = 0
    while k < len(marks) - 1:
        i = marks[k]
        line = raw[i].strip()
        end = marks[k + 1]
        k += 1
        if line.startswith("**"):
            _data(card, raw, i + 1, end, path)
            continue
        first = i + 1
        j = i + 1
        while line.endswith(",") and j < end and _continues(raw[j]):
            line += raw[j].strip()  # a keyword line continued (Abaqus): the next line starts with a parameter
            j += 1
        name, params = _params(line, path, first)
        if name == "INCLUDE":
            target = params.get("INPUT")
            if not target:
                raise DeckError(f"{path}:{first}: *INCLUDE needs INPUT=file")
            target = target.strip('"').strip("'")
            where = f"{path}:{first}: *INCLUDE, INPUT={target}"
            full = (path.parent / target) if not Path(target).is_absolute() else Path(target)
            if not full.is_file():
                raise DeckError(f"{where}: no such file (looked for {full}; a relative INPUT is relative to the "
                                f"including file)")
            card = _read(full, cards, stack, card)
            _data(card, raw, j, end, path)
            continue
        card = Card(name, params, path, first, line)
        cards.append(card)
        _data(card, raw, j, end, path)
    stack.pop()
    return card


#: parameters without a value that an Abaqus keyword line may carry on its continuation line
_FLAGS = {"GENERATE", "NLGEOM", "UNSYMM", "DIRECT", "SMALL SLIDING", "PERTURBATION", "FIXED", "UNSORTED",
          "INTERNAL", "REMOVE ALL", "REMOVE", "ADJUST"}


def _continues(text: str) -> bool:
    """Whether a line after a keyword line that ends with a comma continues it: it starts with a parameter
    (``NAME=VALUE``) or holds only parameter flags (GENERATE, NLGEOM, ...), as Abaqus' continuation lines do; a data
    line (numbers, set names, output variables such as U) does not."""
    fields = [f.strip() for f in text.split(",") if f.strip()]
    if not fields:
        return False
    head = fields[0]
    if "=" in head and head[:1].isalpha():
        return True
    return all(" ".join(f.upper().split()) in _FLAGS for f in fields)


def _data(card: Card | None, raw: list[str], a: int, b: int, path: Path) -> None:
    """Lines a .. b - 1 of ``raw`` (0-based) as data lines of ``card`` (blank lines skipped)."""
    if b <= a:
        return
    chunk = [ln.strip() for ln in raw[a:b]]
    if all(chunk):
        numbers_ = range(a + 1, b + 1)
    else:
        numbers_ = [a + 1 + t for t, ln in enumerate(chunk) if ln]
        chunk = [ln for ln in chunk if ln]
        if not chunk:
            return
    if card is None:
        raise DeckError(f"{path}:{numbers_[0]}: a data line before any keyword (a missing *NODE or *ELEMENT line?)")
    if path != (card.sources[-1][1] if card.sources else card.file):
        card.sources.append((len(card.data), path))
    card.data += chunk
    card.lines += numbers_


def numbers(card: Card, width: int | None = None, what: str = "entries", integer: bool = False) -> np.ndarray:
    """All data lines of ``card`` as one float array of rows of ``width`` numbers (lines ending with a comma
    continue on the next one, as element lines of 20-node bricks do); a malformed line is named. ``integer``: try
    whole numbers first (int64, else float)."""
    if width is not None and card.data and not any(ln.endswith(",") for ln in card.data):
        try:  # one entry per line: numpy's text reader
            values = np.loadtxt(card.data, delimiter=",", ndmin=2, dtype=np.int64 if integer else float)
            if values.shape[1] == width:
                return values
        except ValueError:
            pass  # (not all numbers, or lines of different lengths: found below)
    text = ",".join(card.data)
    flat = text.replace(" ", "").replace("\t", "").split(",")
    flat = [f for f in flat if f != ""]
    try:
        values = np.array(flat, dtype=float)
    except ValueError:
        for k, line in enumerate(card.data):
            for f in line.split(","):
                f = f.strip()
                if f:
                    try:
                        float(f)
                    except ValueError:
                        raise card.fail(f"{what}: {f!r} is not a number", k) from None
        raise card.fail(f"{what}: not numbers") from None
    if width is None:
        return values
    if values.size % width:
        _count_fail(card, width, what)
    return values.reshape(-1, width)


def _count_fail(card: Card, width: int, what: str) -> None:
    """The first data line (or joined continuation) whose field count breaks rows of ``width``."""
    count = 0
    for k, line in enumerate(card.data):
        fields = [f for f in line.split(",") if f.strip()]
        count += len(fields)
        if not line.rstrip().endswith(",") and count % width:
            raise card.fail(f"{what}: {count % width} fields where {width} are needed per entry (a missing node, "
                            f"or a continuation line without the trailing comma?)", k)
    raise card.fail(f"{what}: the fields do not make whole entries of {width}")
