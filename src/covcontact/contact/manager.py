"""Contact pairs of a problem inside Newton: search, projection, element kernels, friction and Uzawa.

``ContactManager.evaluate(x, lam, committed, guess)`` is a function of its arguments (docs/theory.md,
section 10): it reads the committed history (friction history, the positions of the
last commit) and the starting point of the iteration (``guess``: contact points and Uzawa multipliers;
the committed state when omitted), and returns the element blocks and a new trial state. It writes into
neither state. The only thing it keeps is a cache of search candidates, valid while the slaves move less
than a quarter of the search margin and emptied by :meth:`begin_step`.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from . import nodal_gap, report
from .assembly import ElementBlocks
from .driver import EDGE, FACET, VERTEX, project_slaves
from .edge import edge_vertex_batch
from .edgelock import FREE, RELEASED, edge_point, inconsistent, new_locks
from .element import CASE_A, CASES
from .friction import HIST_SIZE, analytic_friction_batch, friction_batch, start_history, transfer_history
from .kernels import contact_batch
from .laws import is_active, linear_equivalents, uzawa_update
from .planar import segment_pass
from .reference import map_analytic, map_rigid_nodes
from .search import candidates
from .selfcontact import FRONT_COS, HOLD_COS, drop_excluded, facet_normals, slave_normals
from .setup import Numbering, Pass, make_passes
from .state import ContactState, PassState
from .surface import facet_sizes
from .tied import tied_blocks

_CASE_NAME = {v: k for k, v in CASES.items()}
#: self-contact projections are accepted this far outside a facet (in xi): the nodes on the boundary of an open
#: surface (the end of a tube) lie exactly on the boundary of the facets they touch, and round-off alone would
#: decide whether they have a contact point
SELF_TOL_INSIDE = 1e-4
#: frictional passes: how far outside its facet of the last Newton iterate (element coordinates) a slave keeps it
KEEP_BAND = 0.02
#: how far (element coordinates) beyond the master surface's free edge a slave keeps its facet of the last iterate:
#: enough for a slave resting on that edge, which Newton moves across by a hair, far less than a slave sliding off
BOUNDARY_BAND = 1e-3


@dataclass
class ContactEvaluation:
    """What one evaluation yields: the element blocks and, on request, the four tangent parts
    (main, rotational, curvature, second order) as blocks of their own."""

    blocks: ElementBlocks
    parts: list[ElementBlocks] | None = None


@dataclass
class _SearchCache:
    cand: tuple
    x: np.ndarray
    margin: float


class ContactManager:
    """All contact pairs of a problem."""

    def __init__(self, problem, system, tangent: str | None = None):
        self.problem = problem
        self.system = system
        self.num = Numbering(problem, system)
        self.N = self.num.N
        self.passes: list[Pass] = make_passes(self.num, problem, tangent)
        self.points = self.num.points  # segment-to-surface slave points (ids after the extended nodes)
        self.symmetric = not any(p.mu > 0.0 for p in self.passes)
        self.timing = {"search": 0.0, "projection": 0.0}
        self._cache: list[_SearchCache | None] = [None] * len(self.passes)
        # per pass: the friction histories moved onto new facets (``_facet_history``) for the committed state they
        # came from, so that the residuals of a step compute each once
        self._moved: list[tuple | None] = [None] * len(self.passes)
        self._rigid: tuple[float, np.ndarray] | None = None
        self.enabled = [True] * len(self.passes)  # pairs switched on (stages may switch them)
        # rigid bodies with a reference node: their nodes' rows and columns are mapped onto the node pair
        self.reference = list(getattr(system, "reference", []))
        self.owner = np.full(self.num.n_ext + self.points.count, -1, dtype=np.int64)
        index = {ref.name: i for i, ref in enumerate(self.reference)}
        for rb in self.num.rigid_meshes:
            if rb.name in index:
                off = self.num.rigid_offset[rb.name]
                self.owner[off: off + rb.mesh.n_nodes] = index[rb.name]
        self._ref_of_pass = [index.get(p.rigid, -1) if p.analytic is not None else -1 for p in self.passes]
        self._poses = []
        # the extended positions where the first step starts (its committed configuration: the state has none yet)
        xe = np.ascontiguousarray(np.vstack([system.X, self.num.rigid_positions(0.0)]))
        self._x_start = xe if not self.points.count else np.ascontiguousarray(np.vstack([xe, self.points.positions(xe)]))

    # -- state ------------------------------------------------------------------------------------
    def initial_state(self) -> ContactState:
        return ContactState([PassState.empty(p.ns) for p in self.passes])

    def begin_step(self) -> None:
        """A new load step: search every pass from scratch at its first evaluation."""
        self._cache = [None] * len(self.passes)

    def set_stage(self, motions: dict, pairs: dict[str, bool], friction: dict | None = None) -> None:
        """The rigid bodies' motions, the pairs switched on and the Coulomb coefficients of the frictional pairs in
        the current stage."""
        self.num.motions = dict(motions)
        for p in self.passes:
            if friction and p.pair in friction:
                p.mu = float(friction[p.pair])
        for p in self.passes:
            if p.analytic is not None:
                p.analytic.motion = motions[p.rigid]
        self.enabled = [pairs.get(p.pair, True) for p in self.passes]
        self._rigid = None
        self.begin_step()

    def switch(self, state: ContactState) -> ContactState:
        """``state`` with the history of the passes switched off cleared (a pair switched on again starts
        afresh)."""
        out = state.copy()
        for k, p in enumerate(self.passes):
            if not self.enabled[k]:
                out.passes[k] = PassState.empty(p.ns)
        return out

    # -- positions --------------------------------------------------------------------------------
    def extended(self, x: np.ndarray, lam: float) -> np.ndarray:
        """Deformable positions x (N, 3) followed by the rigid-mesh nodes at load factor lam, then the
        segment-to-surface slave points."""
        xe = self._nodes(x, lam)
        if not self.points.count:
            return xe
        return np.ascontiguousarray(np.vstack([xe, self.points.positions(xe)]))

    def _nodes(self, x: np.ndarray, lam: float) -> np.ndarray:
        if not self.num.rigid_meshes:
            return np.ascontiguousarray(x)
        if self.reference:  # the reference bodies' poses come from x: no cache
            self._set_poses(x)
            return np.ascontiguousarray(np.vstack([x, self.num.rigid_positions(lam)]))
        if self._rigid is None or self._rigid[0] != lam:
            self._rigid = (lam, self.num.rigid_positions(lam))
        return np.ascontiguousarray(np.vstack([x, self._rigid[1]]))

    # -- evaluation -------------------------------------------------------------------------------
    def evaluate(self, x: np.ndarray, lam: float, committed: ContactState, guess: ContactState | None = None,
                 want_K: bool = True, case: int | None = None, want_parts: bool = False,
                 pairs: tuple[str, ...] | None = None):
        """Element blocks and the trial state at deformable positions x (N, 3) and load factor lam.

        ``case`` overrides every pass's tangent case; ``want_parts`` also returns the four parts (of the
        frictionless element, for the contribution norms); ``pairs`` limits the evaluation to the named pairs
        (of those switched on).
        """
        guess = committed if guess is None else guess
        if self.reference:
            self._set_poses(x)
        xe = self.extended(x, lam)
        ev = ContactEvaluation(ElementBlocks(self.N, points=self.points),
                               [ElementBlocks(self.N, points=self.points) for _ in range(4)] if want_parts else None)
        trial = ContactState([], xe)
        for k, p in enumerate(self.passes):
            c, g0 = committed.passes[k], guess.passes[k]
            t = PassState.empty(p.ns)
            if not self.enabled[k] or (pairs is not None and p.pair not in pairs):
                trial.passes.append(t)
                continue
            t.multiplier = g0.multiplier.copy()
            t.n_aug = g0.n_aug
            pcase = p.case if case is None else case
            if p.tied:
                self._tied_pass(p, xe, t, want_K, want_parts, ev)
            elif p.curve is not None:  # node-to-segment contact in the plane
                segment_pass(self, p, xe, pcase, t, want_K, want_parts, ev, c, g0,
                             self._x_start if committed.x is None else committed.x)
            elif p.surface is not None:
                self._mesh_pass(k, p, xe, pcase, c, g0, t, committed.x, want_K, want_parts, ev)
            else:
                self._analytic_pass(p, xe, lam, pcase, c, t, want_K, want_parts, ev)
            trial.passes.append(t)
        return ev, trial

    def _search(self, k: int, p: Pass, xe: np.ndarray) -> tuple:
        cache = self._cache[k]
        if cache is not None and float(np.abs(xe - cache.x).max()) < 0.25 * cache.margin:
            return cache.cand
        t0 = time.perf_counter()
        sizes = facet_sizes(xe, p.surface.faces)
        margin = float(sizes.max()) if len(sizes) else 0.0
        cand = candidates(xe, p.surface, xe[p.slaves], margin)
        self._cache[k] = _SearchCache(cand, xe.copy(), margin)
        self.timing["search"] += time.perf_counter() - t0
        return cand

    def _mesh_pass(self, k, p: Pass, xe, case, c: PassState, g0: PassState, t: PassState, x_commit, want_K,
                   want_parts, ev: ContactEvaluation) -> None:
        cand = self._search(k, p, xe)
        t0 = time.perf_counter()
        if p.self_contact:  # every facet near the slave is a candidate: no walks into its own neighbourhood
            fn = facet_normals(xe, p.surface.faces)
            own = slave_normals(xe, p.surface, p.slaves, p.own_patch, fn)
            ptr, fac = drop_excluded(np.ascontiguousarray(cand[0], np.int64), np.ascontiguousarray(cand[1], np.int64),
                                     p.exclude, own, fn, np.where(g0.facet >= 0, HOLD_COS, 0.0))
            res = project_slaves(xe, p.surface, xe[p.slaves], ptr, fac, g0.facet, g0.xi, max_hops=0,
                                 tol_inside=SELF_TOL_INSIDE, tol_keep=KEEP_BAND if p.mu > 0.0 else None)
            self._face_to_face(own, res, g0.facet >= 0)
        else:
            # a frictional slave keeps its facet of the last iterate up to KEEP_BAND outside it (self-contact too): across a master edge
            # the friction history moves to the other facet's frame, and a slave resting on the edge (conforming meshes
            # pressed together) would cycle between the two (frictionless slaves have the edge locks instead)
            # and every slave keeps its facet up to BOUNDARY_BAND beyond the master's free edge: one resting on that
            # edge (a tool as long as the sheet it presses) otherwise drops out and comes back, and Newton cycles
            res = project_slaves(xe, p.surface, xe[p.slaves], cand[0], cand[1], g0.facet, g0.xi,
                                 tol_keep=KEEP_BAND if p.mu > 0.0 else None,
                                 tol_boundary=KEEP_BAND if p.mu > 0.0 else BOUNDARY_BAND)
        self.timing["projection"] += time.perf_counter() - t0
        if p.mu == 0.0 and not p.self_contact:
            t.edge_lock = self._hold(p, xe, res, g0)
        ok = res.kind != 0
        t.facet = np.where(ok, res.facet, -1).astype(np.int64)
        t.xi = np.where(ok[:, None], res.xi, 0.0)
        t.gap = np.where(ok, res.g, np.inf)
        t.hist_facet = t.facet.copy()
        if p.nodal:
            nodal_gap.mesh_pass(self, p, xe, res, case, t, want_K, want_parts, ev)
            return
        nen = p.surface.nen
        nd = 3 * (nen + 1)
        eps, eps_t = p.eps, p.eps_t
        # the smoothed law (or a pressure-overclosure curve) as the linear one with its traction and slope at each
        # gap (the same g the kernels compute from the projection)
        if p.law is not None:
            on, eps_s, lam_s = p.law.equivalents(np.where(ok, res.g, np.inf), p.area)
            active = ok & on
        else:
            active = ok & is_active(res.g, t.multiplier, eps, p.band)
            eps_s, lam_s = linear_equivalents(res.g, t.multiplier, eps, p.band) if p.band != 0.0 else \
                (eps, t.multiplier)
        facet_points = active & (res.kind == FACET)
        if p.law is not None:  # (a curve's tension at a clearance: the kernels' linear law, split in two, below)
            pull = facet_points & (lam_s + eps_s * np.where(ok, res.g, 0.0) > 0.0)
            facet_points &= ~pull
            self._pull(p, xe, res, np.flatnonzero(pull), eps_s, lam_s, case, t, want_K, want_parts, ev)
        idx = np.flatnonzero(facet_points)
        if idx.size:
            conn = np.hstack([p.surface.faces[res.facet[idx]], p.slaves[idx][:, None]])
            xi = np.ascontiguousarray(res.xi[idx])
            eps = np.ascontiguousarray(eps_s[idx])
            lam_k = np.ascontiguousarray(lam_s[idx])
            g = np.zeros(idx.size)
            R = np.zeros((idx.size, nd))
            K = np.zeros((idx.size, nd, nd))
            facet_conn = np.ascontiguousarray(conn[:, :nen])
            slaves = np.ascontiguousarray(conn[:, nen])
            if p.mu > 0.0:
                hist = self._facet_history(k, p, c, idx, t.facet[idx], xi,
                                           self._x_start if x_commit is None else x_commit)
                hist_out = np.zeros_like(hist)
                state = np.zeros(idx.size, dtype=np.int64)
                friction_batch(xe, facet_conn, slaves, xi, eps, np.ascontiguousarray(eps_t[idx]),
                               np.full(idx.size, p.mu), hist, R, K, hist_out, g, state, lam_k)
                t.hist[idx] = hist_out
                t.status[idx] = state
            if p.mu == 0.0 or want_parts:
                Rn = np.zeros((idx.size, nd))
                Kn = np.zeros((idx.size, nd, nd))
                P = np.zeros((idx.size, 4, nd, nd)) if want_parts else np.zeros((1, 4, 1, 1))
                contact_batch(xe, facet_conn, slaves, xi, eps, case, want_parts, Rn, Kn, P, g, lam_k)
                if p.mu == 0.0:
                    R, K = Rn, Kn
                if want_parts:
                    for j in range(4):
                        ev.parts[j].add(conn, np.zeros_like(R), P[:, j])
            t.gap[idx] = g
            t.force[idx] = -R[:, -3:]
            self._add(ev.blocks, conn, R, K if want_K else None, xe)
        # edge and vertex points: the distance to the closest point of the facet boundary (frictionless)
        idx = np.flatnonzero(active & ((res.kind == EDGE) | (res.kind == VERTEX)))
        if idx.size:
            conn = np.hstack([p.surface.faces[res.facet[idx]], p.slaves[idx][:, None]])
            R, K, t.gap[idx] = edge_vertex_batch(xe, conn, res.xi[idx], res.g[idx], res.kind[idx] == VERTEX,
                                                 np.broadcast_to(eps_s, (p.ns,))[idx],
                                                 np.broadcast_to(lam_s, (p.ns,))[idx])
            t.force[idx] = -R[:, -3:]
            self._add(ev.blocks, conn, R, K if want_K else None, xe)
            if want_parts:
                ev.parts[0].add(conn, np.zeros_like(R), K)

    def _pull(self, p: Pass, xe, res, idx, eps_s, lam_s, case, t: PassState, want_K, want_parts,
              ev: ContactEvaluation) -> None:
        """Facet points where a pressure-overclosure curve pulls (sigma = lam' + eps' g > 0: CalculiX's tension at a
        clearance). The kernels act only where their linear law pushes, but their residual and every tangent part
        are linear in (eps', lam') (eps' g_e = lam' + eps' g and each term carries eps' or eps' g_e), so the pull is
        the sum of two pushing laws with the same g: (2 eps', -2 eps' g - c) and (-eps', lam' + 2 eps' g + c), both
        with g_e < 0 for c = eps' |g| + |lam'| > 0. Frictionless (a pull carries no friction)."""
        if not idx.size:
            return
        nen = p.surface.nen
        nd = 3 * (nen + 1)
        conn = np.hstack([p.surface.faces[res.facet[idx]], p.slaves[idx][:, None]])
        facet_conn = np.ascontiguousarray(conn[:, :nen])
        slaves = np.ascontiguousarray(conn[:, nen])
        xi = np.ascontiguousarray(res.xi[idx])
        e, lam, g0 = eps_s[idx], lam_s[idx], res.g[idx]
        c = e * np.abs(g0) + np.abs(lam) + 1e-300
        R = np.zeros((idx.size, nd))
        K = np.zeros((idx.size, nd, nd))
        P = np.zeros((idx.size, 4, nd, nd)) if want_parts else np.zeros((1, 4, 1, 1))
        g = np.zeros(idx.size)
        for e_j, l_j in ((2.0 * e, -2.0 * e * g0 - c), (-e, lam + 2.0 * e * g0 + c)):
            Rj = np.zeros((idx.size, nd))
            Kj = np.zeros((idx.size, nd, nd))
            Pj = np.zeros_like(P)
            contact_batch(xe, facet_conn, slaves, xi, np.ascontiguousarray(e_j), case, want_parts, Rj, Kj, Pj, g,
                          np.ascontiguousarray(l_j))
            R += Rj
            K += Kj
            P += Pj
        if want_parts:
            for j in range(4):
                ev.parts[j].add(conn, np.zeros_like(R), P[:, j])
        t.gap[idx] = g
        t.force[idx] = -R[:, -3:]
        t.status[idx] = 0
        t.hist[idx] = 0.0
        self._add(ev.blocks, conn, R, K if want_K else None, xe)

    @staticmethod
    def _face_to_face(own: np.ndarray, res, held: np.ndarray) -> None:
        """Self-contact (:mod:`.selfcontact`): facet points whose normal does not oppose the slave's own normal
        ``own``, edge and vertex points the slave does not lie in front of, dropped (``held``: slaves with a
        contact point at the last iterate, which keep theirs up to HOLD_COS more)."""
        cos = np.einsum("si,si->s", own, res.normal) - np.where(held, HOLD_COS, 0.0)
        bad = (res.kind != 0) & ((cos >= 0.0) | ((res.kind != FACET) & (cos > -FRONT_COS)))
        res.kind[bad] = 0
        res.facet[bad] = -1
        res.g[bad] = np.inf
        res.xi[bad] = 0.0

    def _tied_pass(self, p: Pass, xe, t: PassState, want_K, want_parts, ev: ContactEvaluation) -> None:
        """Tied slaves: a vector penalty to their fixed tie points (:mod:`.tied`); gap: the points' distance."""
        idx = np.flatnonzero(p.tie_facet >= 0)
        faces = (p.curve.segments if p.curve is not None else p.surface.faces)[p.tie_facet[idx]]
        R, K, d = tied_blocks(xe, faces, p.tie_N[idx], xe[p.slaves[idx]], p.eps[idx], want_K or want_parts)
        conn = np.hstack([faces, p.slaves[idx][:, None]])
        t.facet[idx] = p.tie_facet[idx]
        t.gap[idx] = np.linalg.norm(d, axis=1)
        t.force[idx] = -R[:, -3:]
        self._add(ev.blocks, conn, R, K if want_K else None, xe)
        if want_parts:
            ev.parts[0].add(conn, np.zeros_like(R), K)

    @staticmethod
    def _hold(p: Pass, xe: np.ndarray, res, g0: PassState) -> np.ndarray:
        """Edge locks (:mod:`.edgelock`): new ones (or pending marks) where a slave crossed a valley edge or
        corner since the last iterate; the contact point of every held slave replaced in ``res`` by its point on
        the edge or corner. Returns the locks."""
        lock = g0.edge_lock.copy()
        xs = xe[p.slaves]
        idx, codes = new_locks(p.surface, xe, xs, lock, res.facet, res.xi, res.g, res.kind, g0.facet, g0.xi)
        lock[idx] = codes
        for s in np.flatnonzero(lock >= 0):
            res.facet[s], res.xi[s], res.g[s], res.normal[s], res.kind[s] = edge_point(p.surface, xe, lock[s], xs[s])
        return lock

    def _set_poses(self, x: np.ndarray) -> None:
        """The reference bodies' poses at the system positions x: rigid nodes and analytic surfaces follow."""
        self._poses = [ref.pose(x) for ref in self.reference]
        for ref, pose in zip(self.reference, self._poses):
            self.num.motions[ref.name] = pose
        for k, p in enumerate(self.passes):
            if self._ref_of_pass[k] >= 0:
                p.analytic.motion = self._poses[self._ref_of_pass[k]]

    def _add(self, blocks: ElementBlocks, conn, R, K, xe) -> None:
        """Add element blocks, their rows and columns of reference bodies' nodes mapped onto the node pairs."""
        if not self.reference:
            blocks.add(conn, R, K)
            return
        if self.points.count and conn.max() >= self.points.offset:  # onto nodes first: a patch point of a rigid mesh
            conn, R, K = self.points.expand(conn, R, K)
        for c, r, k in map_rigid_nodes(conn, R, K, self.owner, self.reference, self._poses, xe):
            blocks.add(c, r, k)

    def _facet_history(self, k: int, p: Pass, c: PassState, idx, facets, xi, x_commit) -> np.ndarray:
        """Committed friction history of slaves ``idx`` moved onto their current facets; a slave new to contact (no
        history) sticks from where the step found it: its projection on its facet in the committed configuration,
        zero traction (so a contact that closes in a step carries friction in that step already).

        What a slave's history becomes on a facet depends on the committed state only (``xi``, the current contact
        point, is where the projections start), so each (slave, facet) is worked out once per committed state and
        reused by the step's later residuals."""
        hist = c.hist[idx].copy()
        moved = c.hist_facet[idx] != facets
        if x_commit is None:
            hist[moved & (hist[:, -1] > 0.0)] = 0.0
            return hist
        memo = self._moved[k]
        if memo is None or memo[0] is not c or memo[1] is not x_commit or memo[2] is not p.eps_t:
            memo = self._moved[k] = (c, x_commit, p.eps_t, {})
        done = memo[3]
        for j in np.flatnonzero(moved | (hist[:, -1] == 0.0)):
            key = (int(idx[j]), int(facets[j]))
            h = done.get(key)
            if h is None:
                h = done[key] = self._moved_history(p, hist[j], bool(moved[j]), int(idx[j]), int(facets[j]), xi[j],
                                                    x_commit)
            hist[j] = h
        return hist

    @staticmethod
    def _moved_history(p: Pass, h, moved: bool, i: int, facet: int, xi, x_commit) -> np.ndarray:
        """The history ``h`` of slave ``i`` on ``facet``: started where it has none, transferred where it was kept on
        another facet."""
        xyz = x_commit[p.surface.faces[facet]]
        eps_t = float(p.eps_t[i])
        if h[-1] == 0.0:
            h = start_history(xyz, x_commit[p.slaves[i]], xi, eps_t)
        if h[-1] > 0.0 and moved:
            try:  # (the slave's tangential penalty: an old point far off the new facet is anchored on it)
                h = transfer_history(h, xyz, xi, eps_t)
            except ValueError:
                h = np.zeros_like(h)
        return h

    def _analytic_pass(self, p: Pass, xe, lam, case, c: PassState, t: PassState, want_K, want_parts,
                       ev: ContactEvaluation) -> None:
        if p.nodal:
            if self.reference and self._ref_of_pass[next(i for i, q in enumerate(self.passes) if q is p)] >= 0:
                raise ValueError(f"contact {p.pair}: gap = \"nodal\" is not for a tool pressed with a force")
            nodal_gap.analytic_pass(self, p, xe, lam, _CASE_NAME[case], t, want_K, want_parts, ev)
            return
        xs = np.ascontiguousarray(xe[p.slaves])
        mult = t.multiplier if p.augmented else None
        ns = len(xs)
        if p.mu > 0.0:
            origin, frame = p.analytic.placement(lam)
            R = np.zeros((ns, 3))
            K = np.zeros((ns, 3, 3))
            hist_out = np.zeros((ns, HIST_SIZE))
            analytic_friction_batch(p.analytic.kind, origin, frame, float(p.analytic.radius),
                                    float(p.analytic.sigma), p.analytic.prof, xs, np.ascontiguousarray(p.eps),
                                    np.ascontiguousarray(p.eps_t), np.full(ns, p.mu), c.hist.copy(), R, K,
                                    hist_out, t.gap, t.xi, t.status, np.ascontiguousarray(t.multiplier), p.band)
        else:
            out = p.analytic.evaluate(xs, p.eps, parts=_CASE_NAME[case], lam=lam, multiplier=mult, band=p.band)
            R, K, t.gap, t.xi = out.residual, out.tangent, out.gap, out.xi
        active = is_active(t.gap, t.multiplier, p.eps, p.band)
        if p.mu > 0.0:
            t.hist[active] = hist_out[active]
        t.force = -R
        idx = np.flatnonzero(active)
        if idx.size == 0:
            return
        conn = p.slaves[idx][:, None]
        b = self._ref_of_pass[next(i for i, q in enumerate(self.passes) if q is p)] if self.reference else -1
        if b >= 0:
            ev.blocks.add(*map_analytic(p.slaves[idx], xs[idx], R[idx], K[idx] if want_K else None,
                                        self.reference[b], self._poses[b]))
        else:
            ev.blocks.add(conn, R[idx], K[idx] if want_K else None)
        if want_parts:
            tan = {name: p.analytic.evaluate(xs, p.eps, parts=name, lam=lam, multiplier=mult,
                                             band=p.band).tangent[idx]
                   for name in ("d", "c", "exact")}
            zero = np.zeros((idx.size, 3))
            ev.parts[0].add(conn, zero, tan["d"])
            ev.parts[2].add(conn, zero, tan["c"] - tan["d"])
            ev.parts[3].add(conn, zero, tan["exact"] - tan["c"])

    # -- Uzawa ------------------------------------------------------------------------------------
    def augment(self, trial: ContactState) -> ContactState | None:
        """The edge locks that disagree with the free projection released (:meth:`_release`); else the Uzawa
        update lambda <- <lambda + eps_N g> of every augmented pass whose largest penetration exceeds its
        tolerance (at most ``max_aug`` times per step): the new trial, or None when no pass needs another
        Newton solve. ``trial`` itself is not changed."""
        new = self._release(trial)
        if new is not None:  # Newton goes on with the released edge locks first
            return new
        for k, p in enumerate(self.passes):
            t = trial.passes[k]
            if not p.augmented or t.n_aug >= p.max_aug or self._penetration(p, t) <= p.gap_tol:
                continue
            new = new or trial.copy()
            q = new.passes[k]
            q.multiplier = uzawa_update(t.multiplier, t.gap, p.eps, p.band)
            q.n_aug += 1
        return new

    def _release(self, trial: ContactState) -> ContactState | None:
        """The trial with the edge locks released that disagree with the free projection at its positions
        (:func:`.edgelock.inconsistent`), or None when all agree."""
        new = None
        for k, p in enumerate(self.passes):
            t = trial.passes[k]
            held = np.flatnonzero(t.edge_lock >= 0)
            if not held.size or p.surface is None or trial.x is None:
                continue
            xe = trial.x
            cand = candidates(xe, p.surface, xe[p.slaves[held]], float(facet_sizes(xe, p.surface.faces).max()))
            free = project_slaves(xe, p.surface, xe[p.slaves[held]], cand[0], cand[1], t.facet[held], t.xi[held],
                                  tol_inside=0.0)
            normal = np.zeros((held.size, 3))
            for j, s in enumerate(held):
                normal[j] = edge_point(p.surface, xe, t.edge_lock[s], xe[p.slaves[s]])[3]
            bad = held[inconsistent(t.edge_lock[held], t.gap[held], normal, free.kind, free.g, free.normal)]
            if bad.size:
                new = new or trial.copy()
                new.passes[k].edge_lock[bad] = RELEASED
        return new

    def _penetration(self, p: Pass, t: PassState) -> float:
        """Largest penetration of the pass's slaves (a distributed run takes the largest over the ranks)."""
        return float(np.max(-t.gap[np.isfinite(t.gap)], initial=0.0))

    def start_step(self, committed: ContactState) -> ContactState:
        """The starting trial of a new step: the committed state with the Uzawa counters at zero."""
        t = committed.copy()
        for p in t.passes:
            p.n_aug = 0
            p.edge_lock[p.edge_lock < FREE] = FREE  # released and pending marks last one step
        return t

    # -- queries on a state -----------------------------------------------------------------------
    def active_mask(self, k: int, state: ContactState) -> np.ndarray:
        s = state.passes[k]
        if self.passes[k].tied:
            return s.facet >= 0
        if self.passes[k].law is not None:
            return self.passes[k].law.traction(s.gap, self.passes[k].area)[0]
        if self.passes[k].nodal:  # a point carries force where a node of its facet is active, whatever its own gap
            return np.any(s.force != 0.0, axis=1)
        return is_active(s.gap, s.multiplier, self.passes[k].eps, self.passes[k].band)

    def active_count(self, state: ContactState) -> int:
        return int(sum(np.count_nonzero(self.active_mask(k, state)) for k in range(len(self.passes))))

    def opened_closed(self, a: ContactState, b: ContactState) -> int:
        """Slave nodes whose contact opened or closed from state ``a`` to state ``b``."""
        return int(sum(np.count_nonzero(self.active_mask(k, a) != self.active_mask(k, b))
                       for k in range(len(self.passes))))

    def coupled_dofs(self, state: ContactState) -> np.ndarray:
        """Dofs of the deformable nodes of the active contact elements of ``state``."""
        nodes = []
        for k, p in enumerate(self.passes):
            act = self.active_mask(k, state)
            nodes.append(self.points.nodes(p.slaves[act]))
            if p.surface is not None:
                f = state.passes[k].facet[act]
                nodes.append(self.points.nodes(p.surface.faces[f[f >= 0]].ravel()))
            elif p.curve is not None:
                f = state.passes[k].facet[act]
                nodes.append(p.curve.segments[f[f >= 0]].ravel())
        nodes = np.unique(np.concatenate(nodes)) if nodes else np.zeros(0, int)
        nodes = nodes[nodes < self.N]
        return (3 * nodes[:, None] + np.arange(3)).ravel()

    # -- reports (covcontact.contact.report) -------------------------------------------------------
    def gather(self, rows: list) -> list[list]:
        """Per-rank lists of per-pass rows (one rank here; a distributed run gathers)."""
        return [rows]

    def global_norms(self, mats) -> list[float]:
        return report.frobenius_norms(mats)

    def step_report(self, x: np.ndarray, lam: float, state: ContactState) -> dict:
        return report.step_report(self, x, lam, state)

    def point_data(self, n_nodes: int, state: ContactState, fields: tuple | None = None,
                   per_pass: dict | None = None) -> dict:
        return report.point_data(self, n_nodes, state, fields, per_pass)

    def facet_fields(self, state: ContactState, nodal_pressure: np.ndarray | None = None) -> list:
        """(slave faces, mean contact pressure per facet) of every pass with a slave face set; ``nodal_pressure``
        the pressure of :meth:`node_fields` when the caller has it."""
        if nodal_pressure is None:
            nodal_pressure = self.node_fields(state)[1]
        return report.facet_pressure(self, state, nodal_pressure)

    def node_fields(self, state: ContactState, per_pass: dict | None = None):
        """(gap, pressure, status) over the extended node numbering (deformable nodes, then the nodes of rigid
        meshes), for the result files; ``per_pass`` receives each pass's own."""
        return report.node_fields(self, self.num.n_ext, state, per_pass)


__all__ = ["CASE_A", "ContactEvaluation", "ContactManager"]
