"""The C allocator of a solving process: freed memory is kept for the next allocation, not returned.

glibc's malloc serves every request above its mmap threshold (at most 32 MiB) with fresh pages from the
kernel and gives them back on free. A Newton iteration of a 2e5-dof run allocates and frees well over a
GiB that way: the tangent's values (128 MiB), PETSc's copy and its GAMG hierarchy, the sparse products
of the analysis. Every fresh page is zeroed by the kernel on its first touch, so the same memory is
cleared again at every iteration; on the 2e5-dof two-block race that was a tenth of the wall time
(docs/performance.md, "Memory the kernel clears").

:func:`keep_freed_memory` turns that off for the process: no mmap for single allocations (they come from
the heap, and what is freed is reused) and no trimming of the heap's top below 2 GiB. The resident size
then stays near its peak, and the peak can rise: on the 1e6-dof shell with PARDISO it rose 13 % for a 2 %
gain, and runs of up to 3.5e4 dofs with PARDISO did not change. So a run calls it when it solves with
PETSc (the distributed model: each GAMG set-up and each new tangent allocates anew), and
``COVCONTACT_MALLOC=system`` keeps glibc's defaults there too.
"""

from __future__ import annotations

import ctypes
import os
import sys

__all__ = ["keep_freed_memory"]

#: glibc's mallopt parameters (malloc.h)
M_TRIM_THRESHOLD = -1
M_MMAP_MAX = -4
#: the largest trim threshold mallopt takes (an int)
TRIM_THRESHOLD = 2**31 - 1


def keep_freed_memory() -> bool:
    """Keep freed memory in the process (glibc only; a no-op elsewhere or with ``COVCONTACT_MALLOC=system``).
    Returns whether the allocator took the settings."""
    if os.environ.get("COVCONTACT_MALLOC", "").strip().lower() == "system" or not sys.platform.startswith("linux"):
        return False
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes = (ctypes.c_int, ctypes.c_int)
    mallopt.restype = ctypes.c_int
    return mallopt(M_MMAP_MAX, 0) == 1 and mallopt(M_TRIM_THRESHOLD, TRIM_THRESHOLD) == 1
