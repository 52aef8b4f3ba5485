"""covcontact: covariant node-to-surface contact for large-deformation finite elements."""

import os as _os

from .parallel.launcher import under_launcher as _under_launcher

__version__ = "0.1.0"

# under mpiexec numba's error highlighting writes a colour reset (ESC[0m) to the standard output at every
# compilation; covcontact's output is plain text
if _under_launcher():
    _os.environ.setdefault("NUMBA_DISABLE_ERROR_MESSAGE_HIGHLIGHTING", "1")

# kernels compiled from older sources are not loaded (kernel_cache.py)
if _os.environ.get("COVCONTACT_KEEP_KERNEL_CACHE") != "1":
    from . import kernel_cache as _kernel_cache

    _kernel_cache.check()
