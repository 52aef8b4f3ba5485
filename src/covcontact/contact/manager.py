"""Contact pairs of a problem inside Newton: search, projection, assembly, history and reports.

Node numbering: the deformable nodes 0..N-1 of the global system come first, then the nodes of rigid meshed
bodies (no unknowns; positions from their prescribed motion). A master facet or slave node of a rigid body
contributes to the residual and tangent only through the deformable dofs of its pair.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from .analytic import Cylinder, Plane, Sphere
from .driver import EDGE, FACET, VERTEX, project_slaves
from .edge import edge_vertex_contact
from .element import CASES
from .friction import HIST_SIZE, SLIP, STICK, analytic_friction_batch, friction_batch, transfer_history
from .kernels import contact_batch
from .search import candidates
from .surface import MeshSurface, facet_sizes, tributary_area


@dataclass
class Pass:
    """One slave node set against one master surface (a pair, or one direction of a two-pass pair)."""

    name: str
    slaves: np.ndarray                 # node ids in the extended numbering
    eps: np.ndarray                    # (ns,) weighted penalty per slave
    area: np.ndarray                   # (ns,) tributary area per slave (for the pressure output)
    surface: MeshSurface | None = None
    analytic: object = None
    prev_facet: np.ndarray = field(default=None)
    prev_xi: np.ndarray = field(default=None)
    saved: tuple = field(default=None)
    cand: tuple | None = None
    x_search: np.ndarray | None = None
    margin: float = 0.0
    mu: float = 0.0                    # Coulomb coefficient (0: frictionless)
    augmented: bool = False            # augmented Lagrangian (Uzawa) instead of pure penalty
    gap_tol: float = 0.0               # largest accepted penetration of the augmented method
    max_aug: int = 20
    eps_t: np.ndarray = field(default=None)  # (ns,) tangential penalty per slave
    # last evaluation
    g: np.ndarray = field(default=None)
    force: np.ndarray = field(default=None)  # (ns, 3) force on each slave node
    state: np.ndarray = field(default=None)  # (ns,) friction state (0 open, 1 stick, 2 slip, 3 new)

    def __post_init__(self):
        ns = len(self.slaves)
        self.prev_facet = np.full(ns, -1, dtype=np.int64)
        self.prev_xi = np.zeros((ns, 2))
        self.g = np.full(ns, np.inf)
        self.force = np.zeros((ns, 3))
        self.state = np.zeros(ns, dtype=np.int64)
        self.committed = (self.prev_facet.copy(), self.prev_xi.copy())
        # friction history: committed at converged steps, trial from the last evaluation
        self.hist = np.zeros((ns, HIST_SIZE))
        self.hist_trial = np.zeros((ns, HIST_SIZE))
        self.hist_facet = np.full(ns, -1, dtype=np.int64)
        self.x_conv: np.ndarray | None = None
        # augmented Lagrangian multipliers (<= 0) per slave node: trial, saved at a step start, committed
        self.lam_mult = np.zeros(ns)
        self.lam_saved = np.zeros(ns)
        self.n_aug = 0


def _analytic_surface(rb):
    p = rb.params
    if rb.shape == "plane":
        return Plane(point=p["point"], normal=p["normal"], motion=rb.motion)
    if rb.shape == "cylinder":
        return Cylinder(center=p["center"], axis=p["axis"], radius=p["radius"], outside=p["outside"],
                        motion=rb.motion)
    return Sphere(center=p["center"], radius=p["radius"], outside=p["outside"], motion=rb.motion)


class ContactManager:
    """All contact pairs of a problem, evaluated at the current positions."""

    symmetric = True

    def __init__(self, problem, system, tangent: str = "a"):
        self.problem = problem
        self.system = system
        self.case = CASES[tangent]
        self.N = system.n_nodes
        # rigid meshed bodies appended after the deformable nodes
        self.rigid_offset: dict[str, int] = {}
        self.rigid_meshes = []
        n = self.N
        for rb in problem.rigid:
            if rb.mesh is not None:
                self.rigid_offset[rb.name] = n
                self.rigid_meshes.append(rb)
                n += rb.mesh.n_nodes
        self.n_ext = n
        self.X_rigid = (np.vstack([rb.mesh.points for rb in self.rigid_meshes]) if self.rigid_meshes
                        else np.zeros((0, 3)))
        self.passes: list[Pass] = []
        for pair in problem.contacts:
            self.passes.append(self._make_pass(pair.name, pair.slave, pair.master, pair))
            if pair.two_pass:
                rev_slave = (pair.master[0], pair.master[1])
                rev_master = (pair.slave[0], pair.slave[1])
                self.passes.append(self._make_pass(pair.name + "/reverse", rev_slave, rev_master, pair))
        self.symmetric = not any(p.mu > 0.0 for p in self.passes)
        self.lam = 0.0
        self._x_rigid_lam = self.X_rigid.copy()
        self.timing = {"search": 0.0, "projection": 0.0}
        self._x_last: np.ndarray | None = None

    # -- set-up ---------------------------------------------------------------------------------
    def _mesh_of(self, body: str):
        for b in self.problem.bodies:
            if b.name == body:
                return b.mesh, self.system.offset(body)
        for rb in self.rigid_meshes:
            if rb.name == body:
                return rb.mesh, self.rigid_offset[body]
        return None, None

    def _reference_positions(self) -> np.ndarray:
        return np.vstack([self.system.X, self.X_rigid])

    def _material_E(self, body: str) -> float | None:
        for b in self.problem.bodies:
            if b.name == body:
                return float(b.material.params[0])
        return None

    def _auto_penalty(self, pair, slave, master) -> float:
        """eps_N per unit area: auto_factor * E / h of the master body (the slave body's if rigid)."""
        X = self._reference_positions()
        for body, sset in (master, slave):
            E = self._material_E(body)
            mesh, off = self._mesh_of(body)
            if E is None or mesh is None or sset not in mesh.face_sets:
                continue
            h = float(np.mean(facet_sizes(X, mesh.face_sets[sset] + off))) / np.sqrt(2.0)
            return pair.auto_factor * E / h
        raise ValueError(f"contact {pair.name}: penalty = \"auto\" needs a deformable body with a face set "
                         f"named like its contact set")

    def _make_pass(self, name, slave, master, pair) -> Pass:
        smesh, soff = self._mesh_of(slave[0])
        slaves = smesh.node_sets[slave[1]] + soff
        X = self._reference_positions()
        if slave[1] in smesh.face_sets:
            area_all = tributary_area(X, smesh.face_sets[slave[1]] + soff)
            area = area_all[slaves]
        else:
            area = np.ones(len(slaves))
        penalty = self._auto_penalty(pair, slave, master) if pair.penalty == "auto" else pair.penalty
        if pair.weighting == "area" or pair.penalty == "auto":
            if slave[1] not in smesh.face_sets:
                raise ValueError(f"contact {pair.name}: area weighting needs a face set named {slave[1]!r}")
            eps = penalty * area
        else:
            eps = np.full(len(slaves), float(penalty))
        mu = float(getattr(pair, "friction", 0.0) or 0.0)
        ratio = (pair.tangential_penalty / penalty) if getattr(pair, "tangential_penalty", None) else 1.0
        eps_t = eps * ratio
        extra = {"mu": mu, "eps_t": eps_t, "augmented": pair.method == "augmented",
                 "max_aug": pair.max_augmentations}
        mmesh, moff = self._mesh_of(master[0])
        if mmesh is None:
            rb = next(r for r in self.problem.rigid if r.name == master[0])
            h = float(np.mean(facet_sizes(X, smesh.face_sets[slave[1]] + soff))) if slave[1] in smesh.face_sets \
                else 1.0
            p = Pass(name, slaves, eps, area, analytic=_analytic_surface(rb), **extra)
        else:
            faces = mmesh.face_sets[master[1]] + moff
            h = float(np.mean(facet_sizes(X, faces))) / np.sqrt(2.0)
            p = Pass(name, slaves, eps, area, surface=MeshSurface(faces, n_nodes=self.n_ext), **extra)
        if p.augmented:
            p.gap_tol = pair.gap_tolerance if pair.gap_tolerance is not None else pair.gap_tolerance_relative * h
        return p

    # -- positions ------------------------------------------------------------------------------
    def rigid_positions(self, lam: float) -> np.ndarray:
        parts = [rb.motion.apply(rb.mesh.points, lam) for rb in self.rigid_meshes]
        return np.vstack(parts) if parts else np.zeros((0, 3))

    def extended(self, x: np.ndarray) -> np.ndarray:
        if len(self._x_rigid_lam) == 0:
            return np.ascontiguousarray(x)
        return np.ascontiguousarray(np.vstack([x, self._x_rigid_lam]))

    # -- Newton interface -----------------------------------------------------------------------
    def begin_step(self, x: np.ndarray, lam: float) -> None:
        self.lam = lam
        self._x_rigid_lam = self.rigid_positions(lam)
        for p in self.passes:
            p.cand = None  # global search again at the start of every step

    def _search(self, p: Pass, xe: np.ndarray) -> None:
        moved = np.inf if p.x_search is None or p.cand is None else \
            float(np.abs(xe - p.x_search).max())
        if p.cand is not None and moved < 0.25 * p.margin:
            return
        t0 = time.perf_counter()
        sizes = facet_sizes(xe, p.surface.faces)
        p.margin = float(sizes.max()) if len(sizes) else 0.0
        p.cand = candidates(xe, p.surface, xe[p.slaves], p.margin)
        p.x_search = xe.copy()
        self.timing["search"] += time.perf_counter() - t0

    def _pair_arrays(self, p: Pass, xe: np.ndarray):
        """Project the slaves; returns the projection result and the active mask."""
        self._search(p, xe)
        t0 = time.perf_counter()
        res = project_slaves(xe, p.surface, xe[p.slaves], p.cand[0], p.cand[1], p.prev_facet, p.prev_xi)
        self.timing["projection"] += time.perf_counter() - t0
        ok = res.kind != 0
        p.prev_facet = np.where(ok, res.facet, -1)
        p.prev_xi = np.where(ok[:, None], res.xi, 0.0)
        active = ok & (res.g + p.lam_mult / p.eps <= 0.0)
        return res, active

    def _dofs(self, nodes: np.ndarray) -> np.ndarray:
        """(m, k) node ids -> (m, 3k) global dofs, -1 for rigid nodes."""
        d = 3 * nodes[:, :, None] + np.arange(3)[None, None, :]
        d = d.reshape(nodes.shape[0], -1)
        d[np.repeat(nodes >= self.N, 3, axis=1)] = -1
        return d

    def _scatter(self, dofs, R, K, r_out, rows, cols, vals):
        m, nd = dofs.shape
        keep = dofs >= 0
        np.add.at(r_out, dofs[keep], R[keep])
        if K is not None:
            rr = np.repeat(dofs, nd, axis=1)
            cc = np.tile(dofs, (1, nd))
            mask = (rr >= 0) & (cc >= 0)
            rows.append(rr[mask])
            cols.append(cc[mask])
            vals.append(K.reshape(m, -1)[mask])

    def _mesh_pass(self, p: Pass, xe, case, want_K, want_parts, r, rows, cols, vals, parts_acc):
        res, active = self._pair_arrays(p, xe)
        p.g = np.where(res.kind != 0, res.g, np.inf)
        p.force[:] = 0.0
        nen = p.surface.nen
        facet_act = active & (res.kind == FACET)
        idx = np.flatnonzero(facet_act)
        if idx.size:
            conn = np.ascontiguousarray(p.surface.faces[res.facet[idx]])
            sl = np.ascontiguousarray(p.slaves[idx])
            xi = np.ascontiguousarray(res.xi[idx])
            eps = np.ascontiguousarray(p.eps[idx])
            nd = 3 * (nen + 1)
            R = np.zeros((idx.size, nd))
            K = np.zeros((idx.size, nd, nd))
            P = np.zeros((idx.size, 4, nd, nd)) if want_parts else np.zeros((1, 4, 1, 1))
            g = np.zeros(idx.size)
            lam_k = np.ascontiguousarray(p.lam_mult[idx]) if p.augmented else None
            contact_batch(xe, conn, sl, xi, eps, case, want_parts, R, K, P, g, lam_k)
            if p.mu > 0.0 and not want_parts:
                R, K, g = self._facet_friction(p, xe, idx, conn, sl, xi, eps)
            p.g[idx] = g
            p.force[idx] = -R[:, -3:]
            dofs = self._dofs(np.hstack([conn, sl[:, None]]))
            self._scatter(dofs, R, K if want_K else None, r, rows, cols, vals)
            if want_parts:
                for k in range(4):
                    self._scatter(dofs, np.zeros_like(R), P[:, k], np.zeros_like(r), *parts_acc[k])
        # edge and vertex points: the distance to the closest point of the facet boundary (contact.edge)
        idx = np.flatnonzero(active & ((res.kind == EDGE) | (res.kind == VERTEX)))
        if idx.size:
            conn = p.surface.faces[res.facet[idx]]
            sl = p.slaves[idx]
            nd = 3 * (nen + 1)
            R = np.zeros((idx.size, nd))
            K = np.zeros((idx.size, nd, nd))
            for j, s in enumerate(idx):
                lam = float(p.lam_mult[s]) if p.augmented else 0.0
                R[j], K[j], g = edge_vertex_contact(xe[conn[j]], res.xi[s], xe[p.slaves[s]],
                                                    1.0 if res.g[s] >= 0.0 else -1.0, float(p.eps[s]), lam,
                                                    vertex=bool(res.kind[s] == VERTEX))
                p.g[s] = g
            p.force[idx] = -R[:, -3:]
            dofs = self._dofs(np.hstack([conn, sl[:, None]]))
            self._scatter(dofs, R, K if want_K else None, r, rows, cols, vals)
            if want_parts:
                self._scatter(dofs, np.zeros_like(R), K, np.zeros_like(r), *parts_acc[0])

    def _facet_history(self, p: Pass, idx: np.ndarray, facets: np.ndarray, xi: np.ndarray) -> np.ndarray:
        """Committed friction history of slaves ``idx`` moved onto their current facets."""
        hist = p.hist[idx].copy()
        moved = np.flatnonzero((hist[:, -1] > 0.0) & (p.hist_facet[idx] != facets))
        for j in moved:
            xyz = p.x_conv[p.surface.faces[facets[j]]] if p.x_conv is not None else None
            if xyz is None:
                hist[j] = 0.0
                continue
            try:
                hist[j] = transfer_history(hist[j], xyz, xi[j])
            except ValueError:
                hist[j] = 0.0
        return hist

    def _facet_friction(self, p: Pass, xe, idx, conn, sl, xi, eps):
        """Frictional residual and (non-symmetric) tangent of the active facet pairs ``idx``."""
        facets = p.prev_facet[idx]
        hist = self._facet_history(p, idx, facets, xi)
        nd = 3 * (p.surface.nen + 1)
        R = np.zeros((idx.size, nd))
        K = np.zeros((idx.size, nd, nd))
        hist_out = np.zeros_like(hist)
        g = np.zeros(idx.size)
        state = np.zeros(idx.size, dtype=np.int64)
        friction_batch(xe, conn, sl, xi, np.ascontiguousarray(eps), np.ascontiguousarray(p.eps_t[idx]),
                       np.full(idx.size, p.mu), hist, R, K, hist_out, g, state,
                       np.ascontiguousarray(p.lam_mult[idx]) if p.augmented else np.zeros(idx.size))
        p.hist_trial[idx] = hist_out
        p.state[idx] = state
        return R, K, g

    def _analytic_pass(self, p: Pass, xe, case, want_K, want_parts, r, rows, cols, vals, parts_acc):
        xs = np.ascontiguousarray(xe[p.slaves])
        parts = {v: k for k, v in CASES.items()}[case]
        mult = p.lam_mult if p.augmented else None
        out = p.analytic.evaluate(xs, p.eps, parts=parts, lam=self.lam, multiplier=mult)
        if p.mu > 0.0 and not want_parts:
            ns = len(xs)
            origin, frame = p.analytic.placement(self.lam)
            R3 = np.zeros((ns, 3))
            K3 = np.zeros((ns, 3, 3))
            hist_out = np.zeros((ns, HIST_SIZE))
            g = np.zeros(ns)
            xi = np.zeros((ns, 2))
            state = np.zeros(ns, dtype=np.int64)
            analytic_friction_batch(p.analytic.kind, origin, frame, float(p.analytic.radius),
                                    float(p.analytic.sigma), xs, np.ascontiguousarray(p.eps),
                                    np.ascontiguousarray(p.eps_t), np.full(ns, p.mu), p.hist.copy(), R3, K3,
                                    hist_out, g, xi, state,
                                    np.ascontiguousarray(p.lam_mult) if p.augmented else np.zeros(ns))
            out.residual, out.tangent, out.gap = R3, K3, g
            p.hist_trial[:] = hist_out
            p.state[:] = state
        p.g = out.gap
        active = out.gap + p.lam_mult / p.eps <= 0.0
        p.force = -out.residual
        idx = np.flatnonzero(active)
        if idx.size == 0:
            return
        dofs = self._dofs(p.slaves[idx][:, None])
        self._scatter(dofs, out.residual[idx], out.tangent[idx] if want_K else None, r, rows, cols, vals)
        if want_parts:
            d = p.analytic.evaluate(xs, p.eps, parts="d", lam=self.lam, multiplier=mult)
            c = p.analytic.evaluate(xs, p.eps, parts="c", lam=self.lam, multiplier=mult)
            e = p.analytic.evaluate(xs, p.eps, parts="exact", lam=self.lam, multiplier=mult)
            zero = np.zeros_like(r)
            self._scatter(dofs, np.zeros((idx.size, 3)), d.tangent[idx], zero, *parts_acc[0])
            self._scatter(dofs, np.zeros((idx.size, 3)), c.tangent[idx] - d.tangent[idx], zero, *parts_acc[2])
            self._scatter(dofs, np.zeros((idx.size, 3)), e.tangent[idx] - c.tangent[idx], zero, *parts_acc[3])

    def evaluate(self, x: np.ndarray, lam: float, want_K: bool, case: int | None = None,
                 want_parts: bool = False):
        """Contact residual (n_dofs,) and tangent (CSR or None) at deformable positions x (N, 3)."""
        case = self.case if case is None else case
        xe = self.extended(x)
        self._x_last = xe
        r = np.zeros(3 * self.N)
        rows: list = []
        cols: list = []
        vals: list = []
        parts_acc = [([], [], []) for _ in range(4)]
        for p in self.passes:
            if p.surface is not None:
                self._mesh_pass(p, xe, case, want_K, want_parts, r, rows, cols, vals, parts_acc)
            else:
                self._analytic_pass(p, xe, case, want_K, want_parts, r, rows, cols, vals, parts_acc)
        K = self._coo(rows, cols, vals) if want_K else None
        if want_parts:
            return r, K, [self._coo(*acc) for acc in parts_acc]
        return r, K

    def _coo(self, rows, cols, vals) -> sp.csr_matrix:
        n = 3 * self.N
        if not rows:
            return sp.csr_matrix((n, n))
        return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n))

    def save_state(self) -> None:
        for p in self.passes:
            p.saved = (p.prev_facet.copy(), p.prev_xi.copy())
            p.lam_saved = p.lam_mult.copy()
            p.n_aug = 0

    def restore_state(self) -> None:
        for p in self.passes:
            if p.saved is not None:
                p.prev_facet, p.prev_xi = p.saved[0].copy(), p.saved[1].copy()
            p.lam_mult = p.lam_saved.copy()
            p.cand = None

    def commit(self) -> None:
        for p in self.passes:
            p.committed = (p.prev_facet.copy(), p.prev_xi.copy())
            if p.mu > 0.0:
                open_ = ~self._active(p)
                p.hist = p.hist_trial.copy()
                p.hist[open_] = 0.0  # a node that lost contact starts again without history
                p.hist_facet = p.prev_facet.copy()
                p.x_conv = self._x_last.copy() if self._x_last is not None else None

    def augment(self) -> bool:
        """Uzawa update lambda <- <lambda + eps_N g> of every augmented pass whose largest penetration
        exceeds its tolerance (at most ``max_aug`` times per step); True when Newton must run again."""
        again = False
        for p in self.passes:
            if not p.augmented or p.n_aug >= p.max_aug:
                continue
            if self._penetration(p) <= p.gap_tol:
                continue
            g = np.where(np.isfinite(p.g), p.g, 0.0)
            p.lam_mult = np.minimum(p.lam_mult + p.eps * g, 0.0)
            p.n_aug += 1
            again = True
        return again

    def _penetration(self, p: Pass) -> float:
        """Largest penetration of the pass's slaves (a distributed run takes the largest over the ranks)."""
        return float(np.max(-p.g[np.isfinite(p.g)], initial=0.0))

    @staticmethod
    def _active(p: Pass) -> np.ndarray:
        return p.g + p.lam_mult / p.eps <= 0.0

    def active_count(self) -> int:
        return int(sum(np.count_nonzero(self._active(p)) for p in self.passes))

    def coupled_dofs(self) -> np.ndarray:
        nodes = []
        for p in self.passes:
            act = self._active(p)
            nodes.append(p.slaves[act])
            if p.surface is not None:
                f = p.prev_facet[act]
                nodes.append(p.surface.faces[f[f >= 0]].ravel())
        nodes = np.unique(np.concatenate(nodes)) if nodes else np.zeros(0, int)
        nodes = nodes[nodes < self.N]
        return (3 * nodes[:, None] + np.arange(3)).ravel()

    # -- reports --------------------------------------------------------------------------------
    def step_report(self, x: np.ndarray, lam: float) -> dict:
        """Per pair: active contacts, minimum gap, force resultant; the contribution norms of the parts."""
        saved = [(p.g.copy(), p.force.copy(), p.state.copy()) for p in self.passes]
        r, K, parts = self.evaluate(x, lam, want_K=True, case=CASES["a"], want_parts=True)
        main, rot, curv, _ = parts
        full = main + rot + curv
        nf = sp.linalg.norm(full) if full.nnz else 0.0
        contrib = {"rotational": float(sp.linalg.norm(rot) / nf * 100) if nf > 0 and rot.nnz else 0.0,
                   "curvature": float(sp.linalg.norm(curv) / nf * 100) if nf > 0 and curv.nnz else 0.0}
        for p, kept in zip(self.passes, saved):  # forces and friction states of the converged iterate
            p.g, p.force, p.state = kept
        pairs = {}
        for p in self.passes:
            act = self._active(p)
            pairs[p.name] = {"active_contacts": int(act.sum()),
                             **({"stick": int(np.count_nonzero(act & (p.state == STICK))),
                                 "slip": int(np.count_nonzero(act & (p.state == SLIP)))} if p.mu > 0 else {}),
                             "min_gap": float(p.g.min()) if len(p.g) and np.isfinite(p.g.min()) else None,
                             "contact_force": p.force[act].sum(axis=0).tolist(),
                             **({"augmentations": p.n_aug, "max_penetration": float(np.max(-p.g[act],
                                                                                            initial=0.0))}
                                if p.augmented else {})}
        total_force = np.sum([v["contact_force"] for v in pairs.values()], axis=0).tolist()
        gaps = [v["min_gap"] for v in pairs.values() if v["min_gap"] is not None]
        return {"active_contacts": self.active_count(), "min_gap": min(gaps) if gaps else None,
                "contact_force": total_force, "contribution_percent": contrib, "pairs": pairs}

    def _node_fields(self, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        gap = np.full(n, np.nan)
        pressure = np.zeros(n)
        status = np.full(n, -1.0)
        for p in self.passes:
            s = p.slaves
            sel = s < n
            gap[s[sel]] = np.where(np.isfinite(p.g[sel]), p.g[sel], np.nan)
            act = self._active(p)
            status[s[sel]] = np.where(act[sel], 1.0, 0.0)
            fn = np.linalg.norm(p.force, axis=1) / np.maximum(p.area, 1e-300)
            pressure[s[sel]] = np.where(act[sel], fn[sel], 0.0)
        return gap, pressure, status

    def point_data(self, n_nodes: int) -> dict:
        """Gap, contact pressure and status (-1 not a slave, 0 inactive, 1 active) per deformable node."""
        gap, pressure, status = self._node_fields(self.n_ext)
        return {"gap": gap[:n_nodes], "contact_pressure": pressure[:n_nodes],
                "contact_status": status[:n_nodes]}

    def visual(self, lam: float):
        """Rigid bodies for the VTU files: points, cell blocks and point data of the appended points."""
        from .visual import rigid_visual

        return rigid_visual(self, lam)
