"""Rigid bodies drawn into the result files: rigid meshes and analytic surfaces (as quad patches).

Like the deformable bodies they are written at their reference position with a ``displacement`` field, so
ParaView's "Warp By Vector" shows every body in its current position.
"""

from __future__ import annotations

import numpy as np

from ..contact.analytic import CYLINDER, EXTRUDED, PLANE, REVOLVED
from ..contact.profile import ARC, profile_point
from ..contact.setup import analytic_surface
from .output import body_blocks


def _grid_quads(nu: int, nv: int, closed_u: bool) -> np.ndarray:
    """Quad connectivity of an (nu [+1]) x (nv + 1) point grid, u running fastest."""
    pu = nu if closed_u else nu + 1
    quads = []
    for j in range(nv):
        for i in range(nu):
            a = j * pu + i
            b = j * pu + (i + 1) % pu
            quads.append([a, b, b + pu, a + pu])
    return np.array(quads, dtype=np.int64)


def tessellate(surface, lam: float, center: np.ndarray, size: float) -> tuple[np.ndarray, np.ndarray]:
    """Points and quads approximating an analytic surface near ``center`` (extent ``size``)."""
    origin, frame = surface.placement(lam)
    e1, e2, e3 = frame
    if surface.kind in (EXTRUDED, REVOLVED):
        return _tessellate_profile(surface, origin, frame, center, size)
    if surface.kind == PLANE:
        c = center - np.dot(center - origin, e3) * e3
        s = np.linspace(-0.6 * size, 0.6 * size, 21)
        U, V = np.meshgrid(s, s)
        pts = c + U.ravel()[:, None] * e1 + V.ravel()[:, None] * e2
        return pts, _grid_quads(20, 20, False)
    R = surface.radius
    if surface.kind == CYLINDER:
        z0 = np.dot(center - origin, e3)
        t = np.linspace(0, 2 * np.pi, 48, endpoint=False)
        z = np.linspace(z0 - 0.6 * size, z0 + 0.6 * size, 11)
        T, Z = np.meshgrid(t, z)
        pts = origin + R * (np.cos(T).ravel()[:, None] * e1 + np.sin(T).ravel()[:, None] * e2) \
            + Z.ravel()[:, None] * e3
        return pts, _grid_quads(48, 10, True)
    th = np.linspace(0, np.pi, 25)
    ph = np.linspace(0, 2 * np.pi, 48, endpoint=False)
    PH, TH = np.meshgrid(ph, th)
    d = (np.sin(TH) * np.cos(PH)).ravel()[:, None] * e1 + (np.sin(TH) * np.sin(PH)).ravel()[:, None] * e2 \
        + np.cos(TH).ravel()[:, None] * e3
    return origin + R * d, _grid_quads(48, 24, True)


def profile_polyline(prof: np.ndarray) -> np.ndarray:
    """Points (m, 2) along a profile from its first to its last given point, arcs in steps of 10 degrees."""
    out = []
    for k, seg in enumerate(prof):
        n = max(2, int(np.ceil(seg[2] / seg[7] / np.radians(10.0))) + 1) if seg[0] == ARC else 2
        for t in np.linspace(0.0, seg[2], n)[(1 if k else 0):]:
            out.append(profile_point(prof, k, t)[:2])
    return np.array(out)


def _tessellate_profile(surface, origin, frame, center, size):
    """The whole profile, extruded over the model's extent or revolved all round."""
    e1, e2, e3 = frame
    c2 = profile_polyline(surface.prof)
    m = len(c2)
    if surface.kind == EXTRUDED:
        z0 = float(np.dot(center - origin, e3))
        z = np.linspace(z0 - 0.6 * size, z0 + 0.6 * size, 11)
        pts = [origin + c2[:, :1] * e1 + c2[:, 1:] * e2 + zz * e3 for zz in z]
        return np.vstack(pts), _grid_quads(m - 1, 10, False)
    t = np.linspace(0, 2 * np.pi, 48, endpoint=False)
    pts = [origin + c2[i, 0] * (np.cos(t)[:, None] * e1 + np.sin(t)[:, None] * e2) + c2[i, 1] * e3
           for i in range(m)]
    return np.vstack(pts), _grid_quads(48, m - 1, True)


def rigid_visual(manager, lam: float, fields) -> tuple:
    """(points, blocks, point_data) of all rigid bodies, numbered from 0 (the caller shifts them).

    ``fields``: (gap, pressure, status) over the extended node numbering of ``manager``.
    """
    pts: list[np.ndarray] = []
    blocks = []
    n = 0
    X = manager.system.X
    lo, hi = X.min(axis=0), X.max(axis=0)
    center, size = 0.5 * (lo + hi), float(np.linalg.norm(hi - lo)) or 1.0
    disp = []
    gap, pressure, status = fields
    gaps, press, stats = [], [], []
    body_id = len(manager.problem.bodies)
    for rb in manager.problem.rigid:
        if not rb.shape:  # (nodes attached to a rigid body: drawn with their own body)
            continue
        if rb.mesh is not None:
            p = manager.num.motion(rb.name).apply(rb.mesh.points, lam)
            off = manager.num.rigid_offset[rb.name]
            sl = slice(off, off + rb.mesh.n_nodes)
            gaps.append(gap[sl])
            press.append(pressure[sl])
            stats.append(status[sl])
            blocks += body_blocks(rb.mesh, n, {"body_id": np.full(rb.mesh.n_cells, body_id, dtype=float)})
            disp.append(p - rb.mesh.points)
            p = rb.mesh.points
        else:
            p, quads = tessellate(analytic_surface(rb), 0.0, center, size)
            m = len(p)
            gaps.append(np.full(m, np.nan))
            press.append(np.zeros(m))
            stats.append(np.full(m, -1.0))
            blocks.append(("quad4", quads + n, {"body_id": np.full(len(quads), body_id, dtype=float)}))
            disp.append(manager.num.motion(rb.name).apply(p, lam) - p)
        pts.append(p)
        n += len(p)
        body_id += 1
    if not pts:
        return None, [], {}
    pdata = {"displacement": np.vstack(disp), "gap": np.concatenate(gaps),
             "contact_pressure": np.concatenate(press), "contact_status": np.concatenate(stats)}
    return np.vstack(pts), blocks, pdata
