"""The ``.dat`` table of a deck's run, in CalculiX's layout (docs/input.md, "Abaqus and CalculiX decks"), with the
deck's node and element labels, at each output increment:

- *NODE PRINT: U (displacements), RF (forces; TOTALS: their sum), a rigid body's REF and ROT nodes too;
- *EL PRINT: at the Gauss points S (Cauchy stress), E (Green-Lagrange strain, tensor shear), PEEQ (equivalent plastic
  strain), ENER (strain energy density per reference volume); per element ELSE (its internal energy) and EVOL (its
  volume; the reference volume, as CalculiX prints it also with NLGEOM), TOTALS their sums;
- *CONTACT PRINT: per active slave node (node-to-surface) or slave Gauss point (surface-to-surface, labelled by its
  element and face) CDIS (clearance and relative tangential displacement), CSTR (pressure and tangential tractions),
  CELS (the energy stored in the contact law), and CNUM (the number of active slaves); a node-to-surface pair on
  linear planar edges as CalculiX's expanded model: each slave node as its two face nodes with CalculiX's labels;
- *SECTION PRINT (SOF, SOM): the force and moment the rest of the model exerts on the surface's elements (the sum of
  their internal forces at the surface's nodes), the surface's area, centre and mean normal.

The blocks come in the order of the deck's cards (those carried over from an earlier step first), the section tables
last, as CalculiX writes them."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..contact.reference import tangent_map
from ..observer import Observer

_BLOCK = {"U": "displacements (vx,vy,vz)", "RF": "forces (fx,fy,fz)"}
#: *EL PRINT variables at the Gauss points: the block's header up to the set's name
_POINT_HEAD = {"S": " stresses (elem, integ.pnt.,sxx,syy,szz,sxy,sxz,syz) for set ",
               "E": " strains (elem, integ.pnt.,exx,eyy,ezz,exy,exz,eyz) for set ",
               "PEEQ": " equivalent plastic strain (elem, integ.pnt.,pe)for set ",   # (CalculiX's: no space)
               "ENER": " internal energy density (elem, integ.pnt.,energy) for set "}
#: *EL PRINT variables per element: (header, header of the total)
_ELEMENT_HEAD = {"ELSE": (" internal energy (element, energy) for set ", " total internal energy for set "),
                 "EVOL": (" volume (element, volume) for set ", " total volume for set ")}
#: *CONTACT PRINT headers (CalculiX 2.20's, up to the time) for slave nodes and for slave faces' integration points
_CONTACT_HEAD = {
    "CSTR": (" contact stress (slave node,press,tang1,tang2) for all contact elements and time",
             " contact stress (slave element+face,press,tang1,tang2) for all contact elements and time"),
    "CDIS": (" relative contact displacement (slave node,normal,tang1,tang2) for all contact elements and time",
             " relative contact displacement (slave element+face,normal,tang1,tang2) for all contact elements and "
             "time"),
    "CELS": (" contact print energy (slave node,energy) forall contact elements and time",
             " contact print energy (slave element+face,energy)for all contact elements and time")}

#: corner nodes (0-based) of the faces S1.. of each cell type (CalculiX's and Abaqus' face numbering)
_HEX = {1: (0, 1, 2, 3), 2: (4, 7, 6, 5), 3: (0, 4, 5, 1), 4: (1, 5, 6, 2), 5: (2, 6, 7, 3), 6: (3, 7, 4, 0)}
_TET = {1: (0, 1, 2), 2: (0, 3, 1), 3: (1, 3, 2), 4: (2, 3, 0)}
_WEDGE = {1: (0, 1, 2), 2: (3, 5, 4), 3: (0, 3, 4, 1), 4: (1, 4, 5, 2), 5: (2, 5, 3, 0)}
_CORNERS = {"hex8": _HEX, "hex20": _HEX, "tet4": _TET, "tet10": _TET, "wedge6": _WEDGE}
#: the mid-edge node of each edge (corner pair) of the quadratic cells
_MID = {"hex20": {(0, 1): 8, (1, 2): 9, (2, 3): 10, (3, 0): 11, (4, 5): 12, (5, 6): 13, (6, 7): 14, (7, 4): 15,
                  (0, 4): 16, (1, 5): 17, (2, 6): 18, (3, 7): 19},
        "tet10": {(0, 1): 4, (1, 2): 5, (0, 2): 6, (0, 3): 7, (1, 3): 8, (2, 3): 9}}


#: the .dat's forces of an axisymmetric body's nodes are those of CalculiX's expanded segment of 2 degrees (its
#: .frd's, and covcontact's own results, are totals over the circumference: 180 such segments)
AXISYMMETRIC_SEGMENTS = 180.0


def fortran_e(x: float) -> str:
    """x as CalculiX prints a time: 0.dddddddE+xx."""
    if x == 0.0:
        return " 0.0000000E+00"
    e = int(np.floor(np.log10(abs(x)))) + 1
    m = x / 10.0 ** e
    if abs(round(m, 7)) >= 1.0:
        m, e = m / 10.0, e + 1
    return f"{m:10.7f}" + f"E{e:+03d}"


def _row(values) -> str:
    """Values as CalculiX's 1p,(1x,e13.6) fields (a zero unsigned, as Fortran prints it)."""
    return "".join(f"{v + 0.0:14.6E}" for v in values)


# -- Gauss-point kinematics and energies ------------------------------------------------------------------------------
def _cells(solid) -> list[tuple[str, np.ndarray]]:
    """(cell type, local nodes) of every element of a body."""
    from ..elements.composite import CompositeBody

    if isinstance(solid, CompositeBody):
        out: list = [None] * solid.n_elements
        for idx, part in zip(solid.index, solid.parts):
            for e, nodes in zip(idx, part.cells):
                out[e] = (part.cell_type, nodes)
        return out
    return [(solid.cell_type, nodes) for nodes in solid.cells]


def _point_mask(solid) -> np.ndarray:
    """(n_elements, n_points): 0 at each cell's own Gauss points, NaN past them (a body of mixed cells)."""
    from ..elements.composite import CompositeBody

    if isinstance(solid, CompositeBody):
        out = np.full((solid.n_elements, max(p.weights.size for p in solid.parts)), np.nan)
        for idx, part in zip(solid.index, solid.parts):
            out[idx, : part.weights.size] = 0.0
        return out
    return np.zeros((solid.n_elements, solid.weights.size))


def point_gradients(solid, U: np.ndarray, state: dict) -> np.ndarray:
    """(n_elements, n_points, 3, 3) displacement gradients H = du/dX at the Gauss points of a body (the points in the
    order of its rule, as the stresses are printed; NaN past a cell's own points in a body of mixed cells): plain solids
    and incompatible-mode hexahedra (with their solved mode parameters); a ValueError for other formulations."""
    from ..elements.composite import CompositeBody
    from ..elements.incompatible import IncompatibleBody
    from ..elements.solid import SolidBody

    if isinstance(solid, CompositeBody):
        rows = [point_gradients(part, U, solid._views(k, state)[0]) for k, part in enumerate(solid.parts)]
        out = np.full((solid.n_elements, max(r.shape[1] for r in rows), 3, 3), np.nan)
        for idx, r in zip(solid.index, rows):
            out[idx, : r.shape[1]] = r
        return out
    if not isinstance(solid, (SolidBody, IncompatibleBody)):
        raise ValueError(f"Gauss-point strains are for solid elements, not {type(solid).__name__}")
    U = np.asarray(U, dtype=float).reshape(-1, 3)
    out = np.empty((solid.n_elements, solid.weights.size, 3, 3))
    for lo in range(0, solid.n_elements, 2048):
        cells = solid.cells[lo: lo + 2048]
        Xe, Ue = solid.X[cells], U[cells]
        J0 = np.einsum("eai,gak->egik", Xe, solid.dNdxi)
        Ji = np.linalg.inv(J0)
        G = np.einsum("gak,egkj->egaj", solid.dNdxi, Ji)   # dN_a/dX_j
        H = np.einsum("eai,egaj->egij", Ue, G)
        if isinstance(solid, IncompatibleBody):   # the modes' enhanced gradients times their parameters
            Jc = np.einsum("eai,ak->eik", Xe, solid.dNc)
            r = np.linalg.det(Jc)[:, None] / np.linalg.det(J0)
            b = -2.0 * r[:, :, None, None] * solid.points[None, :, :, None] * np.linalg.inv(Jc)[:, None]  # e,g,k,j
            alpha = state["alpha"][lo: lo + 2048].reshape(-1, 3, 3)   # e, k, i
            H += np.einsum("eki,egkj->egij", alpha, b)
        out[lo: lo + len(cells)] = H
    return out


def green_strain(H: np.ndarray) -> np.ndarray:
    """(..., 6) Green-Lagrange strain E = (H + H^T + H^T H) / 2, tensor components xx, yy, zz, xy, xz, yz."""
    E = 0.5 * (H + np.swapaxes(H, -1, -2) + np.einsum("...ki,...kj->...ij", H, H))
    return np.stack([E[..., 0, 0], E[..., 1, 1], E[..., 2, 2], E[..., 0, 1], E[..., 0, 2], E[..., 1, 2]], axis=-1)


def point_energies(solid, H: np.ndarray, state: dict) -> np.ndarray:
    """(n_elements, n_points) strain energy density per reference volume at the Gauss points: W(E) of St.
    Venant-Kirchhoff, Neo-Hooke and the rubber models; for J2 plasticity the elastic (Hencky) energy of the elastic
    log strain plus the accumulated plastic work, the whole stress work as CalculiX integrates it."""
    from ..elements.composite import CompositeBody
    from ..materials.hyperelastic import NEO_HOOKE, SVK, material_energy
    from ..materials.plasticity import H_EP, H_WP, J2
    from ..materials.rubber import RUBBER

    if isinstance(solid, CompositeBody):
        out = np.full(H.shape[:2], np.nan)
        for k, (idx, part) in enumerate(zip(solid.index, solid.parts)):
            n = part.weights.size
            out[idx, :n] = point_energies(part, H[idx, :n], solid._views(k, state)[0])
        return out
    kind, params = solid.material.kind, solid.material.params
    lam, mu = float(params[2]), float(params[3])
    F = H + np.eye(3)
    C = np.einsum("...ki,...kj->...ij", F, F)
    if kind == SVK:
        E = 0.5 * (H + np.swapaxes(H, -1, -2) + np.einsum("...ki,...kj->...ij", H, H))
        tr = np.einsum("...ii->...", E)
        return 0.5 * lam * tr ** 2 + mu * np.einsum("...ij,...ij->...", E, E)
    if kind == NEO_HOOKE:
        lnJ = np.log(np.linalg.det(F))
        return 0.5 * mu * (np.einsum("...ii->...", C) - 3.0) - mu * lnJ + 0.5 * lam * lnJ ** 2
    if kind == RUBBER:  # (the rubber models: W point by point)
        Fs = F.reshape(-1, 3, 3)
        return np.array([material_energy(kind, params, np.ascontiguousarray(f)) for f in Fs]).reshape(H.shape[:-2])
    if kind != J2:
        raise ValueError(f"no strain energy for material kind {kind}")
    w, v = np.linalg.eigh(C)
    Elog = np.einsum("...ia,...a,...ja->...ij", v, 0.5 * np.log(w), v)
    hist = state["hist"]
    ep = hist[..., H_EP: H_EP + 6]   # 11, 22, 33, 12, 23, 13
    Ep = np.stack([np.stack([ep[..., 0], ep[..., 3], ep[..., 5]], -1),
                   np.stack([ep[..., 3], ep[..., 1], ep[..., 4]], -1),
                   np.stack([ep[..., 5], ep[..., 4], ep[..., 2]], -1)], -2)
    Ee = Elog - Ep
    tr = np.einsum("...ii->...", Ee)
    return 0.5 * lam * tr ** 2 + mu * np.einsum("...ij,...ij->...", Ee, Ee) + hist[..., H_WP]


def element_forces(solid, U: np.ndarray, state: dict, elements) -> dict[int, np.ndarray]:
    """{element: (nen, 3) its internal forces at its nodes} of the ``elements`` of a body at displacement U and the
    committed element history ``state`` (the element kernels themselves, one element at a time)."""
    from ..elements.composite import CompositeBody

    if isinstance(solid, CompositeBody):
        out = {}
        for k, part in enumerate(solid.parts):
            pos = {int(e): j for j, e in enumerate(solid.index[k])}
            mine = [int(e) for e in elements if int(e) in pos]
            if mine:
                got = element_forces(part, U, solid._views(k, state)[0], [pos[e] for e in mine])
                out.update({e: got[pos[e]] for e in mine})
        return out
    u = solid._u(np.asarray(U, dtype=float).reshape(-1, 3))
    ks = solid.kernel_state(state, state)
    nd = 3 * solid.nen
    out = {}
    for e in sorted({int(e) for e in elements}):
        fe = np.zeros((1, nd))
        solid._chunk(u, e, False, np.empty((0, nd, nd)), fe, np.zeros(1, dtype=np.int64), 1, ks)
        out[e] = fe[0].reshape(-1, 3)
    return out


def face_nodes(cell_type: str, face: int) -> list[int]:
    """Local nodes of face ``face`` (1..) of a cell: its corners, then the mid-edge nodes of a quadratic cell."""
    corners = list(_CORNERS[cell_type][face])
    mids = _MID.get(cell_type)
    if mids is None:
        return corners
    pairs = zip(corners, corners[1:] + corners[:1])
    return corners + [mids[(a, b)] if (a, b) in mids else mids[(b, a)] for a, b in pairs]


def ccx_tangents(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """CalculiX's tangential unit vectors of a contact normal n: t1 along x (along z when n is nearly x) projected off
    n, t2 = n x t1 (:func:`covcontact.fem.axes.calculix_axes`)."""
    from ..fem.axes import calculix_axes

    return calculix_axes(n)


def contact_energy(p, j: int, f: np.ndarray, n: np.ndarray, gap: float, multiplier: float) -> float:
    """The energy stored in the contact law of slave ``j`` of pass ``p`` with force ``f`` on it and gap ``gap``, as
    CalculiX's CELS: normal part -F_n g / 2 for the linear and arctan laws (the penalty and the augmented Lagrangian's
    too), F_n / beta for CalculiX's exponential law, the area under a table up to the overclosure, the integral of the
    law for a smoothed penalty and Abaqus' exponential curve; plus |f_t|^2 / (2 eps_t) with friction."""
    from ..contact.laws import exponential_law, smooth_law

    fn = float(f @ n)
    law = p.law
    if law is None or law.kind == "arctan":
        energy = -0.5 * fn * gap
        if law is None and p.band != 0.0:  # (the law's integral from the gap to where it ends)
            eps = float(p.eps[j])
            top = -float(p.band) if p.band < 0.0 else 0.5 * p.band - multiplier / eps
            x, w = np.polynomial.legendre.leggauss(64)
            gs = gap + (top - gap) * 0.5 * (x + 1.0)
            law_at = (lambda g: exponential_law(g, eps, -p.band)[0]) if p.band < 0.0 else \
                (lambda g: smooth_law(g, multiplier, eps, p.band)[0])
            energy = -0.5 * (top - gap) * float(sum(wk * law_at(g) for wk, g in zip(w, gs)))
    elif law.kind == "calculix_exponential":
        energy = fn / law.beta
    else:   # table: the integral of p from no overclosure to the overclosure d (p constant outside the table)
        d = -gap
        grid = np.unique(np.concatenate([[0.0, d], law.d[(law.d > min(0.0, d)) & (law.d < max(0.0, d))]]))
        pv = law.pressure(-grid)[0]
        area = float(np.sum(0.5 * (pv[1:] + pv[:-1]) * np.diff(grid)))
        energy = (area if d >= 0.0 else -area) * (float(p.area[j]) if law.per_area else 1.0)
    if p.mu > 0.0:
        ft = f - fn * n
        energy += float(ft @ ft) / (2.0 * float(p.eps_t[j]))
    return energy


def output_due(info: dict, count: dict, stage: int, ends_stage: bool) -> bool:
    """Whether a converged increment of ``stage`` is an output increment of the deck (the .dat and the .frd alike):
    the end of a step or of a time point, or every Nth increment of the deck step (FREQUENCY; CalculiX's default:
    every increment). ``count``: converged increments per deck step so far (updated)."""
    ends = info.get("print_end")
    if ends is None or stage >= len(ends):  # (a labels file without output times: the step's end)
        return ends_stage
    deck_step = info["deck_step"][stage]
    count[deck_step] = count.get(deck_step, 0) + 1
    every = info["print_every"][stage]
    return (ends_stage and ends[stage]) or (every > 0 and count[deck_step] % every == 0)


class DatTable(Observer):
    """Writes ``path`` (the .dat table) from the labels file of :func:`covcontact.io.deck_import.import_deck`."""

    def __init__(self, labels: Path, path: Path, deck: dict | None = None):
        self.info = json.loads(Path(labels).read_text())
        self.path = Path(path)
        self.deck = deck
        self.count: dict[int, int] = {}  # converged increments of each deck step so far
        self._elements: dict[int, tuple[int, int]] | None = None   # element label -> (block, element)

    def started(self, run) -> None:
        if run.model.is_root:
            self.path.write_text("")
        summary = getattr(run, "summary", None)
        if self.deck is not None and summary is not None:  # (summary.json: what was ignored and filled in)
            summary.data["deck"] = dict(self.deck)

    def _due(self, inc) -> bool:
        return output_due(self.info, self.count, inc.state.stage, bool(inc.ends_stage))

    @staticmethod
    def _of(info: dict, key: str, stage: int, default):
        per_stage = info.get(key, [])
        return per_stage[stage] if stage < len(per_stage) else default

    def increment_converged(self, run, inc) -> None:
        if not self._due(inc):
            return
        stage = inc.state.stage
        info = self.info
        node_prints = self._of(info, "node_print", stage, [])
        el_prints = self._of(info, "el_print", stage, [])
        contact = self._of(info, "contact_print", stage, [])
        totals, contact_order = self._of(info, "contact_card", stage, ["NO", 0])
        sections = self._of(info, "section_print", stage, [])
        if not (node_prints or el_prints or contact or sections):
            return
        time = sum(info["periods"][:stage]) + info["periods"][stage] * inc.lam
        now = _Now(self, run, inc, time)
        requests = [(p[3] if len(p) > 3 else 0, 0, k, p) for k, p in enumerate(node_prints)]
        requests += [(p[3] if len(p) > 3 else 0, 1, k, p) for k, p in enumerate(el_prints)]
        if contact:
            requests.append((contact_order, 2, 0, (contact, totals)))
        text = []
        for _, kind, _, p in sorted(requests, key=lambda r: r[:3]):
            if kind == 0:
                text += now.node_blocks(*p[:3]) if len(p) > 2 else now.node_blocks(p[0], p[1], "NO")
            elif kind == 1:
                text += now.el_blocks(p[0], p[1], p[2] if len(p) > 2 else "NO")
            else:
                text += now.contact_blocks(*p)
        for surface, _name, _variables, _ in sorted(sections, key=lambda s: s[3]):
            text += now.section_block(surface)
        if run.model.is_root:
            with open(self.path, "a") as fh:
                fh.write("".join(text))

    def element_index(self, model) -> dict[int, tuple[int, int]]:
        """Deck element label -> (block, element of the block)."""
        if self._elements is None:
            self._elements = {}
            for b, blk in enumerate(model.system.blocks):
                for j, lab in enumerate(self.info["elements"].get(blk.name, [])):
                    self._elements[int(lab)] = (b, j)
        return self._elements


class _Now:
    """One output increment: what its blocks need, each computed once."""

    def __init__(self, table: DatTable, run, inc, time: float):
        self.table, self.info, self.run, self.inc, self.model = table, table.info, run, inc, run.model
        self.time = time
        self.blocks = self.model.system.blocks
        self.U = run.u.reshape(-1, 3)
        self._where = self._forces = None
        self._fields: dict[str, dict] = {}
        self._contact = None
        self._cells: dict[int, list] = {}

    def cells(self, b: int) -> list[tuple[str, np.ndarray]]:
        """(cell type, local nodes) of every element of block b."""
        if b not in self._cells:
            self._cells[b] = _cells(self.blocks[b].solid)
        return self._cells[b]

    # -- nodes ----------------------------------------------------------------------------------------------------
    def where(self) -> dict[int, int]:
        """Deck node label -> global node (a rigid body's REF and ROT nodes: its node pair)."""
        if self._where is None:
            self._where = {}
            for blk in self.blocks:
                labels = self.info["bodies"].get(blk.name, [])
                self._where.update(zip(labels, range(blk.offset, blk.offset + len(labels))))
            refs = {ref.name: ref for ref in self.model.system.reference}
            for name, (ref_label, rot_label) in self.info.get("rigid", {}).items():
                for lab, node in ((ref_label, refs[name].A), (rot_label, refs[name].B)):
                    if lab is not None:
                        self._where[lab] = node
        return self._where

    def forces(self) -> np.ndarray:
        """The internal and contact forces at every node; at a rigid body's REF node the attached nodes' pull plus
        its load, at its ROT node the moment (the residual after the attached nodes hand their forces over)."""
        if self._forces is None:
            model, run, lam = self.model, self.run, self.inc.lam
            R, _, _ = model.evaluate(run.u, lam, run.state, want_K=False, raw=True)
            forces = (R + model.applied(run.u, lam)).reshape(-1, 3)
            refs = {ref.name: ref for ref in model.system.reference}
            rigid = self.info.get("rigid", {})
            if any(lab is not None for labels in rigid.values() for lab in labels):  # (the constraints hand R over)
                Rr = model.constraints.transform(R, None)[0].reshape(-1, 3)
            for name, (ref_label, rot_label) in rigid.items():
                ref = refs[name]
                if ref_label is not None or rot_label is not None:
                    force, moment = model.loading.rigid_load(name, lam)
                    forces[ref.A] = Rr[ref.A] + force
                    forces[ref.B] = Rr[ref.B] + tangent_map(run.u[3 * ref.B: 3 * ref.B + 3]).T @ moment
            for blk, body in zip(model.system.blocks, model.problem.bodies):  # (CalculiX's .dat: its 2 degree
                if getattr(body, "formulation", "") == "axisymmetric":           # segment of an axisymmetric model)
                    forces[blk.offset: blk.offset + blk.n_nodes] /= AXISYMMETRIC_SEGMENTS
            self._forces = forces
        return self._forces

    def shell_nodes(self) -> dict[int, tuple[int, int]]:
        """Deck label of a shell node -> its bottom and top global nodes (deck_shells)."""
        out = {}
        for blk in self.blocks:
            labels, n = self.info.get("shells", {}).get(blk.name, ([], 0))
            out.update((lab, (blk.offset + i, blk.offset + i + n)) for i, lab in enumerate(labels))
        return out

    def node_blocks(self, nset: str, variables, totals: str) -> list[str]:
        where = self.where()
        shells = self.shell_nodes()
        labels = [lab for lab in self.info["nsets"][nset] if lab in where or lab in shells]
        rows = np.array([shells[lab][0] if lab in shells else where[lab] for lab in labels], dtype=np.int64)
        other = np.array([shells[lab][1] if lab in shells else where[lab] for lab in labels], dtype=np.int64)
        pair = rows != other  # (a shell node: U the mean of its layers, as CalculiX prints the mid-surface; RF their sum)
        text = []
        for var in variables:
            if var not in _BLOCK:
                continue
            if var == "U":
                values = np.where(pair[:, None], 0.5 * (self.U[rows] + self.U[other]), self.U[rows])
            else:
                F = self.forces()
                values = np.where(pair[:, None], F[rows] + F[other], F[rows])
            if var != "RF" or totals != "ONLY":
                text.append(f"\n {_BLOCK[var]} for set {nset} and time {fortran_e(self.time)}\n\n")
                text += [f"{lab:10d}" + _row(row) + "\n" for lab, row in zip(labels, values)]
            if var == "RF" and totals in ("YES", "ONLY"):  # (CalculiX sums the external forces only)
                total = values.sum(axis=0) if len(values) else np.zeros(3)
                text.append(f"\n total force (fx,fy,fz) for set {nset} and time {fortran_e(self.time)}\n\n")
                text.append("      " + _row(total) + "\n")
        return text

    # -- elements -------------------------------------------------------------------------------------------------
    def field(self, var: str) -> dict:
        """Element label -> the variable's rows: S, E (n_points, 6), PEEQ, ENER (n_points, 1), ELSE, EVOL (1,);
        bodies whose formulation has no Gauss-point values are left out."""
        if var in self._fields:
            return self._fields[var]
        from ..elements.points import point_plastic_strains, point_stresses

        out: dict = {}
        for blk, est in zip(self.blocks, self.run.state.elements):
            labels = self.info["elements"].get(blk.name, [])
            U = self.U[blk.offset: blk.offset + blk.n_nodes]
            try:
                if var == "S":
                    s = point_stresses(blk.solid, U, est)
                    out.update(zip(labels, s[:, :, [0, 1, 2, 3, 5, 4]]))
                elif var == "PEEQ":
                    p = point_plastic_strains(blk.solid, est)
                    p = _point_mask(blk.solid) if p is None else p   # (an elastic body: zero)
                    out.update(zip(labels, p[:, :, None]))
                elif var == "EVOL":
                    out.update(zip(labels, blk.solid.gauss_volumes().sum(axis=1)[:, None]))
                else:
                    H = point_gradients(blk.solid, U, est)
                    if var == "E":
                        out.update(zip(labels, green_strain(H)))
                        continue
                    w = point_energies(blk.solid, np.nan_to_num(H), est)
                    w = np.where(np.isnan(H[:, :, 0, 0]), np.nan, w)
                    if var == "ENER":
                        out.update(zip(labels, w[:, :, None]))
                    else:   # ELSE: the density times the Gauss points' reference volumes
                        out.update(zip(labels, np.nansum(w * blk.solid.gauss_volumes(), axis=1)[:, None]))
            except (ValueError, AttributeError):   # (a formulation without these Gauss-point values)
                continue
        self._fields[var] = out
        return out

    def el_blocks(self, elset: str, variables, totals: str) -> list[str]:
        """The *EL PRINT blocks of one card: Gauss-point variables numbered as CalculiX numbers the points (the first
        direction of the element's coordinates fastest), element variables with their TOTALS."""
        text = []
        t = fortran_e(self.time)
        for var in variables:
            if var in _POINT_HEAD:
                table = self.field(var)
                text.append(f"\n{_POINT_HEAD[var]}{elset} and time {t}\n\n")
                for lab in self.info["elsets"][elset]:
                    if lab in table:
                        text += [f"{lab:10d}{g + 1:4d}" + _row(row) + "\n"
                                 for g, row in enumerate(table[lab]) if not np.isnan(row[0])]
            elif var in _ELEMENT_HEAD:
                table = self.field(var)
                labels = [lab for lab in self.info["elsets"][elset] if lab in table]
                head, total_head = _ELEMENT_HEAD[var]
                if totals != "ONLY":
                    text.append(f"\n{head}{elset} and time {t}\n\n")
                    text += [f"{lab:10d}" + _row(table[lab]) + "\n" for lab in labels]
                if totals in ("YES", "ONLY"):
                    total = float(sum(table[lab][0] for lab in labels))
                    text.append(f"\n{total_head}{elset} and time {t}\n\n      " + _row([total]) + "\n")
        return text

    # -- contact --------------------------------------------------------------------------------------------------
    def contact_rows(self) -> list[tuple]:
        """Per printed pass, per active slave in the pass's order: (kind "node" | "face", label, gap, pressure,
        shear stress (t1, t2), relative tangential displacement (t1, t2), energy), the tangential axes CalculiX's of the
        contact normal (:func:`ccx_tangents`); the pressure is the normal force on the slave over its area, the shear
        stress the tangential force the slave exerts (CalculiX's sign: along the slave's slip)."""
        if self._contact is not None:
            return self._contact
        from ..contact.surface import facet_frame

        self._contact = rows = []
        manager = self.model.contact
        if manager is None:
            return rows
        state = self.run.state.contact
        label = {node: lab for lab, node in self.where().items()}
        printed = self.info.get("contact_pairs")
        xe = manager.extended(self.model.positions(self.run.u), self.inc.lam)
        x0 = getattr(manager, "_x_start", None)
        ue = xe - x0 if x0 is not None and x0.shape == xe.shape else None
        rho, t1, t2, n = np.empty(3), np.empty(3), np.empty(3), np.empty(3)
        zero = np.zeros(3)
        planar = self.info.get("planar_contact") or {}
        for k, p in enumerate(manager.passes):
            if p.curve is not None and p.pair in planar.get("pairs", {}):
                rows += self._planar_rows(k, p, xe, ue, planar)
                continue
            if p.surface is None or p.tied or (printed is not None and p.pair not in printed):
                continue
            face_of = self._face_labels(p, printed.get(p.pair) if printed else None) if p.kind == "sts" else None
            s = state.passes[k]
            for j in np.flatnonzero(manager.active_mask(k, state) & (s.facet >= 0)):
                if face_of is None:
                    if int(p.slaves[j]) not in label:
                        continue
                    key = ("node", label[int(p.slaves[j])])
                else:
                    key = ("face", face_of.get(int(p.slave_facet[j]), (0, 0)))
                faces = p.surface.faces[s.facet[j]]
                facet_frame(np.ascontiguousarray(xe[faces]), float(s.xi[j, 0]), float(s.xi[j, 1]), rho, t1, t2, n)
                gap = float(s.gap[j])
                d = xe[p.slaves[j]] - rho   # g n: the contact normal also at an edge or vertex point
                if abs(gap) > 1e-9 * np.linalg.norm(t1):
                    n = d / gap
                    n /= np.linalg.norm(n)
                e1, e2 = ccx_tangents(n)
                f = s.force[j] / p.area[j]
                rel = zero
                if p.mu > 0.0 and ue is not None:   # (the slave against the master material point under it)
                    frame = np.empty(3), np.empty(3), np.empty(3), np.empty(3)
                    facet_frame(np.ascontiguousarray(ue[faces]), float(s.xi[j, 0]), float(s.xi[j, 1]), *frame)
                    rel = ue[p.slaves[j]] - frame[0]
                energy = contact_energy(p, j, s.force[j], n, gap, float(s.multiplier[j]))
                # (the shear stress as CalculiX prints it: the spring's force, opposite to the one on the slave)
                rows.append((key[0], key[1], gap, float(f @ n), (-float(f @ e1), -float(f @ e2)),
                             (float(rel @ e1), float(rel @ e2)), energy))
        return rows

    def _planar_rows(self, k: int, p, xe: np.ndarray, ue: np.ndarray | None, planar: dict) -> list[tuple]:
        """The rows of a planar node-to-segment pass as CalculiX prints its expanded model: per active slave node its
        two face nodes (labels ``planar["labels"]`` + 0 and + 2), each with the 2D node's gap, pressure, shear and
        slip and half its energy (an axisymmetric pass: of the 2 degree segment)."""
        from ..contact.planar_kernels import segment_point

        state = self.run.state.contact.passes[k]
        label = {node: lab for lab, node in self.where().items()}
        first = {int(lab): int(v) for lab, v in planar["labels"].items()}
        share = 0.5 / (AXISYMMETRIC_SEGMENTS if planar["pairs"][p.pair] == "axisymmetric" else 1.0)
        rows = []
        for j in np.flatnonzero(self.model.contact.active_mask(k, self.run.state.contact) & (state.facet >= 0)):
            lab = first.get(label.get(int(p.slaves[j]), -1))
            if lab is None:
                continue
            nodes = p.curve.segments[state.facet[j]]
            x, r, _ = segment_point(np.ascontiguousarray(xe[nodes]), float(state.xi[j, 0]))
            gap = float(state.gap[j])
            n = np.array([r[1], -r[0], 0.0]) / float(np.hypot(r[0], r[1]))
            d = xe[p.slaves[j]] - np.array([x[0], x[1], 0.0])   # (g n, also at a vertex)
            if abs(gap) > 1e-9 * float(np.hypot(r[0], r[1])):
                n = d / np.linalg.norm(d) * np.sign(gap)
            e1, e2 = ccx_tangents(n)
            f = state.force[j] / p.area[j]
            rel = np.zeros(3)
            if p.mu > 0.0 and ue is not None:
                u, _, _ = segment_point(np.ascontiguousarray(ue[nodes]), float(state.xi[j, 0]))
                rel = ue[p.slaves[j]] - np.array([u[0], u[1], 0.0])
            energy = share * contact_energy(p, j, state.force[j], n, gap, float(state.multiplier[j]))
            values = (gap, float(f @ n), (-float(f @ e1), -float(f @ e2)), (float(rel @ e1), float(rel @ e2)), energy)
            rows += [("node", lab, *values), ("node", lab + 2, *values)]
        return rows

    def contact_kinds(self) -> set[str]:
        """The kinds of slaves the printed pairs have: "node" (node-to-surface; also without contact pairs, as
        CalculiX then prints the node layout) and "face" (surface-to-surface)."""
        pairs = self.info.get("contact_pairs")
        if pairs is None:
            manager = self.model.contact
            kinds = {"face" if p.kind == "sts" else "node" for p in (manager.passes if manager is not None else [])}
        else:
            kinds = {"node" if v == "node" else "face" for v in pairs.values()}
        return kinds or {"node"}

    def _face_labels(self, p, surface: str | None) -> dict[int, tuple[int, int]]:
        """Slave facet of a surface-to-surface pass -> (element label, face number) of the deck's slave surface."""
        faces = self.info.get("surfaces", {}).get(surface or "", [])
        index = self.table.element_index(self.model)
        by_corners = {}
        for el, face in faces:
            if el not in index:
                continue
            b, e = index[el]
            blk = self.blocks[b]
            cell, nodes = self.cells(b)[e]
            by_corners[frozenset((blk.offset + nodes[list(_CORNERS[cell][face])]).tolist())] = (int(el), int(face))
        out = {}
        for f, row in enumerate(p.slave_faces):
            nc = 3 if len(row) in (3, 6) else 4
            hit = by_corners.get(frozenset(np.asarray(row[:nc]).tolist()))
            if hit is not None:
                out[f] = hit
        return out

    def contact_blocks(self, variables, totals: str) -> list[str]:
        """The *CONTACT PRINT blocks in the order of the card's variables (read by their first four letters):
        node-to-surface slaves by node label, surface-to-surface slave points by their element and face."""
        text = []
        t = fortran_e(self.time)
        for var in variables:
            v = var[:4]
            if v == "CNUM":
                n = len(self.contact_rows())
                text.append(f"\n total number of contact elements for time {t}\n\n       {n:10d}\n")
                continue
            if v not in _CONTACT_HEAD:
                continue
            rows = self.contact_rows()
            for kind, head in zip(("node", "face"), _CONTACT_HEAD[v]):
                if kind not in self.contact_kinds():
                    continue
                mine = [r for r in rows if r[0] == kind]
                if v != "CELS" and totals == "ONLY":   # (CalculiX prints nothing of them then)
                    continue
                if totals != "ONLY":
                    text.append(f"\n{head}{t}\n\n")
                    for _, lab, gap, press, trac, rel, energy in mine:
                        values = {"CSTR": (press, *trac), "CDIS": (gap, *rel), "CELS": (energy,)}[v]
                        lead = f"{lab:10d}" if kind == "node" else f"{lab[0]:10d} {lab[1]:10d}"
                        text.append(lead + _row(values) + "\n")
            if v == "CELS" and totals in ("YES", "ONLY"):
                total = float(sum(r[6] for r in rows))
                text.append(f"\n total contact spring energy for time {t}\n\n      " + _row([total]) + "\n")
        return text

    # -- sections -------------------------------------------------------------------------------------------------
    def section_block(self, surface: str) -> list[str]:
        """*SECTION PRINT (SOF, SOM, SOAREA) of an element surface in CalculiX's table: the force on the surface's
        elements from the rest of the model (the sum of their internal forces at the surface's nodes) and its moment
        about the origin, the surface's centre and mean normal (area weighted, deformed), the moment about the centre,
        the area, normal force (+ = tension), shear force, torque and bending moment."""
        from ..fem.cells import any_face

        index = self.table.element_index(self.model)
        per_element: dict[tuple[int, int], set] = {}
        geometry = []
        for el, face in self.info.get("surfaces", {}).get(surface, []):
            if el not in index:
                continue
            b, e = index[el]
            blk = self.blocks[b]
            cell, nodes = self.cells(b)[e]
            local = face_nodes(cell, face)
            per_element.setdefault((b, e), set()).update(local)
            x = blk.solid.X[nodes] + self.U[blk.offset + nodes]
            geometry.append((x[local], x.mean(axis=0)))
        force, moment = np.zeros(3), np.zeros(3)
        by_block: dict[int, list[int]] = {}
        for b, e in per_element:
            by_block.setdefault(b, []).append(e)
        for b, els in by_block.items():
            blk = self.blocks[b]
            U = self.U[blk.offset: blk.offset + blk.n_nodes]
            fe = element_forces(blk.solid, U, self.run.state.elements[b], els)
            cells = self.cells(b)
            for e in els:
                local = sorted(per_element[(b, e)])
                nodes = cells[e][1][local]
                f = fe[e][local]
                x = blk.solid.X[nodes] + U[nodes]
                force += f.sum(axis=0)
                moment += np.cross(x, f).sum(axis=0)
        area, centre, normal = 0.0, np.zeros(3), np.zeros(3)
        for x, inside in geometry:
            N, dN, w = any_face(len(x))
            a1, a2 = np.einsum("ga,ai->gi", dN[:, :, 0], x), np.einsum("ga,ai->gi", dN[:, :, 1], x)
            nv = np.cross(a1, a2)
            if np.einsum("gi,i->", nv, x.mean(axis=0) - inside) < 0.0:   # outward of the element
                nv = -nv
            da = np.linalg.norm(nv, axis=1) * w
            area += da.sum()
            centre += np.einsum("g,ga,ai->i", da, N, x)
            normal += np.einsum("g,gi->i", w, nv)
        if area > 0.0:
            centre, normal = centre / area, normal / area
        mcg = moment - np.cross(centre, force)
        fn = float(force @ normal)
        torque = float(mcg @ normal)
        t = fortran_e(self.time)
        return [f"\n\n\n statistics for surface set {surface} and time {t}\n\n",
                "   total surface force (fx,fy,fz) and moment about the origin(mx,my,mz)\n\n",
                "  " + _row([*force, *moment]) + "\n\n",
                "   center of gravity and mean normal\n\n",
                "  " + _row([*centre, *normal]) + "\n\n",
                "   moment about the center of gravity(mx,my,mz)\n\n",
                "  " + _row(mcg) + "\n\n",
                "   area, normal force (+ = tension), shear force (size), torque and bending moment (size)\n\n",
                "  " + _row([area, fn, np.linalg.norm(force - fn * normal), torque,
                             np.linalg.norm(mcg - torque * normal)]) + "\n"]
