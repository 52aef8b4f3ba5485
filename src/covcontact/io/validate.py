"""Validation helpers for problem files: every key is consumed once, leftovers are errors."""

from __future__ import annotations

import difflib
import math
from pathlib import Path
from typing import Any

from ..words import suggest  # noqa: F401  (the input layer's messages name it from here)


class InputError(ValueError):
    """Bad input. ``str(err)`` is the one-line message printed by the CLI (exit code 2)."""


_REQUIRED = object()


def _type_name(value: Any) -> str:
    return {bool: "a boolean", int: "an integer", float: "a number", str: "a string", list: "an array",
            dict: "a table"}.get(type(value), type(value).__name__)


class Section:
    """A TOML table being read: ``get`` takes keys out, ``done`` rejects what is left."""

    def __init__(self, data: Any, path: str, file: Path | str):
        self.file = str(file)
        self.path = path
        if not isinstance(data, dict):
            self.fail(f"must be a table, got {_type_name(data)}")
        self.data = dict(data)
        self.known: set[str] = set()

    def fail(self, msg: str, key: str | None = None):
        where = self.key_path(key) if key else self.path
        raise InputError(f"{self.file}: {where}: {msg}" if where else f"{self.file}: {msg}")

    def key_path(self, key: str) -> str:
        return f"{self.path}.{key}" if self.path else key

    def has(self, key: str) -> bool:
        self.known.add(key)
        return key in self.data

    def get(self, key: str, kind: str, default: Any = _REQUIRED, *, positive: bool = False,
            nonnegative: bool = False, choices: tuple | None = None, length: int | None = None) -> Any:
        """Take ``key``; kind is one of str, float, int, bool, vector, floats, table, array, any."""
        self.known.add(key)
        if key not in self.data:
            if default is _REQUIRED:
                spelt = difflib.get_close_matches(key, [k for k in self.data if k not in self.known], n=1,
                                                  cutoff=0.6)
                hint = f" (found {spelt[0]!r}: a misspelling of {key!r}?)" if spelt else ""
                self.fail(f"missing required key{hint}", key)
            return default
        value = self.data.pop(key)
        value = self._convert(key, value, kind, length)
        if choices is not None and value not in choices:
            self.fail(f"{value!r} is not one of {', '.join(map(str, choices))}"
                      f"{suggest(value, choices) if isinstance(value, str) else ''}", key)
        if positive and not value > 0:
            self.fail(f"must be > 0, got {value}", key)
        if nonnegative and not value >= 0:
            self.fail(f"must be >= 0, got {value}", key)
        return value

    def _convert(self, key: str, value: Any, kind: str, length: int | None) -> Any:
        if kind == "any":
            return value
        if kind == "str":
            if not isinstance(value, str):
                self.fail(f"must be a string, got {_type_name(value)}", key)
            return value
        if kind == "bool":
            if not isinstance(value, bool):
                self.fail(f"must be true or false, got {_type_name(value)}", key)
            return value
        if kind == "int":
            if isinstance(value, bool) or not isinstance(value, int):
                self.fail(f"must be an integer, got {_type_name(value)}", key)
            return value
        if kind == "float":
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                self.fail(f"must be a number, got {_type_name(value)}", key)
            if not math.isfinite(value):
                self.fail("must be finite", key)
            return float(value)
        if kind in ("vector", "floats"):
            if not isinstance(value, list) or not all(
                    isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
                self.fail(f"must be an array of numbers, got {_type_name(value)}", key)
            n = 3 if kind == "vector" else length
            if n is not None and len(value) != n:
                self.fail(f"must have {n} entries, got {len(value)}", key)
            if not all(math.isfinite(v) for v in value):
                self.fail("entries must be finite", key)
            return tuple(float(v) for v in value)
        if kind == "table":
            return Section(value, self.key_path(key), self.file)
        if kind == "array":
            if not isinstance(value, list):
                self.fail(f"must be an array of tables, got {_type_name(value)}", key)
            return [Section(v, f"{self.key_path(key)}[{i}]", self.file) for i, v in enumerate(value)]
        raise AssertionError(kind)

    def rest(self) -> dict:
        """Take every remaining key (for keyword arguments checked elsewhere)."""
        out, self.data = self.data, {}
        return out

    def done(self, known=()) -> None:
        """Reject the keys nobody took; the message proposes the closest key this table knows."""
        if self.data:
            key = min(self.data)
            allowed = (self.known | set(known)) - set(self.data)
            self.fail("unknown key" + suggest(key, sorted(allowed)), key)
