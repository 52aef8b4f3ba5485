"""Structured solid meshes for contact checks: a half- or quarter-cylinder graded toward its lowest line.

The cross-section (the x-z plane) is an O-grid like the one of ``hemisphere_solid``: a central box
below the axis and blocks of ``nr`` layers between the box and the circle, equiangular on the circle;
the section is extruded along the axis (y). An optional smooth map in polar coordinates about the axis
pulls the nodes toward the lowest line (the line contact of a cylinder on a plane) while the circle and
the flat face stay exact.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from .generators import _assemble, _Block, _check_cell, _count, _lattice, _lin, _positive
from .mesh import Mesh


def _half_lin(n: int, negative: bool) -> np.ndarray:
    """Element boundaries in [-1, 1] (or [0, 1]) with an exact 0 in the middle."""
    half = np.linspace(0.0, 1.0, n + 1)
    return np.concatenate([-half[::-1], half[1:]]) if negative else half


def _grade(XZ: np.ndarray, R: float, grade_angle: float, grade_depth: float) -> np.ndarray:
    """Pull section points (X, Z about the axis, Z <= 0) toward (0, -R); the circle and Z = 0 map onto
    themselves.

    Polar angle from the downward direction, x = theta / (pi/2) in [-1, 1], and depth s = 1 - rho/R:
    s -> sinh(gd s)/sinh(gd), x -> x + w (sinh(ga x)/sinh(ga) - x) with w = rho_new/R. Element sizes at the
    lowest line shrink by ga/sinh(ga) along the circle and gd/sinh(gd) in depth.
    """
    X, Z = XZ[:, 0], XZ[:, 1]
    rho = np.hypot(X, Z)
    x = np.arctan2(X, -Z) / (0.5 * math.pi)
    s = 1.0 - rho / R
    if grade_depth > 0.0:
        s = np.sinh(grade_depth * s) / math.sinh(grade_depth)
    rho_new = R * (1.0 - s)
    if grade_angle > 0.0:
        x = x + rho_new / R * (np.sinh(grade_angle * x) / math.sinh(grade_angle) - x)
    theta = 0.5 * math.pi * x
    out = np.stack([rho_new * np.sin(theta), -rho_new * np.cos(theta)], axis=1)
    out[rho < 1e-14 * R] = 0.0
    return out


def half_cylinder_solid(
    radius: float, length: float, n: int = 8, nr: int | None = None, n_len: int = 1, cell: str = "hex8",
    part: str = "half", core: float = 0.45, grade_angle: float = 0.0, grade_depth: float = 0.0,
    origin: Sequence[float] = (0.0, 0.0, 0.0),
) -> Mesh:
    """Solid half-cylinder of radius R (axis along y): flat face up at z = R, lowest line through ``origin``.

    The section x-z is the lower half-disk about (0, R) relative to ``origin``: a box [-a, a] x [-a, 0]
    (a = core * R, relative to the axis) with n x n/2 elements, a bottom block (n elements along the
    circle) and two side blocks (n/2 each), nr layers between box and circle. Along the axis the body spans
    [0, length] from ``origin`` with n_len elements. ``part = "quarter"`` keeps x >= 0 (n/2 x n/2 box, n
    elements on the quarter circle). ``grade_angle`` and ``grade_depth`` (0: none) grade the mesh toward the lowest
    line: element sizes there shrink by g/sinh(g) along the circle and in depth (4.5 gives 0.1). hex18 is
    rejected (a solid-shell cell).

    Sets: node and face sets "flat" (z = R), "curved" (the cylinder), "end0", "end1" (the axial ends
    y = 0 and y = length), and for a quarter "symx" (the plane x = 0); node sets "bottom_line" (the
    nodes on the lowest line) and "all".
    """
    _check_cell(cell)
    if cell == "hex18":
        raise ValueError("half_cylinder_solid needs hex8 or hex27: hex18 is a solid-shell cell")
    if part not in ("half", "quarter"):
        raise ValueError(f"part must be 'half' or 'quarter', got {part!r}")
    quarter = part == "quarter"
    R = _positive("radius", radius)
    L = _positive("length", length)
    n = _count("n", n)
    if n % 2:
        raise ValueError(f"n must be even (a node on the lowest line), got {n}")
    nr = max(1, n // 2) if nr is None else _count("nr", nr)
    n_len = _count("n_len", n_len)
    if not (0.0 < core < 1.0 / math.sqrt(2.0)):
        raise ValueError(f"core must lie in (0, 1/sqrt(2)), got {core!r}")
    for name, g in (("grade_angle", grade_angle), ("grade_depth", grade_depth)):
        if not (math.isfinite(g) and g >= 0.0):
            raise ValueError(f"{name} must be >= 0, got {g!r}")
    a = core * R
    bx = _half_lin(n // 2, negative=not quarter)  # across the box (x) and along the bottom arc
    bz = np.linspace(-1.0, 0.0, n // 2 + 1)  # up the box (z) and along the side arcs
    bs, by = _lin(nr), _lin(n_len)
    sections: list[tuple[np.ndarray, np.ndarray, dict[str, np.ndarray]]] = []

    U, cells = _lattice(cell, [bx, bz, by])
    sections.append((a * U[:, :2], U, cells, {"flat": U[:, 1] == 0.0, "symx": U[:, 0] == 0.0}))
    # bottom block: box edge Z = -a to the arc at angles pi/4 t from the downward direction
    U, cells = _lattice(cell, [bx, bs, by])
    t, s = U[:, 0], U[:, 1:2]
    box = np.stack([a * t, -a * np.ones_like(t)], axis=1)
    arc = R * np.stack([np.sin(0.25 * math.pi * t), -np.cos(0.25 * math.pi * t)], axis=1)
    sections.append(((1.0 - s) * box + s * arc, U, cells,
                     {"curved": U[:, 1] == 1.0, "symx": t == 0.0, "bottom_line": (t == 0.0) & (U[:, 1] == 1.0)}))
    # side blocks: box edge X = +-a to the arc at angles pi/4 t from the horizontal
    for sign in (1.0,) if quarter else (1.0, -1.0):
        U, cells = _lattice(cell, [bz, bs, by])
        t, s = U[:, 0], U[:, 1:2]
        box = np.stack([sign * a * np.ones_like(t), a * t], axis=1)
        arc = R * np.stack([sign * np.cos(0.25 * math.pi * t), np.sin(0.25 * math.pi * t)], axis=1)
        sections.append(((1.0 - s) * box + s * arc, U, cells, {"curved": U[:, 1] == 1.0, "flat": t == 0.0}))

    o = np.asarray(origin, dtype=np.float64)
    blocks: list[_Block] = []
    for XZ, U, cells, sets in sections:
        if grade_angle > 0.0 or grade_depth > 0.0:
            XZ = _grade(XZ, R, grade_angle, grade_depth)
        X = o + np.stack([XZ[:, 0], L * U[:, 2], R + XZ[:, 1]], axis=1)
        sets = dict(sets, end0=U[:, 2] == 0.0, end1=U[:, 2] == 1.0, all=np.ones(U.shape[0], dtype=bool))
        if not quarter:
            sets.pop("symx", None)
        blocks.append((X, cells, sets))
    return _assemble(blocks, cell, no_faces=("all", "bottom_line"))
