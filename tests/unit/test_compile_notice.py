"""The first run of an installation says on stderr that it compiles; a run from the cache says nothing."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from covcontact.compile_notice import MESSAGE

SCRIPT = """
import numba
from covcontact.compile_notice import install
install()
@numba.njit(cache=True)
def twice(x):
    return 2 * x
print(twice(21))
"""


def test_notice_only_when_compiling(tmp_path):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    script = tmp_path / "kernel.py"
    script.write_text(SCRIPT)
    first = subprocess.run([sys.executable, str(script)], env=env, capture_output=True, text=True, check=True)
    assert first.stdout.strip() == "42"
    assert first.stderr.count(MESSAGE) == 1  # once, however many kernels compile
    second = subprocess.run([sys.executable, str(script)], env=env, capture_output=True, text=True, check=True)
    assert MESSAGE not in second.stderr  # loaded from the cache: silent
    assert Path(tmp_path / "cache").exists()


def test_notice_only_on_rank_0(tmp_path):
    # under mpiexec (the launcher's environment) only rank 0 says it; the others compile silently
    script = tmp_path / "kernel.py"
    script.write_text(SCRIPT)
    for rank, expected in ((0, 1), (1, 0)):
        env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / f"cache{rank}"), OMPI_COMM_WORLD_SIZE="2",
                   OMPI_COMM_WORLD_RANK=str(rank))
        run = subprocess.run([sys.executable, str(script)], env=env, capture_output=True, text=True, check=True)
        assert run.stdout.strip() == "42" and run.stderr.count(MESSAGE) == expected
