"""``covcontact compile``: compile every numerical kernel once, into numba's cache, before the first real run.

numba compiles a kernel the first time it is called and keeps the machine code in its cache (the
``__pycache__`` folders of the installed package, or ``NUMBA_CACHE_DIR``). A new installation's first run
therefore pays the compilation of every kernel it meets (docs/performance.md, "Cold start"). This module
runs a handful of tiny problems that together call every compiled kernel with the argument types real runs
use: each element family (hex8, hex27, F-bar hex8, hex8 with incompatible modes, solid-shells hex8 and hex18,
elastic and plastic), each material, each kind of master surface (deformable facets quad4 and quad9, rigid
meshes, analytic plane, cylinder and sphere), friction, the output fields. Run once after installing; later runs
load the cache.
"""

from __future__ import annotations

import sys
import tempfile
import time
import tomllib
from pathlib import Path

_STEPS = "\n[steps]\ncount = 2\n\n[output]\nevery = 1\n"

_HEAD = '[problem]\nname = "{name}"\n\n'

#: two hex8 bodies pressed and dragged: a punch on a base, a frictional pair with the exact tangent
_TWO_HEX8 = """
[[bodies]]
name = "base"
element = "hex8"
material = { model = "svk", E = 1000.0, nu = 0.3 }
mesh = { generator = "block", lx = 2.0, ly = 2.0, lz = 0.5, nx = 2, ny = 2, nz = 1, origin = [-1.0, -1.0, -0.5] }
[[bodies]]
name = "punch"
element = "hex8"
material = { model = "svk", E = 1000.0, nu = 0.3 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 0.5, nx = 3, ny = 3, nz = 1, origin = [-0.5, -0.5, 0.0] }
[[contact]]
slave = "punch.zmin"
master = "base.zmax"
penalty = 1.0e6
weighting = "area"
friction = 0.2
tangent = "exact"
[[dirichlet]]
set = "base.zmin"
components = "xyz"
[[dirichlet]]
set = "punch.zmax"
components = "xyz"
value = [0.01, 0.0, -0.02]
"""

#: (label, problem text): tiny problems, two load steps each, VTU output on.
PROBLEMS: tuple[tuple[str, str], ...] = (
    ("hex8 on a plane with friction", """
[[bodies]]
name = "block"
element = "hex8"
material = { model = "svk", E = 1000.0, nu = 0.3 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 0.5, nx = 2, ny = 2, nz = 1 }
[[rigid]]
name = "floor"
shape = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[[contact]]
slave = "block.zmin"
master = "floor"
penalty = 1.0e6
weighting = "area"
friction = 0.3
[[dirichlet]]
set = "block.zmax"
components = "xyz"
value = [0.05, 0.0, -0.01]
"""),
    ("hex27 Neo-Hooke on a sphere, exact tangent", """
[[bodies]]
name = "block"
element = "hex27"
material = { model = "neo-hooke", E = 1000.0, nu = 0.3 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 0.5, nx = 2, ny = 2, nz = 1, origin = [-0.5, -0.5, 0.0] }
[[rigid]]
name = "ball"
shape = "sphere"
center = [0.0, 0.0, -1.0]
radius = 1.0
[[contact]]
slave = "block.zmin"
master = "ball"
penalty = 1.0e5
tangent = "exact"
[[dirichlet]]
set = "block.zmax"
components = "xyz"
value = [0.0, 0.0, -0.01]
"""),
    ("hex8 on a cylinder with friction", """
[[bodies]]
name = "block"
element = "hex8"
material = { model = "svk", E = 1000.0, nu = 0.3 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 0.5, nx = 2, ny = 2, nz = 1, origin = [-0.5, -0.5, 0.0] }
[[rigid]]
name = "drum"
shape = "cylinder"
center = [0.0, 0.0, -1.0]
axis = [0.0, 1.0, 0.0]
radius = 1.0
[[contact]]
slave = "block.zmin"
master = "drum"
penalty = 1.0e5
friction = 0.2
[[dirichlet]]
set = "block.zmax"
components = "xyz"
value = [0.02, 0.0, -0.01]
"""),
    ("two hex8 bodies, quad4 facets, friction", _TWO_HEX8),
    ("rigid meshed ball into a hex27 plate, quad9 facets", """
[[bodies]]
name = "plate"
element = "hex27"
material = { model = "svk", E = 1.0e4, nu = 0.3 }
mesh = { generator = "plate", lx = 2.0, ly = 2.0, t = 0.1, nx = 3, ny = 3, origin = [-1.04, -0.97, -0.11] }
[[rigid]]
name = "ball"
shape = "mesh"
element = "hex8"
mesh = { generator = "hemisphere_solid", radius = 0.5, n = 2 }
motion = { translation = [0.0, 0.0, -0.05] }
[[contact]]
slave = "ball.curved"
master = "plate.top"
penalty = 1.0e3
[[dirichlet]]
set = "plate.xmin"
components = "xyz"
[[dirichlet]]
set = "plate.xmax"
components = "xyz"
"""),
    ("hex18 solid-shell on a rigid meshed sphere (quad9 master)", """
[[bodies]]
name = "plate"
element = "hex18"
formulation = "solid-shell"
material = { model = "svk", E = 2.1e5, nu = 0.3 }
mesh = { generator = "plate", lx = 9.0, ly = 4.0, t = 1.0, nx = 3, ny = 2 }
[[rigid]]
name = "sphere"
shape = "mesh"
element = "hex8"
mesh = { generator = "sphere_patch", radius = 2.95, t = 0.1, theta0 = 0.0, theta1 = 1.2, phi0 = 0.0, phi1 = 6.283185307179586, n_theta = 2, n_phi = 8, center = [3.03, 2.03, -3.001] }
[[contact]]
slave = "sphere.outer"
master = "plate.bottom"
penalty = 1.0e4
weighting = "area"
[[dirichlet]]
set = "plate.xmin"
components = "xyz"
[[force]]
set = "plate.xmax"
value = [0.0, 0.0, -1.0]
distribution = "total"
"""),
    ("hex8 solid-shell, J2 with Swift hardening, on a rigid meshed cylinder", """
[[bodies]]
name = "strip"
element = "hex8"
formulation = "solid-shell"
options = { thickness_points = 3 }
material = { model = "j2", E = 2.1e5, nu = 0.3, hardening = { law = "swift", K = 500.0, eps0 = 0.01, n = 0.2 } }
mesh = { generator = "plate", lx = 9.0, ly = 4.0, t = 1.0, nx = 3, ny = 2 }
[[rigid]]
name = "drum"
shape = "mesh"
element = "hex27"
mesh = { generator = "cylinder_patch", radius = 2.95, length = 4.0, angle0 = -0.5708, angle1 = 0.5708, t = 0.1, n_circ = 2, n_len = 2, axis = "y", center = [4.5, 0.0, -3.001] }
[[contact]]
slave = "drum.outer"
master = "strip.bottom"
penalty = 1.0e4
[[dirichlet]]
set = "strip.xmin"
components = "xyz"
[[dirichlet]]
set = "strip.xmax"
components = "z"
value = -0.5
"""),
    ("F-bar hex8 and hex8, J2 with Voce and kinematic hardening, Hill48", """
[[bodies]]
name = "block"
element = "hex8"
formulation = "fbar"
material = { model = "j2", E = 1000.0, nu = 0.3, yield_stress = 1.0, kinematic_modulus = 10.0, hardening = { law = "voce", sigma_inf = 1.5, delta = 10.0, modulus = 1.0 }, hill48 = { r0 = 1.5, r45 = 1.2, r90 = 1.8 } }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 1.0, nx = 1, ny = 1, nz = 2 }
[[bodies]]
name = "cap"
element = "hex8"
material = { model = "j2", E = 1000.0, nu = 0.3, yield_stress = 1.0, hardening = { law = "linear", modulus = 10.0 } }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 0.5, nx = 1, ny = 1, nz = 1, origin = [0.0, 0.0, 1.0] }
[[dirichlet]]
set = "block.zmin"
components = "xyz"
[[dirichlet]]
set = "block.zmax"
components = "z"
value = 0.01
[[dirichlet]]
set = "cap.zmax"
components = "xyz"
value = [0.0, 0.0, -0.01]
"""),
    ("hex8 with incompatible modes (C3D8I), J2", """
[[bodies]]
name = "beam"
element = "hex8"
options = { incompatible_modes = true }
material = { model = "j2", E = 1000.0, nu = 0.3, yield_stress = 2.0, hardening = { law = "linear", modulus = 50.0 } }
mesh = { generator = "block", lx = 4.0, ly = 1.0, lz = 1.0, nx = 2, ny = 1, nz = 1 }
[[dirichlet]]
set = "beam.xmin"
components = "xyz"
[[force]]
set = "beam.xmax"
value = [0.0, 0.0, -1.0]
distribution = "total"
"""),
    ("plane strain quad4 on quad4 with friction, F-bar quad4 on an axisymmetric rigid plane", """
[[bodies]]
name = "low"
formulation = "plane_strain"
element = "quad4"
mesh = { generator = "rectangle", lx = 2.0, ly = 0.5, nx = 4, ny = 1, origin = [0.0, 0.0] }
material = { model = "neo-hooke", E = 1000.0, nu = 0.3 }
[[bodies]]
name = "up"
formulation = "plane_strain"
element = "quad4"
mesh = { generator = "rectangle", lx = 0.5, ly = 0.25, nx = 2, ny = 1, origin = [0.75, 0.5] }
material = { model = "neo-hooke", E = 1000.0, nu = 0.3 }
[[bodies]]
name = "ring"
formulation = "axisymmetric"
element = "quad4"
options = { fbar = true }
mesh = { generator = "rectangle", lx = 0.5, ly = 0.25, nx = 2, ny = 1, origin = [5.0, 0.0] }
material = { model = "mooney-rivlin", c10 = 0.8, c01 = 0.2, d1 = 0.05 }
[[rigid]]
name = "lid"
shape = "plane"
point = [5.0, 0.25, 0.0]
normal = [0.0, -1.0, 0.0]
motion = { translation = [0.0, -0.01, 0.0] }
[[contact]]
slave = "up.ymin"
master = "low.ymax"
penalty = 1.0e5
weighting = "area"
friction = 0.2
[[contact]]
slave = "ring.ymax"
master = "lid"
penalty = 1.0e4
weighting = "area"
[[dirichlet]]
set = "low.ymin"
components = "xy"
[[dirichlet]]
set = "ring.ymin"
components = "xy"
[[dirichlet]]
set = "up.ymax"
components = "xy"
value = [0.01, -0.01]
"""),
    ("two hex8 bodies, segment-to-surface", _TWO_HEX8.replace('weighting = "area"\nfriction = 0.2\ntangent = "exact"',
                                                                'type = "sts"')),
)

#: groups of warm-up problems that share their costly kernels (indices into PROBLEMS) with the seconds each group
#: took to compile from a cold cache in a worker of `covcontact compile --jobs 2` (2 cores, 2026-12-07): a parallel
#: compile gives each worker whole groups, the costliest first, so that no two workers compile the same element
#: family (with these: the facets, solid-shells and planar problems in one worker, the solid, F-bar and incompatible
#: hexahedra in the other, 210 s each)
GROUPS: tuple[tuple[tuple[int, ...], float], ...] = (
    ((0, 1, 2), 107.0),  # solid elements, analytic masters, friction
    ((3, 4, 10), 110.0), # facets of deformable bodies and rigid meshes, segment-to-surface
    ((8,), 41.0),        # incompatible modes
    ((5, 6), 57.0),      # solid-shells
    ((7,), 62.0),        # F-bar
    ((9,), 43.0),        # planar bodies and contact in the plane
)


def byte_compile() -> bool:
    """Compile covcontact's Python modules to bytecode (``__pycache__``), as installing a package with pip does;
    True when every module compiled and was written. An editable or unpacked installation run with
    PYTHONDONTWRITEBYTECODE never writes it, so every run would compile the modules again (about 0.1 s of a
    1.6 s run, docs/performance.md "Start-up of a warm run"); a read-only installation is left as it is."""
    import compileall

    return bool(compileall.compile_dir(Path(__file__).resolve().parent, quiet=2))


def warm(stream=None, only: str | None = None, quiet: bool = False,
         indices: tuple[int, ...] | None = None) -> list[tuple[str, float]]:
    """Run every warm-up problem (or those whose label contains ``only``, or those of ``indices``); (label,
    seconds) per problem.

    A line per problem goes to ``stream`` (default: the current stderr) unless ``quiet``.
    """
    from .io.loader import problem_from_dict

    times = []
    with tempfile.TemporaryDirectory() as tmp:
        for i, (label, body) in enumerate(PROBLEMS):
            if (only is not None and only not in label) or (indices is not None and i not in indices):
                continue
            text = _HEAD.format(name=f"warmup-{i}") + body + _STEPS
            problem = problem_from_dict(tomllib.loads(text), Path(tmp) / f"warmup-{i}.toml")
            t0 = time.perf_counter()
            result = problem.run(out=Path(tmp) / f"w{i}", quiet=True)
            dt = time.perf_counter() - t0
            if result.exit_code != 0:
                raise RuntimeError(f"warm-up problem {label!r} did not converge (exit {result.exit_code})")
            times.append((label, dt))
            if not quiet:
                _say(label, dt, stream)
    if only is None and (indices is None or 0 in indices):
        _solver_kernels()
    return times


def _solver_kernels() -> None:
    """The kernels of the linear solvers that the warm-up problems may not meet where they run (an installation
    built without the `fast` extra's PARDISO compiles the kernels a PARDISO run needs all the same)."""
    import numpy as np
    import scipy.sparse as sp

    from .solvers.pardiso_backend import _upper_structure

    _upper_structure(sp.csr_matrix(np.array([[2.0, 1.0], [1.0, 2.0]])))


def _say(label: str, seconds: float, stream=None) -> None:
    print(f"covcontact: compiled {label} ({seconds:.1f} s)", file=stream or sys.stderr, flush=True)


def _warm_group(indices: tuple[int, ...]) -> list[tuple[str, float]]:
    """A worker process's share of :func:`warm_parallel`."""
    return warm(quiet=True, indices=indices)


def warm_parallel(jobs: int, stream=None, quiet: bool = False) -> list[tuple[str, float]]:
    """:func:`warm` in ``jobs`` worker processes, each compiling whole :data:`GROUPS` (the costliest group to the
    least loaded worker): numba compiles a kernel in one thread, so a cold cache fills ``jobs`` times faster where
    the cores are there. (label, seconds in its worker) per problem, in the order of PROBLEMS."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    jobs = max(1, min(int(jobs), len(GROUPS)))
    if jobs == 1:
        return warm(stream, quiet=quiet)
    # (the stamp of the kernel sources was checked at the package's import, here and in each worker alike)
    loads = [0.0] * jobs
    shares: list[list[int]] = [[] for _ in range(jobs)]
    for members, seconds in sorted(GROUPS, key=lambda g: -g[1]):
        k = loads.index(min(loads))
        shares[k].extend(members)
        loads[k] += seconds
    done: dict[str, float] = {}
    with ProcessPoolExecutor(jobs, mp_context=multiprocessing.get_context("spawn")) as pool:
        for result in pool.map(_warm_group, [tuple(sorted(s)) for s in shares]):
            for label, seconds in result:
                done[label] = seconds
                if not quiet:
                    _say(label, seconds, stream)
    return [(label, done[label]) for label, _ in PROBLEMS if label in done]


def cache_is_cold() -> bool:
    """Whether numba's cache lacks the compiled solid-element kernel that every 3D run loads (a new installation, a
    cache cleared for changed kernel sources at the package's import, or a NUMBA_CACHE_DIR not filled yet)."""
    from . import kernel_cache

    return not any(any(folder.glob("solid.solid_chunk-*.nbi")) for folder in kernel_cache.cache_dirs())
