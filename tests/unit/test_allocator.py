"""The allocator setting of PETSc runs (covcontact.allocator): freed memory is reused, not cleared anew."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's mallopt")

PROBE = """
import resource, sys
import numpy as np
from covcontact.allocator import keep_freed_memory

kept = keep_freed_memory()
faults = []
for _ in range(3):  # 256 MiB written, freed, written again: fresh pages fault, reused ones do not
    f0 = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    a = np.ones(2**25)
    del a
    faults.append(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - f0)
print(kept, *faults)
"""


def _probe(**env) -> tuple[str, list[int]]:
    out = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True, check=True,
                         env={**os.environ, **env}).stdout.split()
    return out[0], [int(v) for v in out[1:]]


def test_freed_memory_is_reused():
    kept, faults = _probe(COVCONTACT_MALLOC="")
    assert kept == "True"
    assert faults[0] > 0
    assert max(faults[1:]) * 4 < faults[0], faults  # the second and third array reuse the first one's pages


def test_system_allocator_on_request():
    kept, _ = _probe(COVCONTACT_MALLOC="system")
    assert kept == "False"
