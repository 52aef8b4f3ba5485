"""Words for messages: the closest known name to a misspelt one (used by every layer's one-line errors)."""

from __future__ import annotations

import difflib


def suggest(word: str, candidates, fallback: str = "") -> str:
    """``"; did you mean 'x'?"`` for the closest of ``candidates`` to ``word`` (difflib), else ``fallback``."""
    names = [str(c) for c in candidates]
    close = difflib.get_close_matches(str(word), names, n=1, cutoff=0.6)
    if not close:
        lower = {n.lower(): n for n in names}
        close = [lower[str(word).lower()]] if str(word).lower() in lower else []
    return f"; did you mean {close[0]!r}?" if close else fallback
