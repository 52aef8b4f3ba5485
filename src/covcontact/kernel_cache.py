"""Stale numba caches never run: a stamp of the kernel sources that clears the package's cached kernels when any of
them changed.

numba keeps a compiled kernel (``@njit(cache=True)``) in its cache and loads it again as long as the kernel's own
source file is unchanged. A kernel that calls or inlines functions of other modules (the element loops call the
material routines, which call the rubber models) keeps its old machine code when only those modules change: an
edited material law would run as the old one, silently. At import, :func:`check` hashes the contents of every module
of the package that defines numba kernels and compares the digest with the stamp beside the cache; where they
differ, it deletes the package's cached kernels (``*.nbi``, ``*.nbc``) and writes the new stamp, so the next run
compiles them from the current sources. Costs a read of those modules (about 1 MB, milliseconds) per start.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent
STAMP = "kernel-sources.stamp"


def kernel_sources() -> list[Path]:
    """The package's modules that define numba kernels (``njit``; sorted). Modules that only use numba (its thread
    count, its compile events) or name it leave the cache alone when they change."""
    out = []
    for path in sorted(PACKAGE.rglob("*.py")):
        if path.name == "kernel_cache.py":
            continue
        try:
            text = path.read_bytes()
        except OSError:
            continue
        if b"njit" in text:
            out.append(path)
    return out


def digest(paths: list[Path]) -> str:
    h = hashlib.sha256()
    for path in paths:
        h.update(str(path.relative_to(PACKAGE)).encode())
        h.update(b"\0")
        h.update(path.read_bytes())
    return h.hexdigest()


def cache_dirs() -> list[Path]:
    """Where numba keeps this package's cached kernels: the ``__pycache__`` folders beside the sources, or under
    NUMBA_CACHE_DIR the folders whose path names the package."""
    root = os.environ.get("NUMBA_CACHE_DIR")
    if not root:
        return sorted(PACKAGE.rglob("__pycache__"))
    base = Path(root)
    return sorted(p for p in base.rglob("*") if p.is_dir() and "covcontact" in p.name) if base.is_dir() else []


def check() -> bool:
    """Clear the package's cached kernels where the kernel sources changed since the stamp; True where it
    cleared. Never fails a run: a folder that cannot be written is left as it is (numba then compiles into its own
    fallback cache)."""
    try:
        stamp_dir = Path(os.environ.get("NUMBA_CACHE_DIR") or PACKAGE / "__pycache__")
        stamp = stamp_dir / STAMP
        now = digest(kernel_sources())
        if stamp.is_file() and stamp.read_text().strip() == now:
            return False
        for folder in cache_dirs():
            for pattern in ("*.nbi", "*.nbc"):
                for f in folder.glob(pattern):
                    f.unlink(missing_ok=True)
        stamp_dir.mkdir(parents=True, exist_ok=True)
        tmp = stamp.with_name(f"{STAMP}.{os.getpid()}")
        tmp.write_text(now + "\n")
        tmp.replace(stamp)
        return True
    except OSError:
        return False
