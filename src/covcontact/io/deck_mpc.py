"""A deck's *MPC (CalculiX's nonlinear multi-point constraints): PLANE, STRAIGHT and BEAM become ``[[mpc]]`` entries
(``covcontact.solvers.mpc``: the same dependent dofs, eliminated exactly); MEANROT, DIST and user MPCs are listed as
unsupported with one line each (docs/input.md, "Abaqus and CalculiX decks").

As CalculiX reads the card: its first line names the MPC and starts the list of nodes, the lines after it continue
the list (node labels or node set names; zeros are dropped); one MPC per card. Where a node's dependent dof is the
dependent dof of an earlier MPC already, CalculiX warns and leaves that node's constraint out (planempc.f,
straightmpc.f): so does the import, with a note. CalculiX allows these MPCs on no node of its expanded (shell, beam,
plane, axisymmetric) elements; a node of those, or of no element, is listed as unsupported.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..loads import KINDS, degenerate, dependent_components
from .deck import Card, DeckError

#: *MPC types covcontact does not read: what they are, for the line that lists them
_OTHER = {"MEANROT": "a mean rotation (a rotation dof of an extra node)",
          "DIST": "a maximum distance (an inequality)"}
_COMP = ("x", "y", "z")


@dataclass
class DeckMPC:
    """One *MPC card: its type, the entries of its node list as written (labels or set names), the card's line."""

    kind: str
    entries: list[str]
    where: str


def read_mpc_card(reader, c: Card) -> None:
    """*MPC (model data): the type on the first line, then the nodes (kept in ``DeckModel.mpcs``)."""
    if reader.step is not None:
        raise c.fail("is model data: it belongs before the first *STEP")
    for p, v in c.params.items():  # (CalculiX warns and goes on: cgx writes *MPC, USER)
        reader.m.notes.append(f"{c.where()}: *MPC, {p}{'=' + v if v else ''}: the card takes no parameters; ignored, "
                              f"as CalculiX ignores it")
    rows = [[f.strip() for f in row if f.strip()] for row in c.rows()]
    if not rows or not rows[0]:
        raise c.fail("needs its line 'type, nodes...' (PLANE, STRAIGHT, BEAM, MEANROT, DIST or a user MPC's name)")
    kind = rows[0][0].upper()
    if kind == "1":  # (CalculiX's old name of MEANROT, which cgx still writes)
        kind = "MEANROT"
    entries = [f for row in [rows[0][1:]] + rows[1:] for f in row if f != "0"]
    if kind in _OTHER and entries and entries[-1].isdigit():  # (its extra node: loads on it act on nothing here)
        reader.m.unsupported_nodes[int(entries[-1])] = f"{c.where()}: *MPC {kind}"
    if not hasattr(reader.m, "mpcs"):
        reader.m.mpcs = []
    reader.m.mpcs.append(DeckMPC(kind, entries, c.where()))


class DeckMPCs:
    """The ``[[mpc]]`` entries of an import (``writer``: the DeckImport)."""

    def __init__(self, writer):
        self.w, self.m = writer, writer.m

    def entries(self) -> list[dict]:
        from .deck_planar import _planar_bodies

        out: list[dict] = []
        index = self.m.node_index()
        taken: set[tuple[int, int]] = set()   # (node label, dof 0..2) on the dependent side of an earlier MPC
        planar = _planar_bodies(self.w)
        for k, mpc in enumerate(getattr(self.m, "mpcs", [])):
            if mpc.kind not in ("PLANE", "STRAIGHT", "BEAM"):
                what = _OTHER.get(mpc.kind, "a user MPC")
                self.w.unsupported.append(f"{mpc.where}: *MPC {mpc.kind} ({what}, a nonlinear constraint) is not "
                                          f"supported: covcontact reads PLANE, STRAIGHT and BEAM")
                continue
            kind = mpc.kind.lower()
            labels = self._labels(mpc, index)
            nd = KINDS[kind]
            if (len(labels) != 2) if kind == "beam" else len(labels) <= nd:
                raise DeckError(f"{mpc.where}: *MPC {mpc.kind} needs "
                                + ("exactly two nodes" if kind == "beam" else f"{nd} defining nodes and at least one "
                                   f"more") + f" (found {len(labels)})")
            bodies = self.w.b.nodes_body(np.array(labels, dtype=np.int64))
            shell = self.w.shells.is_shell(np.array(labels, dtype=np.int64)) if self.w.shells.n else \
                np.zeros(len(labels), dtype=bool)
            odd = [(lab, "of shell elements") for lab, s in zip(labels, shell) if s] + \
                  [(lab, f"of {planar[int(b)]} elements") for lab, b in zip(labels, bodies) if int(b) in planar] + \
                  [(lab, "of no element") for lab, b, s in zip(labels, bodies, shell) if b < 0 and not s]
            if odd:
                lab, why = odd[0]
                self.w.unsupported.append(f"{mpc.where}: *MPC {mpc.kind} on node {lab}, a node {why}: CalculiX applies "
                                          f"these MPCs to nodes of solid elements only (covcontact: of its 3D bodies)")
                continue
            X = self.m.X[index[np.array(labels, dtype=np.int64)]]
            if degenerate(kind, X[:nd]):
                raise DeckError(f"{mpc.where}: *MPC {mpc.kind}: the defining nodes {', '.join(map(str, labels[:nd]))} "
                                + ("lie on a line" if kind == "plane" else "coincide"))
            groups = [list(range(nd))] if kind == "beam" else [list(range(nd)) + [j] for j in range(nd, len(labels))]
            kept = []
            for g in groups:
                dep = [(labels[g[i]], c) for i, c in dependent_components(kind, X[g])]
                clash = [d for d in dep if d in taken]
                if clash:
                    self.w.notes.append(f"{mpc.where}: *MPC {mpc.kind}: dof {clash[0][1] + 1} of node {clash[0][0]} is "
                                        f"the dependent dof of an earlier MPC: this node's constraint is left out, as "
                                        f"CalculiX leaves it out (with a warning)")
                    continue
                taken.update(dep)
                kept.append(labels[g[-1]])
            if not kept:
                continue
            refs = [self._single(lab, mpc.where) for lab in labels[:nd]]
            if kind != "beam":
                name = f"_MPC{k + 1}"
                while name in self.m.nsets:
                    name += "_"
                refs += [self.w._ref(*t) for t in self.w._node_targets(name, np.array(kept, dtype=np.int64),
                                                                       mpc.where)]
            out.append({"name": f"mpc{k + 1}", "type": kind, "nodes": refs})
        return out

    def _labels(self, mpc: DeckMPC, index: np.ndarray) -> list[int]:
        """The MPC's node labels in order (sets expanded in the order they were written; a node once, where it first
        comes)."""
        labels: list[int] = []
        for e in mpc.entries:
            if e.lstrip("+-").isdigit():
                lab = int(e)
                if lab < 0 or lab >= index.size or index[lab] < 0:
                    raise DeckError(f"{mpc.where}: *MPC {mpc.kind}: node {lab} is not defined by any *NODE")
                labels.append(lab)
            else:
                found = self.m.nset_order.get(e.upper(), self.m.nsets.get(e.upper()))
                if found is None:
                    raise DeckError(f"{mpc.where}: *MPC {mpc.kind}: no node set {e} (node sets are defined before "
                                    f"the *MPC)")
                labels += [int(v) for v in found]
        return list(dict.fromkeys(labels))

    def _single(self, label: int, where: str) -> str:
        (body, set_name), = self.w._node_targets(str(label), np.array([label], dtype=np.int64), where)
        return self.w._ref(body, set_name)
