"""Test configuration: hypothesis runs derandomized, so every CI run draws the same examples; a cold numba cache is
filled before the tests start, by ``covcontact compile``'s warm-up problems in one worker process per core (the test
workers would otherwise each compile the same kernels, one thread each, while their tests wait)."""

import os
import sys

import pytest
from hypothesis import settings

settings.register_profile("covcontact", derandomize=True, deadline=None, print_blob=True)
settings.load_profile("covcontact")


@pytest.hookimpl(tryfirst=True)
def pytest_sessionstart(session):
    if hasattr(session.config, "workerinput"):  # a pytest-xdist worker: the controller did it
        return
    from covcontact import warmup

    if not warmup.cache_is_cold():
        return
    jobs = os.cpu_count() or 1
    print(f"\ncovcontact: numba's cache is cold: compiling the kernels in {jobs} processes first", file=sys.stderr,
          flush=True)
    try:
        warmup.warm_parallel(jobs, quiet=True)
    except Exception as exc:  # (a warm-up problem that fails is test_cli's to report; the tests compile what they need)
        print(f"covcontact: the compile before the tests failed ({exc}); the tests go on", file=sys.stderr, flush=True)
