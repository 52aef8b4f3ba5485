"""Build hook: an installation built from source brings its numerical kernels compiled.

``pip install .`` builds a wheel; after the modules are copied into the build tree, this hook runs ``python -m
covcontact compile`` there (the warm-up problems, in one worker process per core), so numba's cache files
(``__pycache__/*.nbi``, ``*.nbc``, beside the modules) travel in the wheel and the installation's first run loads
them instead of compiling (docs/performance.md, "Cold start"). numba (0.68 and later) keys a cached kernel to its
module's contents, its own version and the CPU: a wheel installed on the machine that built it starts warm; anywhere
else the kernels are compiled at the first run, as without this hook.

Set COVCONTACT_COMPILE_AT_INSTALL=0 to build without compiling (a wheel for other machines, a quick reinstall).
Editable installs (``pip install -e``) never compile here: their kernels are cached beside the sources at the first
run. A compile that fails leaves the build as it is, with a line on stderr.
"""

from __future__ import annotations

import os
import subprocess
import sys

from setuptools import setup
from setuptools.command.build_py import build_py


class BuildWithKernels(build_py):
    def run(self):
        super().run()
        if getattr(self, "editable_mode", False) or os.environ.get("COVCONTACT_COMPILE_AT_INSTALL", "1") == "0":
            return
        env = dict(os.environ)
        env.pop("NUMBA_CACHE_DIR", None)  # the cache must land beside the modules, where the wheel takes it
        env.pop("COVCONTACT_KEEP_KERNEL_CACHE", None)
        env["PYTHONPATH"] = os.pathsep.join(p for p in (os.path.abspath(self.build_lib), env.get("PYTHONPATH")) if p)
        print("covcontact: compiling the numerical kernels into the wheel (minutes; "
              "COVCONTACT_COMPILE_AT_INSTALL=0 skips it)", file=sys.stderr, flush=True)
        done = subprocess.run([sys.executable, "-m", "covcontact", "compile"], env=env, cwd=self.build_lib)
        if done.returncode != 0:
            print(f"covcontact: the kernels were not compiled at install (exit {done.returncode}); the first run "
                  "compiles them", file=sys.stderr, flush=True)


setup(cmdclass={"build_py": BuildWithKernels})
