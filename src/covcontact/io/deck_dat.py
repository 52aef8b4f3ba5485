"""The ``.dat`` table of a deck's run: the *NODE PRINT requests (U: displacements, RF: forces; a rigid body's REF and
ROT nodes too), *EL PRINT (S, PEEQ at the Gauss points) and *CONTACT PRINT (CSTRESS) at the end of each step, in
CalculiX's layout, with the deck's node and element labels (docs/input.md, "Abaqus and CalculiX decks")."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..contact.reference import tangent_map
from ..observer import Observer

_BLOCK = {"U": "displacements (vx,vy,vz)", "RF": "forces (fx,fy,fz)"}


def fortran_e(x: float) -> str:
    """x as CalculiX prints a time: 0.dddddddE+xx."""
    if x == 0.0:
        return " 0.0000000E+00"
    e = int(np.floor(np.log10(abs(x)))) + 1
    m = x / 10.0 ** e
    if abs(round(m, 7)) >= 1.0:
        m, e = m / 10.0, e + 1
    return f"{m:10.7f}" + f"E{e:+03d}"


class DatTable(Observer):
    """Writes ``path`` (the .dat table) from the labels file of :func:`covcontact.io.deck_import.import_deck`."""

    def __init__(self, labels: Path, path: Path, deck: dict | None = None):
        self.info = json.loads(Path(labels).read_text())
        self.path = Path(path)
        self.deck = deck
        self.count: dict[int, int] = {}  # converged increments of each deck step so far

    def started(self, run) -> None:
        if run.model.is_root:
            self.path.write_text("")
        summary = getattr(run, "summary", None)
        if self.deck is not None and summary is not None:  # (summary.json: what was ignored and filled in)
            summary.data["deck"] = dict(self.deck)

    def _due(self, inc) -> bool:
        """Whether this converged increment prints: the end of a step or of a time point, or every Nth increment
        of the deck step (FREQUENCY; CalculiX's default: every increment)."""
        stage = inc.state.stage
        steps = self.info.get("deck_step", [])
        ends = self.info.get("print_end")
        if ends is None or stage >= len(ends):  # (a labels file without output times: the step's end)
            return bool(inc.ends_stage)
        deck_step = steps[stage]
        self.count[deck_step] = self.count.get(deck_step, 0) + 1
        every = self.info["print_every"][stage]
        return bool(inc.ends_stage and ends[stage]) or (every > 0 and self.count[deck_step] % every == 0)

    def increment_converged(self, run, inc) -> None:
        if not self._due(inc):
            return
        stage = inc.state.stage
        prints = self.info["node_print"][stage] if stage < len(self.info["node_print"]) else []
        el_prints = self.info.get("el_print", [])
        contact_prints = self.info.get("contact_print", [])
        if not prints and not (stage < len(el_prints) and el_prints[stage]) and not (
                stage < len(contact_prints) and "CSTRESS" in contact_prints[stage]):
            return
        model = run.model
        sysm = model.system
        where = {}  # deck node label -> global node
        for blk in sysm.blocks:
            labels = self.info["bodies"].get(blk.name, [])
            where.update(zip(labels, range(blk.offset, blk.offset + len(labels))))
        R, _, _ = model.evaluate(run.u, inc.lam, run.state, want_K=False, raw=True)
        forces = (R + model.external(inc.lam)).reshape(-1, 3)  # internal and contact forces at each node
        refs = {ref.name: ref for ref in sysm.reference}
        rigid = self.info.get("rigid", {})
        if any(lab is not None for labels in rigid.values() for lab in labels):  # (the constraints hand R over)
            Rr = model.constraints.transform(R, None)[0].reshape(-1, 3)
        for name, (ref_label, rot_label) in rigid.items():
            # a rigid body's REF node: its translation and the attached nodes' pull, ROT node: its rotation vector
            # and the moment on it (the residual after the attached nodes hand their forces over, plus the load)
            ref = refs[name]
            if ref_label is not None or rot_label is not None:
                force, moment = model.loading.rigid_load(name, inc.lam)
                forces[ref.A] = Rr[ref.A] + force
                forces[ref.B] = Rr[ref.B] + tangent_map(run.u[3 * ref.B: 3 * ref.B + 3]).T @ moment
            for lab, node in ((ref_label, ref.A), (rot_label, ref.B)):
                if lab is not None:
                    where[lab] = node
        U = run.u.reshape(-1, 3)
        time = sum(self.info["periods"][:stage]) + self.info["periods"][stage] * inc.lam
        text = []
        for nset, variables, *opt in prints:
            totals = opt[0] if opt else "NO"
            labels = [lab for lab in self.info["nsets"][nset] if lab in where]
            rows = np.array([where[lab] for lab in labels], dtype=np.int64)
            for var in variables:
                if var not in _BLOCK:
                    continue
                values = U[rows] if var == "U" else forces[rows]
                if var != "RF" or totals != "ONLY":
                    text.append(f"\n {_BLOCK[var]} for set {nset} and time {fortran_e(time)}\n\n")
                    text += [f"{lab:10d}" + "".join(f"{v:14.6E}" for v in row) + "\n"
                             for lab, row in zip(labels, values)]
                if var == "RF" and totals in ("YES", "ONLY"):  # (CalculiX sums the external forces only)
                    total = values.sum(axis=0) if len(values) else np.zeros(3)
                    text.append(f"\n total force (fx,fy,fz) for set {nset} and time {fortran_e(time)}\n\n")
                    text.append("      " + "".join(f"{v:14.6E}" for v in total) + "\n")
        text += self._el_print(model, run, stage, time)
        if stage < len(contact_prints) and "CSTRESS" in contact_prints[stage]:
            text += self._contact_stress(model, run, inc.lam, where, time)
        if model.is_root:
            with open(self.path, "a") as fh:
                fh.write("".join(text))

    def _el_print(self, model, run, stage: int, time: float) -> list[str]:
        """The *EL PRINT blocks of S (the Cauchy stress at each Gauss point, in CalculiX's component order xx, yy, zz,
        xy, xz, yz) and PEEQ (the equivalent plastic strain there), in CalculiX's point numbering (the first
        direction of the element's coordinates fastest)."""
        el_prints = self.info.get("el_print", [])
        if stage >= len(el_prints) or not any("S" in v or "PEEQ" in v for _, v in el_prints[stage]):
            return []
        from ..elements.points import point_plastic_strains, point_stresses

        sysm = model.system
        rows, peeq = {}, {}   # element label -> (n_points, 6), (n_points,)
        U = run.u.reshape(-1, 3)
        for blk, est in zip(sysm.blocks, run.state.elements):
            labels = self.info["elements"].get(blk.name, [])
            try:
                s = point_stresses(blk.solid, U[blk.offset: blk.offset + blk.n_nodes], est)
            except ValueError:
                continue
            rows.update(zip(labels, s[:, :, [0, 1, 2, 3, 5, 4]]))
            p = point_plastic_strains(blk.solid, est)
            if p is None:  # (an elastic body: zero at its points)
                p = np.where(np.isnan(s[:, :, 0]), np.nan, 0.0)
            peeq.update(zip(labels, p[:, :, None]))
        text = []
        for elset, variables in el_prints[stage]:
            for var, head, table in (("S", "stresses (elem, integ.pnt.,sxx,syy,szz,sxy,sxz,syz)", rows),
                                     ("PEEQ", "equivalent plastic strain (elem, integ.pnt.,pe)", peeq)):
                if var not in variables:
                    continue
                gap = "" if var == "PEEQ" else " "  # (CalculiX's own headers: PEEQ's has no space before "for")
                text.append(f"\n {head}{gap}for set {elset} and time {fortran_e(time)}\n\n")
                for lab in self.info["elsets"][elset]:
                    if lab not in table:
                        continue
                    text += [f"{lab:10d}{g + 1:4d}" + "".join(f"{v:14.6E}" for v in row) + "\n"
                             for g, row in enumerate(table[lab]) if not np.isnan(row[0])]
        return text

    @staticmethod
    def _contact_stress(model, run, lam: float, where: dict, time: float) -> list[str]:
        """*CONTACT PRINT CSTRESS: per active slave node of the node-to-surface pairs on meshed masters, the contact
        pressure (the normal force over the node's tributary area, positive in compression) and the tangential
        traction in the master's frame at the contact point (n along the gap vector, which is the facet's normal at a
        facet point and the direction from the point at an edge or vertex; tang1 along rho_1 projected off n,
        tang2 = n x tang1; CalculiX's own tangential axes are its element's, so compare their magnitude)."""
        from ..contact.surface import facet_frame

        manager = model.contact
        state = run.state.contact
        label = {node: lab for lab, node in where.items()}
        xe = manager.extended(model.positions(run.u), lam)
        rows = []
        rho, t1, t2, n = np.empty(3), np.empty(3), np.empty(3), np.empty(3)
        for k, p in enumerate(manager.passes):
            if p.kind != "nts" or p.surface is None or p.tied:
                continue
            s = state.passes[k]
            for j in np.flatnonzero(manager.active_mask(k, state) & (s.facet >= 0)):
                if int(p.slaves[j]) not in label:
                    continue
                xyz = np.ascontiguousarray(xe[p.surface.faces[s.facet[j]]])
                facet_frame(xyz, float(s.xi[j, 0]), float(s.xi[j, 1]), rho, t1, t2, n)
                d = xe[p.slaves[j]] - rho   # g n: the contact normal also at an edge or vertex point
                if abs(s.gap[j]) > 1e-9 * np.linalg.norm(t1):
                    n = d / s.gap[j]
                    n /= np.linalg.norm(n)
                f = s.force[j] / p.area[j]
                e1 = t1 - (t1 @ n) * n
                e1 /= np.linalg.norm(e1)
                e2 = np.cross(n, e1)
                rows.append((label[int(p.slaves[j])], f @ n, f @ e1, f @ e2))
        if not rows:
            return []
        text = [f"\n contact stress (slave node,press,tang1,tang2) for all contact elements and time {fortran_e(time)}"
                f"\n\n"]
        text += [f"{lab:10d}" + "".join(f"{v:14.6E}" for v in vals) + "\n" for lab, *vals in sorted(rows)]
        return text
