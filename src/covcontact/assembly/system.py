"""The global system of a problem: dof numbering, the body tangent pattern, loads, Dirichlet elimination.

All deformable bodies share one node numbering: body k's node a is global node ``offset[k] + a`` with dofs
``3 * (offset[k] + a) + i``. Rigid bodies carry no unknowns.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numba import njit

from ..elements.base import NNODES
from ..elements.solid import SolidBody
from ..fem.cells import any_face
from ..loads import BodyForce, NodalForce, Pressure, Traction
from .pattern import Pattern


class InvertedElementError(RuntimeError):
    """An element has det F <= 0 at a Gauss point (triggers a cutback)."""

    def __init__(self, body: str, element: int):
        super().__init__(f"element {element} of body {body!r} inverted (det F <= 0)")
        self.body = body
        self.element = element


@njit(cache=True, inline="always")
def _constrained_pass(indptr, indices, constrained, zero, one):
    """Count (zero and one empty) or list the entries of _constrained_entries; returns the two counts."""
    fill = zero.size > 0
    nz = 0
    no = 0
    for i in range(indptr.size - 1):
        ci = constrained[i]
        for p in range(indptr[i], indptr[i + 1]):
            j = indices[p]
            if ci or constrained[j]:
                if fill:
                    zero[nz] = p
                    if i == j:
                        one[no] = p
                nz += 1
                no += i == j
    return nz, no


@njit(cache=True)
def _constrained_entries(indptr, indices, constrained):
    """Data positions of the CSR entries in a constrained row or column, and of the diagonal ones among them
    (compiled, counted then listed: the whole-array version made 1e6-dof temporaries, about 1 s a pattern)."""
    nz, no = _constrained_pass(indptr, indices, constrained, np.empty(0, np.int64), np.empty(0, np.int64))
    zero = np.empty(nz, np.int64)
    one = np.empty(no, np.int64)
    _constrained_pass(indptr, indices, constrained, zero, one)
    return zero, one


@dataclass
class BodyBlock:
    """A deformable body placed in the global numbering."""

    name: str
    offset: int
    n_nodes: int
    solid: SolidBody


def face_load_vector(X: np.ndarray, faces: np.ndarray, area_only: bool = False) -> np.ndarray:
    """Integral of N_a (rho_1 x rho_2) dxi over reference faces: (nnode, 3) nodal vectors.

    A dead pressure p gives nodal forces -p times this (positive pressure pushes into the body). With
    ``area_only`` the integral of N_a |rho_1 x rho_2| dxi (nodal areas, repeated in the 3 columns).
    """
    N, dN, w = any_face(faces.shape[1])
    xf = X[faces]  # (nf, nfn, 3)
    r1 = np.einsum("pa,fai->fpi", dN[:, :, 0], xf)
    r2 = np.einsum("pa,fai->fpi", dN[:, :, 1], xf)
    nda = np.cross(r1, r2) * w[None, :, None]  # (nf, np, 3)
    if area_only:
        nda = np.repeat(np.linalg.norm(nda, axis=2, keepdims=True), 3, axis=2)
    fa = np.einsum("pa,fpi->fai", N, nda)
    out = np.zeros_like(X)
    np.add.at(out, faces.ravel(), fa.reshape(-1, 3))
    return out


PLANAR_FORMULATIONS = ("plane_strain", "plane_stress", "axisymmetric")


def is_planar(body) -> bool:
    """Whether ``body`` (a ``covcontact.problem.Body``) is a plane strain, plane stress or axisymmetric body."""
    return getattr(body, "formulation", "solid") in PLANAR_FORMULATIONS


def cell_masses(body, cell_type: str, cells: np.ndarray, density: float) -> np.ndarray:
    """Consistent scalar element mass matrices of ``cells`` of ``body`` (planar bodies: times the thickness or
    2 pi R)."""
    if is_planar(body):
        from ..elements.planar import planar_masses

        return planar_masses(cell_type, body.mesh.points, cells, density, body.formulation,
                             float(body.options.get("thickness", 1.0)))
    from ..elements.mass import element_masses

    return element_masses(cell_type, body.mesh.points, cells, density)


def _element_body(body, material, cell_type: str, cells: np.ndarray):
    """The element body of ``body``'s formulation over ``cells`` of ``cell_type`` with ``material``."""
    if is_planar(body) and body.options.get("fbar"):
        from ..elements.planar_fbar import PlanarFbarBody

        return PlanarFbarBody(cell_type, body.mesh.points, cells, material, body.formulation,
                              float(body.options.get("thickness", 1.0)))
    if is_planar(body):
        from ..elements.planar import PlanarBody

        return PlanarBody(cell_type, body.mesh.points, cells, material, body.formulation,
                          float(body.options.get("thickness", 1.0)), body.options.get("integration", "full"))
    if body.formulation == "solid-shell":
        from ..elements.solidshell import SolidShellBody

        return SolidShellBody(cell_type, body.mesh.points, cells, material, **body.options)
    if body.formulation == "fbar":
        from ..elements.fbar import FbarBody

        return FbarBody(cell_type, body.mesh.points, cells, material, **body.options)
    options = {k: v for k, v in body.options.items() if k != "incompatible_modes"}
    if body.options.get("incompatible_modes") and cell_type == "hex8":  # (C3D8I; a mixed mesh's other cells plain)
        from ..elements.incompatible import IncompatibleBody

        return IncompatibleBody(cell_type, body.mesh.points, cells, material)
    return SolidBody(cell_type, body.mesh.points, cells, material, **options)


def make_solid(body, elements: np.ndarray | None = None):
    """The element body of a ``covcontact.problem.Body`` over its cells ``elements`` (default all): one material
    over cells of one type, or a :class:`covcontact.elements.composite.CompositeBody` of one part per material of
    ``body.materials`` and cell type of a mixed mesh."""
    elements = np.arange(body.mesh.n_cells) if elements is None else np.asarray(elements, dtype=np.int64)
    parts = [(idx, _element_body(body, material, cell_type, body.mesh.cells_of(elements[idx])[1]))
             for _, idx, material, cell_type in body.material_parts(elements)]
    if len(parts) == 1:  # one material over cells of one type (in their order)
        return parts[0][1]
    if not parts:
        cell_type = body.mesh.cell_types[0]
        return _element_body(body, body.material, cell_type, np.empty((0, NNODES[cell_type]), dtype=np.int64))
    from ..elements.composite import CompositeBody

    return CompositeBody(parts)


class System:
    """Global arrays of deformable bodies, their loads and Dirichlet conditions, and the reference nodes of
    the rigid bodies with free components: ``System(bodies, rigid, loads, dirichlet)`` (``covcontact.problem``
    Body and RigidBody, ``covcontact.loads`` NodalForce / Pressure / Traction and Dirichlet)."""

    def __init__(self, bodies, rigid=(), loads=(), dirichlet=()):
        self.bodies = {b.name: b for b in bodies}
        self.loads, self.dirichlet = list(loads), list(dirichlet)
        self.blocks: list[BodyBlock] = []
        offset = 0
        for body in bodies:
            solid = make_solid(body)
            self.blocks.append(BodyBlock(body.name, offset, body.mesh.n_nodes, solid))
            offset += body.mesh.n_nodes
        self.n_deformable = offset
        #: the z-dofs of the nodes of planar bodies, held at zero with the Dirichlet conditions of every stage
        self.planar_dofs = np.concatenate([np.zeros(0, dtype=np.int64)] + [
            3 * (blk.offset + np.arange(blk.n_nodes, dtype=np.int64)) + 2
            for blk, body in zip(self.blocks, bodies) if is_planar(body)])
        self.reference = self._reference_nodes(rigid, offset)
        for ref, rb in zip(self.reference, [rb for rb in rigid if rb.free or rb.attach]):
            if rb.attach:
                ref.attached = np.unique(np.concatenate([self.global_nodes(b, s) for b, s in rb.attach]))
                ref.attached_components = tuple(rb.attach_components)
        self.n_nodes = offset + 2 * len(self.reference)
        self.n_dofs = 3 * self.n_nodes
        self.X = np.zeros((self.n_nodes, 3))
        for blk, body in zip(self.blocks, bodies):
            self.X[blk.offset: blk.offset + blk.n_nodes] = body.mesh.points
        for ref in self.reference:
            self.X[ref.A] = ref.origin
        pairs = [np.array([[ref.A, ref.B] for ref in self.reference], dtype=np.int64)] if self.reference else []
        self.pattern = Pattern(self.n_nodes, [b.cells + blk.offset for blk, body in zip(self.blocks, bodies)
                                              for b in body.mesh.blocks] + pairs)
        self._build_loads()
        self._build_dirichlet()

    def mass(self, lumped: bool = False, massless: np.ndarray | None = None, consistent_interior: bool = False):
        """The dof mass matrix (n_dofs, n_dofs) of the deformable bodies, consistent or HRZ-lumped
        (``covcontact.elements.mass``), lumped with the ``massless`` nodes' mass redistributed when given (with
        ``consistent_interior`` only in the elements that have a massless node, consistent elsewhere); zero rows at
        reference nodes. A material without density is a ValueError."""
        from ..elements.mass import assemble_mass, dof_matrix

        parts = []
        for blk, body in zip(self.blocks, self.bodies.values()):
            for _, idx, material, cell_type in body.material_parts():
                rho = getattr(material, "density", None)
                if rho is None:
                    raise ValueError(f"body {body.name!r}: its material has no density (needed for the mass)")
                cells = body.mesh.cells_of(idx)[1]
                parts.append((cells + blk.offset, cell_masses(body, cell_type, cells, rho)))
        M = dof_matrix(assemble_mass(self.n_nodes, parts, lumped or massless is not None, massless,
                                     consistent_interior))
        if self.reference:  # rigid bodies with free components: mass on A, rotary inertia on B (small rotations)
            diag = np.zeros(self.n_dofs)
            for ref in self.reference:
                diag[3 * ref.A: 3 * ref.A + 3] = ref.mass
                diag[3 * ref.B: 3 * ref.B + 3] = ref.inertia
            M = (M + sp.diags(diag)).tocsr()
        return M

    @staticmethod
    def _reference_nodes(rigid, offset: int) -> list:
        """The reference-node pairs (A: translation, B: rotation vector) of rigid bodies with free components,
        numbered after the deformable nodes."""
        from ..contact.reference import ReferenceBody

        out = []
        for rb in rigid:
            if rb.free or rb.attach:
                A = offset + 2 * len(out)
                out.append(ReferenceBody(rb.name, A, A + 1, rb.reference_point(), tuple(rb.free),
                                         np.asarray(rb.force, dtype=float), np.asarray(rb.moment, dtype=float),
                                         float(rb.mass or 0.0), np.asarray(rb.inertia or (0.0, 0.0, 0.0), float)))
        return out

    # -- numbering ------------------------------------------------------------------------------
    def offset(self, body: str) -> int:
        for blk in self.blocks:
            if blk.name == body:
                return blk.offset
        raise KeyError(body)

    def global_nodes(self, body: str, set_name: str) -> np.ndarray:
        mesh = self.bodies[body].mesh
        return mesh.node_sets[set_name] + self.offset(body)

    # -- loads ----------------------------------------------------------------------------------
    def load_vector(self, load, value=None) -> np.ndarray:
        """External force vector (n_dofs,) of one load (NodalForce, Pressure or Traction) with its value
        replaced by ``value`` (default: its own)."""
        value = np.asarray(load.value if value is None else value, dtype=float)
        f = np.zeros((self.n_nodes, 3))
        if isinstance(load, NodalForce):
            nodes = self.global_nodes(load.body, load.set)
            if load.distribution == "total":
                value = value / len(nodes)
            np.add.at(f, nodes, value[None, :])
            return f.ravel()
        if isinstance(load, BodyForce):
            return self._body_force(load, value)
        mesh = self.bodies[load.body].mesh
        faces = mesh.face_sets[load.set]
        off = self.offset(load.body)
        body = self.bodies[load.body]
        weights = mesh.face_weights.get(load.set)
        if isinstance(load, Pressure) and (load.profile is not None or weights is not None):  # (varying over the
            # faces: the follower pressure's forces at the reference positions are the dead pressure's)
            from ..elements.follower import edge_blocks, face_blocks, point_factors

            p, planar = float(value.reshape(-1)[0]), is_planar(body)
            factor = point_factors(mesh.points, faces, load.profile, planar, weights)
            R = (edge_blocks(mesh.points, faces, p, body.formulation, float(body.options.get("thickness", 1.0)),
                             False, factor) if planar else face_blocks(mesh.points, faces, p, False, factor))[0]
            np.add.at(f, faces.ravel() + off, -R.reshape(-1, 3))
            return f.ravel()
        if is_planar(body):  # edges: times the thickness or 2 pi R
            from ..elements.planar import edge_load_vector

            t = float(body.options.get("thickness", 1.0))
            normal = edge_load_vector(mesh.points, faces, body.formulation, t, isinstance(load, Traction))
        else:
            normal = face_load_vector(mesh.points, faces, area_only=isinstance(load, Traction))
        if isinstance(load, Pressure):
            f[off: off + mesh.n_nodes] -= float(value.reshape(-1)[0]) * normal
        else:
            f[off: off + mesh.n_nodes] += normal * value[None, :]
        return f.ravel()

    def _body_force(self, load, value: np.ndarray) -> np.ndarray:
        """int N_a b dV0 over the load's cells: the row sums of the consistent mass matrix of unit density (or the
        material's, ``per_mass``) times b."""
        body = self.bodies[load.body]
        chosen = body.mesh.element_sets[load.cells] if load.cells else np.arange(body.mesh.n_cells)
        weight = np.zeros(self.n_nodes)
        f = np.zeros((self.n_nodes, 3))
        off = self.offset(load.body)
        if load.axis is not None:  # centrifugal: the acceleration omega^2 (X - c)_perp, linear in X, so M a is exact
            e = np.asarray(load.axis, dtype=float) / np.linalg.norm(load.axis)
            d = body.mesh.points - np.asarray(load.center, dtype=float)
            accel = float(value.reshape(-1)[0]) * (d - np.outer(d @ e, e))
        for _, idx, material, cell_type in body.material_parts(chosen):
            rho = 1.0
            if load.per_mass:
                rho = getattr(material, "density", None)
                if rho is None:
                    raise ValueError(f"body {body.name!r}: a body force per mass needs the density of its material")
            cells = body.mesh.cells_of(chosen[idx])[1]
            me = cell_masses(body, cell_type, cells, rho)
            if load.axis is not None:
                np.add.at(f, cells.ravel() + off, np.einsum("eab,ebi->eai", me, accel[cells]).reshape(-1, 3))
            else:
                np.add.at(weight, cells.ravel() + off, me.sum(axis=2).ravel())
        if load.axis is not None:
            return f.ravel()
        return (weight[:, None] * value[None, :]).ravel()

    def _build_loads(self) -> None:
        """f_ext: the dead loads at their own values (follower pressures act on the current faces: the Model's)."""
        f = np.zeros(self.n_dofs)
        for load in self.loads:
            if not getattr(load, "follower", False):
                f += self.load_vector(load)
        self.f_ext = f

    # -- Dirichlet ------------------------------------------------------------------------------
    def _build_dirichlet(self) -> None:
        """The dofs of the first stage's Dirichlet conditions (their values: ``covcontact.solvers.stages``)."""
        constrained = np.zeros(self.n_dofs, dtype=bool)
        for bc in self.dirichlet:
            nodes = self.global_nodes(bc.body, bc.set)
            constrained[(3 * nodes[:, None] + np.asarray(bc.components)[None, :]).ravel()] = True
        self.set_constraints(constrained)

    def set_constraints(self, constrained: np.ndarray) -> None:
        """The dofs whose values are prescribed (a stage may free some)."""
        self.constrained = np.asarray(constrained, dtype=bool).copy()
        self.constrained[getattr(self, "planar_dofs", np.zeros(0, dtype=np.int64))] = True  # (planar bodies' z)
        self.free = ~self.constrained
        self._eliminate_cache = None  # (indices, indptr, entries to zero, diagonal entries) of the last pattern

    # -- evaluation -----------------------------------------------------------------------------
    def new_state(self) -> list[dict[str, np.ndarray]]:
        """Element history of every body at the reference state (solid-shells: EAS parameters)."""
        return [blk.solid.new_state() for blk in self.blocks]

    def internal(self, u: np.ndarray, committed: list[dict] | None = None, guess: list[dict] | None = None,
                 want_K: bool = True, pattern: Pattern | None = None):
        """Internal forces (n_dofs,), the body tangent (CSR over ``pattern``, default the bodies' own, or
        None) and the trial element history at displacement u: history read from ``committed``, local
        iterations started from ``guess`` (default ``committed``); neither is changed."""
        pattern = self.pattern if pattern is None else pattern
        data = np.zeros(pattern.nnz) if want_K else np.zeros(1)
        r = np.zeros(self.n_dofs)
        U = u.reshape(-1, 3)
        committed = self.new_state() if committed is None else committed
        guess = committed if guess is None else guess
        trial = []
        for blk, c, g in zip(self.blocks, committed, guess):
            st = blk.solid.kernel_state(c, g)
            bad = blk.solid.assemble(U[blk.offset: blk.offset + blk.n_nodes], data, r, pattern,
                                     node_offset=blk.offset, want_K=want_K, state=st)
            if bad >= 0:
                raise InvertedElementError(blk.name, int(bad))
            trial.append(blk.solid.trial_of(st))
        K = pattern.csr(data) if want_K else None
        return r, K, trial

    def energy(self, u: np.ndarray, state: list[dict] | None = None) -> float:
        U = u.reshape(-1, 3)
        state = self.new_state() if state is None else state
        return float(sum(blk.solid.energy(U[blk.offset: blk.offset + blk.n_nodes], st)
                         for blk, st in zip(self.blocks, state)))

    def eliminate(self, K: sp.csr_matrix) -> sp.csr_matrix:
        """Zero the rows and columns of constrained dofs and put 1 on their diagonal (in place if possible)."""
        if not self.constrained.any():
            return K
        K = K.tocsr()
        cached = self._eliminate_cache
        if (cached is not None and cached[0].shape == K.indices.shape and np.array_equal(cached[1], K.indptr)
                and np.array_equal(cached[0], K.indices)):
            zero, one = cached[2], cached[3]
        else:  # once per pattern (the bodies' pattern, or a contact pattern) and set of constraints
            zero, one = _constrained_entries(K.indptr, K.indices, self.constrained)
            self._eliminate_cache = (K.indices.copy(), K.indptr.copy(), zero, one)
        K.data[zero] = 0.0
        K.data[one] = 1.0
        return K
