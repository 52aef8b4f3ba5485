"""Distributed model: replicated state, distributed work.

Every rank loads the whole problem and keeps the full node arrays, loads, Dirichlet data and displacement
vector u. Each rank assembles only its own elements (bodies built from its cells; nodes stay global) and
its own contact slaves, so the compiled element and contact loops run unchanged on the local part. The
residual is summed over the ranks into a replicated vector; the tangent stays distributed: a
:class:`DistMatrix` holds this rank's share, which the PETSc backend hands to one MPIAIJ matrix.
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np
import scipy.sparse as sp
from numba import njit

from ..assembly.pattern import Pattern
from ..assembly.system import BodyBlock, InvertedElementError, System, make_solid
from ..contact.assembly import ElementBlocks
from ..elements.base import SolidStress
from ..elements.follower import follower_set
from ..solvers.model import Model, adjust_once
from ..solvers.stages import StagePlan
from ..solvers.state import State
from .comm import gather_all, share_cores, sum_all
from .partition import DofLayout, node_owners, rcb


class Structure:
    """Where this rank's share of the tangent goes in PETSc (built once per partition).

    Attributes:
        keep: indices into the local pattern's data of the entries this rank may fill.
        rows, cols: their PETSc row and column (int32/int64 as PETSc's index type wants).
        bc_data: the pattern data positions in a constrained row or column (zeroed by the elimination).
        diag: PETSc dofs of the constrained dofs this rank owns (they get the unit diagonal).
    """

    def __init__(self, pattern: Pattern, touched: np.ndarray, constrained: np.ndarray, layout: DofLayout):
        # one compiled pass (1.3 s of whole-array numpy at 2e5 dofs before)
        self.keep, _, self.bc_data, self.rows, self.cols = _structure_entries(
            pattern.indptr, pattern.indices, touched, constrained, layout.to_petsc)
        owned = layout.owned
        self.diag = layout.to_petsc[owned[constrained[owned]]]
        self.layout = layout


@njit(cache=True)
def _structure_entries(indptr, indices, touched, constrained, to_petsc):
    """The pattern's entries in rows of touched nodes: their data positions, whether they lie in a constrained
    row or column, the positions of those, and their PETSc rows and columns (Structure's arrays)."""
    n = indptr.size - 1
    m = 0
    for i in range(n):
        if touched[i // 3]:
            m += indptr[i + 1] - indptr[i]
    keep = np.empty(m, np.int64)
    bc = np.empty(m, np.bool_)
    rows = np.empty(m, to_petsc.dtype)
    cols = np.empty(m, to_petsc.dtype)
    k = 0
    nbc = 0
    for i in range(n):
        if not touched[i // 3]:
            continue
        ci = constrained[i]
        pi = to_petsc[i]
        for p in range(indptr[i], indptr[i + 1]):
            j = indices[p]
            keep[k] = p
            rows[k] = pi
            cols[k] = to_petsc[j]
            b = ci or constrained[j]
            bc[k] = b
            nbc += b
            k += 1
    bc_data = np.empty(nbc, np.int64)  # pattern data positions zeroed by the elimination
    q = 0
    for k in range(m):
        if bc[k]:
            bc_data[q] = keep[k]
            q += 1
    return keep, bc, bc_data, rows, cols


class DistMatrix:
    """This rank's share of the global tangent; the global matrix is the sum over the ranks.

    ``body`` is the CSR of the local elements on the local pattern, ``contact`` the CSR of the local
    contact pairs (or None). After :meth:`eliminate` the rows and columns of constrained dofs are zero and
    the unit diagonal is added once, by the owner of each dof. ``K @ v`` is the global product, replicated.
    """

    def __init__(self, comm, structure: Structure, body: sp.csr_matrix, contact: sp.csr_matrix | None,
                 constrained: np.ndarray):
        self.comm = comm
        self.structure = structure
        self.layout = structure.layout
        self.body = body
        self.contact = contact if contact is not None and contact.nnz else None
        self.constrained = constrained
        self.eliminated = False
        self.shape = body.shape

    def __matmul__(self, v: np.ndarray) -> np.ndarray:
        y = self.body @ v
        if self.contact is not None:
            y = y + self.contact @ v
        y = sum_all(self.comm, y)
        if self.eliminated:
            y[self.constrained] += v[self.constrained]
        return y

    def eliminate(self) -> DistMatrix:
        """Zero the constrained rows and columns (unit diagonal added by the owners); in place."""
        if self.eliminated:
            return self
        self.body.data[self.structure.bc_data] = 0.0
        if self.contact is not None:
            K = self.contact
            rows = np.repeat(np.arange(K.shape[0]), np.diff(K.indptr))
            K.data[self.constrained[rows] | self.constrained[K.indices]] = 0.0
        self.eliminated = True
        return self

    def body_values(self, out: np.ndarray | None = None) -> np.ndarray:
        """Values of the entries of ``structure.rows/cols`` (into ``out`` if given)."""
        data, keep = self.body.data, self.structure.keep
        out = np.empty(keep.size) if out is None else out
        if keep.size == data.size:  # every entry (one rank): keep is 0, 1, ...
            np.copyto(out, data)
        else:
            np.take(data, keep, out=out)
        return out

    def add_mass(self, M: sp.csr_matrix, c: float, cache: dict, scale: float = 1.0) -> DistMatrix:
        """``scale`` K + ``c`` M in place (the tangent of a dynamic step): this rank scales its share and adds
        the mass of its own elements (``M.local`` of a :class:`ReplicatedMass`; all of M on one rank) into its
        body entries, so that the sum over the ranks holds the mass once. ``cache``: as for
        ``covcontact.solvers.dynamics.add_into``."""
        from ..solvers.dynamics import add_into

        if self.eliminated:
            raise ValueError("the mass joins a distributed tangent before its elimination")
        local = getattr(M, "local", None)
        if local is None:
            if self.comm.size > 1:
                raise ValueError("a distributed tangent needs the mass of this rank's elements "
                                 "(DistributedSystem.mass)")
            local = M
        self.body.data *= scale
        if self.contact is not None:
            self.contact.data *= scale
        add_into(self.body, local, c, cache)
        return self

    def block(self, mask: np.ndarray) -> sp.csr_matrix:
        """The global matrix's block on the dofs of ``mask`` (before the elimination), the same scipy matrix on
        every rank: the ranks' shares summed."""
        local = self.body[mask][:, mask]
        if self.contact is not None:
            local = local + self.contact[mask][:, mask]
        return sum(p.tocsr() for p in gather_all(self.comm, local.tocoo())).tocsr()

    def contact_triplets(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """PETSc rows, columns and values of the contact share (may repeat entries)."""
        K = self.contact
        if K is None:
            z = np.zeros(0, dtype=np.int64)
            return z, z, np.zeros(0)
        rows = np.repeat(np.arange(K.shape[0]), np.diff(K.indptr))
        t = self.layout.to_petsc
        return t[rows], t[K.indices.astype(np.int64)], K.data


class ReplicatedMass(sp.csr_matrix):
    """The dof mass matrix of a distributed run: the whole matrix on every rank (the vectors are replicated:
    the dynamic residual, the energies and the start's equilibrium use it as a serial run does) and, as
    ``local``, the mass of this rank's elements alone (couplings within its local pattern): its share of the
    dynamic tangent."""

    local: sp.csr_matrix | None = None


class PartBody:
    """A body of which this rank assembles some cells; ``stress`` gathers the fields of all ranks."""

    def __init__(self, local, elements: np.ndarray, n_elements: int, comm):
        self.local = local
        self.elements = elements  # global element ids of the local cells
        self.n_total = n_elements
        self.comm = comm

    def __getattr__(self, name):
        return getattr(self.local, name)

    def stress(self, u: np.ndarray, state: dict | None = None) -> SolidStress:
        """The body's stress fields (global element order), on every rank (collective)."""
        st = self.local.stress(u, state)
        els, flat = self.local.incidence()
        n = self.local.n_nodes
        sums = np.zeros((n, 7))
        for I in range(6):
            sums[:, I] = np.bincount(flat, weights=st.cauchy[els, I], minlength=n)
        sums[:, 6] = np.bincount(flat, minlength=n)
        sums = sum_all(self.comm, sums)
        fields = np.hstack([st.cauchy, st.pk2, st.green_lagrange, st.von_mises[:, None]])
        full = np.empty((self.n_total, fields.shape[1]))
        for idx, f in gather_all(self.comm, (self.elements, fields)):
            full[idx] = f
        nodal = sums[:, :6] / np.maximum(sums[:, 6], 1.0)[:, None]
        return SolidStress(cauchy=np.ascontiguousarray(full[:, :6]), pk2=np.ascontiguousarray(full[:, 6:12]),
                           green_lagrange=np.ascontiguousarray(full[:, 12:18]), cauchy_nodal=nodal,
                           von_mises=np.ascontiguousarray(full[:, 18]))


    def plastic_fields(self, state: dict) -> dict[str, np.ndarray]:
        """The plastic cell fields of all ranks in global element order (collective)."""
        mine = self.local.plastic_fields(state)
        out = {}
        for key in sorted(mine):
            full = np.empty(self.n_total)
            for idx, f in gather_all(self.comm, (self.elements, mine[key])):
                full[idx] = f
            out[key] = full
        return out


class DistributedSystem(System):
    """The System of one rank: global numbering, loads and Dirichlet data; local elements only.

    ``blocks[k].solid`` is a :class:`PartBody` (its ``stress`` is collective); the local pattern couples
    only the nodes of local elements.
    """

    def __init__(self, bodies, loads, dirichlet, comm):
        bodies = list(bodies)
        self.bodies = {b.name: b for b in bodies}
        self.loads, self.dirichlet = list(loads), list(dirichlet)
        self.comm = comm
        rank, size = comm.rank, comm.size
        offsets, offset = [], 0
        for body in bodies:
            offsets.append(offset)
            offset += body.mesh.n_nodes
        self.n_nodes = offset
        self.n_deformable = offset
        self.reference = []  # rigid bodies with reference nodes are refused in distributed runs
        self.n_dofs = 3 * offset
        self.X = np.zeros((self.n_nodes, 3))
        for off, body in zip(offsets, bodies):
            self.X[off: off + body.mesh.n_nodes] = body.mesh.points
        cells = [b.cells + off for off, body in zip(offsets, bodies) for b in body.mesh.blocks]
        centroids = np.vstack([self.X[c].mean(axis=1) for c in cells])
        weights = np.concatenate([np.full(len(c), float(c.shape[1]) ** 2) for c in cells])
        part = rcb(centroids, weights, size)
        block_parts = np.split(part, np.cumsum([len(c) for c in cells])[:-1])
        parts = np.split(part, np.cumsum([body.mesh.n_cells for body in bodies])[:-1])
        self.blocks: list[BodyBlock] = []
        local_cells = [c[p == rank] for c, p in zip(cells, block_parts)]
        for off, body, p in zip(offsets, bodies, parts):
            elements = np.flatnonzero(p == rank)
            local = make_solid(body, elements)
            self.blocks.append(BodyBlock(body.name, off, body.mesh.n_nodes,
                                         PartBody(local, elements, body.mesh.n_cells, comm)))
        self.element_parts = parts
        self.pattern = Pattern(self.n_nodes, local_cells)
        self.owner = node_owners(self.n_nodes, cells, block_parts)
        self.layout = DofLayout.from_owners(self.owner, rank, size, self.X)
        self._build_loads()
        self._build_dirichlet()
        self._touched = np.zeros(self.n_nodes, dtype=bool)
        for c in local_cells:
            self._touched[c.ravel()] = True
        self.structure = Structure(self.pattern, self._touched, self.constrained, self.layout)

    def set_constraints(self, constrained: np.ndarray) -> None:
        old = getattr(self, "constrained", None)
        super().set_constraints(constrained)
        # a later stage freed dofs: the elimination structure follows (the same constraints keep it, and with
        # it the solver's analysis; building it takes 1 s at 2e5 dofs)
        if hasattr(self, "structure") and not np.array_equal(old, self.constrained):
            self.structure = Structure(self.pattern, self._touched, self.constrained, self.layout)

    def local_internal(self, u: np.ndarray, committed: list[dict], guess: list[dict], want_K: bool = True):
        """This rank's share of the internal forces (n_dofs,), tangent data (pattern.nnz,) or None, and the
        trial element history of its elements (history from ``committed``, local iterations started from
        ``guess``; neither changed).

        Raises InvertedElementError on every rank when an element of any rank is inverted.
        """
        data = np.zeros(self.pattern.nnz) if want_K else np.zeros(1)
        r = np.zeros(self.n_dofs)
        U = u.reshape(-1, 3)
        bad = (len(self.blocks), 0)
        trial = []
        for k, (blk, c, g) in enumerate(zip(self.blocks, committed, guess)):
            st = blk.solid.kernel_state(c, g)
            e = blk.solid.local.assemble(U[blk.offset: blk.offset + blk.n_nodes], data, r, self.pattern,
                                         node_offset=blk.offset, want_K=want_K, state=st)
            if e >= 0 and bad[0] == len(self.blocks):
                bad = (k, int(blk.solid.elements[e]))
            trial.append(blk.solid.trial_of(st))
        bad = min(gather_all(self.comm, bad))
        if bad[0] < len(self.blocks):
            raise InvertedElementError(self.blocks[bad[0]].name, bad[1])
        return r, (data if want_K else None), trial

    def energy(self, u: np.ndarray, state: list[dict] | None = None) -> float:
        U = u.reshape(-1, 3)
        state = self.new_state() if state is None else state
        e = sum(blk.solid.local.energy(U[blk.offset: blk.offset + blk.n_nodes], st)
                for blk, st in zip(self.blocks, state))
        return float(sum_all(self.comm, np.array([e]))[0])

    def mass(self, lumped: bool = False, massless: np.ndarray | None = None, **options) -> ReplicatedMass:
        """The whole dof mass matrix (as ``System.mass``) on every rank, with the mass of this rank's elements
        as its ``local``. ``massless`` (a redistributed mass) is the same on every rank: the contact nodes of
        all ranks' slaves (``covcontact.solvers.dynamics.contact_nodes`` joins them through
        ``DistributedModel.any_over_ranks``). ``options``: those of ``System.mass`` and
        ``covcontact.elements.mass.assemble_mass`` (element by element)."""
        from ..elements.mass import assemble_mass, dof_matrix, element_masses

        M = ReplicatedMass(super().mass(lumped, massless, **options))
        if self.comm.size == 1:
            M.local = M
            return M
        parts = []
        for blk, body in zip(self.blocks, self.bodies.values()):
            elements = blk.solid.elements
            for _, idx, material, cell_type in body.material_parts(elements):
                cells = body.mesh.cells_of(elements[idx])[1]
                parts.append((cells + blk.offset, element_masses(cell_type, body.mesh.points, cells,
                                                                 material.density)))
        lump = lumped or massless is not None
        M.local = dof_matrix(assemble_mass(self.n_nodes, parts, lump, massless, **options))
        return M

    def eliminate(self, K):
        """Dirichlet elimination of a DistMatrix (in place); a scipy matrix as in the serial System."""
        if isinstance(K, DistMatrix):
            return K.eliminate()
        return super().eliminate(K)


class DistributedModel(Model):
    """The Model of one rank of a distributed run (``mpiexec -n N covcontact run ... --solver petsc``).

    Same interface as :class:`covcontact.solvers.model.Model`; ``evaluate`` returns the replicated
    residual and a :class:`DistMatrix`. Collective: every rank calls the same methods in the same order.
    """

    distributed = True

    def __init__(self, problem, tangent: str | None = None, comm=None):
        if comm is None:
            from .comm import world

            comm = world()
        self.comm = comm
        self.rank, self.size = comm.rank, comm.size
        self.threads = share_cores(comm)
        self.problem = problem
        adjust_once(problem)
        self.system = DistributedSystem(problem.bodies, problem.loads, problem.dirichlet, comm)
        self.tangent = tangent
        from .contact import DistributedContact

        self.contact = DistributedContact(problem, self.system, tangent, comm)
        self.symmetric = self.contact.symmetric and all(b.solid.symmetric_tangent for b in self.system.blocks)
        self.stages = StagePlan(problem, self.system)
        self.followers = follower_set(self.stages, self.system)  # (every rank has them; rank 0 assembles them)
        if self.followers is not None:
            self.symmetric = False
        #: whether a stage is dynamic: ``evaluate`` then keeps the contact forces' share of the residual
        #: (``last_contact_residual``, summed over the ranks) for the energy account
        self.dynamic = hasattr(problem, "stage_dynamics") and any(
            problem.stage_dynamics(k) is not None for k in range(len(problem.stages) + 1))
        self.set_stage(State([], None))

    @property
    def is_root(self) -> bool:  # type: ignore[override]
        return self.rank == 0

    @property
    def layout(self) -> DofLayout:
        return self.system.layout

    def evaluate(self, u: np.ndarray, lam: float, committed, guess=None, want_K: bool = True,
                 timing: dict | None = None, raw: bool = False):
        """Residual R = f_int + f_contact - lam f_ext (replicated), the tangent share (or None) and the
        trial state of this rank's elements and slaves (``raw``: as ``Model.evaluate``; distributed runs have no
        multi-point constraints)."""
        guess = committed if guess is None else guess
        t0 = time.perf_counter()
        r, data, etrial = self.system.local_internal(u, committed.elements, guess.elements, want_K=want_K)
        t1 = time.perf_counter()
        ev, ctrial = self.contact.evaluate(self.positions(u), lam, committed.contact, guess.contact, want_K)
        rc = ev.blocks.residual()
        r += rc
        Kc = ev.blocks.csr() if want_K else None
        if self.followers is not None and self.rank == 0:  # (the follower pressures' blocks: once, on rank 0)
            fb = ElementBlocks(self.system.n_nodes)
            for blk in self.followers.blocks(self.positions(u), self.loading.follower_values(lam), want_K):
                fb.add(*blk)
            r += fb.residual()
            if want_K:
                Kc = Kc + fb.csr()
        t2 = time.perf_counter()
        if self.dynamic:  # (the dynamic energy account reads the contact forces' share, summed alike)
            r, self.last_contact_residual = sum_all(self.comm, np.stack([r, rc]))
        else:
            r = sum_all(self.comm, r)
        t3 = time.perf_counter()
        if timing is not None:
            timing["assembly"] += t1 - t0
            timing["contact"] += t2 - t1
            timing["comm"] = timing.get("comm", 0.0) + t3 - t2
        K = None
        if want_K:
            sysm = self.system
            K = DistMatrix(self.comm, sysm.structure, sysm.pattern.csr(data), Kc, sysm.constrained)
        return r - self.external(lam), K, replace(committed, elements=etrial, contact=ctrial, lam=lam)

    def eliminate(self, K):
        return self.system.eliminate(K)

    def sum_over_ranks(self, value: float) -> float:
        """A sum over this rank's elements or contact slaves summed over the ranks (collective)."""
        return float(sum_all(self.comm, np.array([float(value)]))[0])

    def any_over_ranks(self, mask: np.ndarray) -> np.ndarray:
        """A boolean mask over the nodes or dofs set where any rank sets it (collective): a mask of this
        rank's contact slaves made that of all slaves (the redistributed mass's contact nodes)."""
        return sum_all(self.comm, np.asarray(mask, dtype=np.float64)) > 0.0

    def plastic_change(self, a, b) -> tuple[int, int]:
        """Summed over the ranks (collective)."""
        mine = super().plastic_change(a, b)
        return tuple(int(v) for v in sum_all(self.comm, np.array(mine, dtype=float)))

    def plastic_work(self, state) -> float | None:
        """Plastic work of all bodies, summed over the ranks (collective)."""
        mine = super().plastic_work(state)
        return None if mine is None else float(sum_all(self.comm, np.array([mine]))[0])

    def partition_report(self) -> dict:
        """Elements, owned dofs and contact slaves per rank (collective)."""
        own = sum(len(blk.solid.elements) for blk in self.system.blocks)
        slaves = sum(len(p.slaves) for p in self.contact.passes)
        rows = gather_all(self.comm, (own, self.layout.hi - self.layout.lo, slaves))
        return {"ranks": self.size, "elements": [r[0] for r in rows], "owned_dofs": [r[1] for r in rows],
                "slaves": [r[2] for r in rows], "numba_threads": self.threads}


__all__ = ["DistMatrix", "DistributedModel", "DistributedSystem", "PartBody", "ReplicatedMass", "Structure"]
