"""Reports on a contact state: per-step summaries, per-node output fields, the rigid bodies' pictures.

Everything here reads a state and evaluates (for the contribution norms of the tangent parts) without
changing it. What looks at all slaves goes through ``manager.gather`` and ``manager.global_norms``, which a
distributed run reduces over the ranks.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .element import CASE_A
from .friction import SLIP, STICK
from .state import ContactState


def frobenius_norms(mats: list[sp.csr_matrix]) -> list[float]:
    return [float(sp.linalg.norm(M)) if M.nnz else 0.0 for M in mats]


def _pass_rows(manager, state: ContactState) -> list[tuple]:
    rows = []
    for k, p in enumerate(manager.passes):
        s = state.passes[k]
        act = manager.active_mask(k, state)
        gmin = float(s.gap.min()) if len(s.gap) and np.isfinite(s.gap.min()) else np.inf
        rows.append((int(act.sum()), int(np.count_nonzero(act & (s.status == STICK))),
                     int(np.count_nonzero(act & (s.status == SLIP))), gmin, s.force[act].sum(axis=0),
                     float(np.max(-s.gap[act], initial=0.0)), s.n_aug))
    return rows


def step_report(manager, x: np.ndarray, lam: float, state: ContactState) -> dict:
    """Per pair: active contacts, minimum gap, force resultant; the contribution norms of the parts."""
    ev, _ = manager.evaluate(x, lam, state, want_K=True, case=CASE_A, want_parts=True)
    main, rot, curv, _ = [b.csr() for b in ev.parts]
    nf, nr, nc = manager.global_norms([main + rot + curv, rot, curv])
    contrib = {"rotational": nr / nf * 100 if nf > 0 else 0.0, "curvature": nc / nf * 100 if nf > 0 else 0.0}
    every = manager.gather(_pass_rows(manager, state))
    pairs = {}
    for k, p in enumerate(manager.passes):
        rows = [e[k] for e in every]
        gmin = min(r[3] for r in rows)
        entry = {"active_contacts": sum(r[0] for r in rows)}
        if p.mu > 0:
            entry.update(stick=sum(r[1] for r in rows), slip=sum(r[2] for r in rows))
        entry["min_gap"] = float(gmin) if np.isfinite(gmin) else None
        entry["contact_force"] = np.sum([r[4] for r in rows], axis=0).tolist()
        if p.augmented:
            entry.update(augmentations=rows[0][6], max_penetration=max(r[5] for r in rows))
        pairs[p.name] = entry
    total_force = np.sum([v["contact_force"] for v in pairs.values()], axis=0).tolist() if pairs else [0.0] * 3
    # the resultant contact force acting on each body: + on the slave side, - on the master side of a pass
    on_body: dict[str, np.ndarray] = {}
    for k, p in enumerate(manager.passes):
        f = np.sum([e[k][4] for e in every], axis=0)
        for body, sign in ((p.slave_body, 1.0), (p.master_body, -1.0)):
            if body:
                on_body[body] = on_body.get(body, np.zeros(3)) + sign * f
    gaps = [v["min_gap"] for v in pairs.values() if v["min_gap"] is not None]
    return {"active_contacts": sum(v["active_contacts"] for v in pairs.values()),
            "min_gap": min(gaps) if gaps else None, "contact_force": total_force,
            "contact_force_on": {b: f.tolist() for b, f in on_body.items()},
            "contribution_percent": contrib, "pairs": pairs}


def node_fields(manager, n: int, state: ContactState, per_pass: dict | None = None
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Gap, contact pressure (force over tributary area) and status (-1 not a slave, 0 inactive, 1 active)
    of nodes 0..n-1 of the extended numbering, from the slaves of all ranks. Segment-to-surface points give the
    nodes of their facets the lumped L2 projection of their values (:meth:`.points.VirtualPoints.smooth`); a node
    is active where an active point's pressure reaches it. A node that is a slave of several passes (a surface in
    several pairs) gets the smallest gap, the sum of the pressures and the highest status; ``per_pass`` (a dict)
    receives each pass's own (gap, pressure, status) by pass name."""
    gap = np.full(n, np.nan)
    pressure = np.zeros(n)
    status = np.full(n, -1.0)
    every = manager.gather(_point_rows(manager, state))
    for k, p in enumerate(manager.passes):
        sl, g, act, fn, area = (np.concatenate([e[k][j] for e in every]) for j in range(5))
        pg = np.full(n, np.nan)
        pp = np.zeros(n)
        ps = np.full(n, -1.0)
        if p.kind == "sts":
            pts = manager.points
            fin = np.isfinite(g)
            sg, touched = pts.smooth(sl, area * fin, np.where(fin, g, 0.0), n)
            sp, has = pts.smooth(sl, area, np.where(act, fn, 0.0), n)
            on, _ = pts.smooth(sl, area, act.astype(float), n)
            pg[touched] = sg[touched]
            pp[has] = sp[has]
            ps[has] = np.where(on[has] > 0.0, 1.0, 0.0)
        else:
            sel = sl < n
            pg[sl[sel]] = np.where(np.isfinite(g[sel]), g[sel], np.nan)
            ps[sl[sel]] = np.where(act[sel], 1.0, 0.0)
            pp[sl[sel]] = np.where(act[sel], fn[sel], 0.0)
        gap = np.fmin(gap, pg)
        pressure += pp
        status = np.maximum(status, ps)
        if per_pass is not None:
            per_pass[p.name] = (pg, pp, ps)
    return gap, pressure, status


def _point_rows(manager, state: ContactState) -> list[tuple]:
    """Per pass: (slave ids, gap, active, pressure = |force| / area, area, facet of a point or -1) of this rank's
    slaves."""
    mine = []
    for k, p in enumerate(manager.passes):
        s = state.passes[k]
        fn = np.linalg.norm(s.force, axis=1) / np.maximum(p.area, 1e-300)
        facet = p.slave_facet if p.slave_facet is not None else np.full(p.ns, -1, dtype=np.int64)
        mine.append((p.slaves, s.gap, manager.active_mask(k, state), fn, p.area, facet))
    return mine


def facet_pressure(manager, state: ContactState, nodal: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per pass with a slave face set: (faces (nf, nen) extended ids, the mean contact pressure of each facet):
    the area-weighted mean over its points (sts), the mean over its nodes of the nodal pressure ``nodal`` (the
    pressure of :func:`node_fields` over the extended nodes) (nts)."""
    every = manager.gather(_point_rows(manager, state))
    out = []
    for k, p in enumerate(manager.passes):
        if p.slave_faces is None:
            continue
        nf = len(p.slave_faces)
        if p.kind == "sts":
            _, _, act, fn, area, facet = (np.concatenate([e[k][j] for e in every]) for j in range(6))
            num = np.bincount(facet, area * np.where(act, fn, 0.0), minlength=nf)
            den = np.bincount(facet, area, minlength=nf)
            out.append((p.slave_faces, np.divide(num, den, out=np.zeros(nf), where=den > 0)))
        else:
            out.append((p.slave_faces, nodal[p.slave_faces].mean(axis=1)))
    return out


def point_data(manager, n_nodes: int, state: ContactState, fields: tuple | None = None,
               per_pass: dict | None = None) -> dict:
    """Gap, contact pressure and status per deformable node (from :func:`node_fields` over the extended nodes,
    ``fields`` and its ``per_pass``, when the caller has them). Where a node is a slave of several passes (a slave
    surface in several pairs), each pass's own fields too: ``gap[NAME]``, ``contact_pressure[NAME]``,
    ``contact_status[NAME]``."""
    if fields is None or per_pass is None:
        per_pass = {}
        fields = node_fields(manager, manager.num.n_ext, state, per_pass)
    gap, pressure, status = fields
    out = {"gap": gap[:n_nodes], "contact_pressure": pressure[:n_nodes], "contact_status": status[:n_nodes]}
    if len(per_pass) > 1:
        slave_of = sum((ps[:n_nodes] >= 0).astype(int) for _, _, ps in per_pass.values())
        if np.any(slave_of > 1):
            for name, (pg, pp, ps) in per_pass.items():
                out[f"gap[{name}]"] = pg[:n_nodes]
                out[f"contact_pressure[{name}]"] = pp[:n_nodes]
                out[f"contact_status[{name}]"] = ps[:n_nodes]
    return out


#: a slave node deeper inside its master than this fraction of the node spacing at the start is warned about
INSIDE_FRACTION = 0.1


def start_warnings(manager, x: np.ndarray, state: ContactState, names: dict[str, str]) -> list[str]:
    """Warnings about a set-up that is legal but almost certainly wrong: most slave nodes of a pass start
    inside the master (deeper than 1 % of their typical spacing: touching is fine), as an analytic surface
    turned inside out, master faces whose normals point into their body, or a body misplaced or in other
    units would make them; or some start deeper than ``INSIDE_FRACTION`` of the spacing.

    ``x`` the positions at the start, ``names`` pass name -> a description of its master for the message.
    """
    ev, trial = manager.evaluate(x, 0.0, state, want_K=False)
    out = []
    for k, p in enumerate(manager.passes):
        if not manager.enabled[k] or p.ns == 0:
            continue
        g = trial.passes[k].gap
        xs = manager.extended(x, 0.0)[p.slaves]
        spacing = _spacing(xs, p)
        deep = np.isfinite(g) & (g < -0.01 * spacing)
        master = names.get(p.name, "its master")
        if deep.sum() > 0.5 * p.ns:
            out.append(f"contact {p.name!r}: {int(deep.sum())} of {p.ns} slave nodes start inside {master} (gap "
                       f"down to {float(g[deep].min()):.3g} against a node spacing of {spacing:.3g}); likely an "
                       f"analytic surface with the wrong 'outside', a master face set whose normals point into "
                       f"its body, or a body misplaced or in other units")
        elif np.any(deeper := np.isfinite(g) & (g < -INSIDE_FRACTION * spacing)):
            worst = int(p.slaves[np.argmin(np.where(deeper, g, np.inf))])
            out.append(f"contact {p.name!r}: {int(deeper.sum())} of {p.ns} slave nodes start inside {master}, "
                       f"down to {float(g[deeper].min()):.3g} (node {worst}) against a node spacing of "
                       f"{spacing:.3g}; the first step pushes them out at once, with a large force and often "
                       f"cutbacks: move the bodies apart or check the geometry")
    return out


def _spacing(xs: np.ndarray, p) -> float:
    """A typical distance between neighbouring slave nodes: sqrt of the mean tributary area, else the
    bounding box over the number of nodes."""
    if np.any(p.area != 1.0):
        return float(np.sqrt(np.mean(p.area)))
    span = float(np.linalg.norm(xs.max(axis=0) - xs.min(axis=0))) if len(xs) > 1 else 1.0
    return span / max(np.sqrt(len(xs)), 1.0)
