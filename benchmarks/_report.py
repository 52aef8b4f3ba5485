"""Shared output of the benchmark scripts: the JSON record to a file (or stdout), the table to stderr."""

from __future__ import annotations

import json
import sys
from pathlib import Path


def emit(result: dict, out: Path | str | None, table: str) -> None:
    """Write ``result`` as JSON to ``out`` (stdout when None) and print ``table`` on stderr."""
    text = json.dumps(result, indent=1)
    if out:
        Path(out).write_text(text + "\n")
    else:
        print(text)
    print(table, file=sys.stderr)
