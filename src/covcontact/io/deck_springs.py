"""A deck's springs and dashpots: *ELEMENT, TYPE=SPRINGA, SPRING1, SPRING2, DASHPOTA with *SPRING and *DASHPOT, mapped
to ``[[spring]]`` and ``[[dashpot]]`` (docs/input.md, "Abaqus and CalculiX decks"; ``covcontact.elements.springs``);
beam elements, which covcontact does not read, each listed with one line saying why.

Spring elements are no solids: they make no body (the importer's parts are the solid elements joined through shared
nodes) and join nodes of the bodies. An end on a node of no solid element is ground where *BOUNDARY holds it (in the
dofs the member acts in, never moved, never loaded): an axial member then goes to that point (``anchor``), a SPRING2
to ground in its other node's dof. A free node of no solid element (a spring chain's middle, a node tied by
*EQUATION) carries no unknowns in covcontact: such an element is listed as unsupported.

The model keeps, in ``DeckModel.springs`` (made here on first use), the element blocks (:class:`SpringElements`) and
the property cards (:class:`SpringCard`) in deck order.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .deck import Card, DeckError, numbers

#: the element types read here, with their node count and whether they are dashpots
SPRING_ELEMENTS = {"SPRINGA": 2, "SPRING1": 1, "SPRING2": 2, "DASHPOTA": 2}
#: the cards read here (deck_model dispatches them)
SPRING_CARDS = ("SPRING", "DASHPOT")
#: beam elements: why they are refused (CalculiX expands them into bricks; covcontact does not)
BEAMS = {etype: f"({nodes}-node beam): CalculiX expands it into {brick} bricks, covcontact does not: mesh the beam "
                f"with {brick} solid elements" for etype, nodes, brick in
         (("B31", 2, "C3D8I"), ("B31R", 2, "C3D8R"), ("B32", 3, "C3D20"), ("B32R", 3, "C3D20R"))}
@dataclass
class SpringElements:
    """One *ELEMENT block of springs or dashpots: labels (n,), nodes (n, 1 or 2) as labels, each element's line."""

    etype: str
    labels: np.ndarray
    nodes: np.ndarray
    where: list[str]


@dataclass
class SpringCard:
    """A *SPRING or *DASHPOT: its element set, the dofs line (SPRING1, SPRING2), the constant or the table."""

    kind: str                       # "SPRING" | "DASHPOT"
    elset: str
    dofs: tuple[int, ...]
    constant: float | None          # k or c
    table: list | None              # NONLINEAR: [(elongation, force), ...]
    where: str


def _store(m) -> list:
    if not hasattr(m, "springs"):
        m.springs = []
    return m.springs


def read_spring_elements(reader, c: Card, etype: str) -> None:
    """*ELEMENT, TYPE=SPRINGA | SPRING1 | SPRING2 | DASHPOTA: labels and nodes (kept apart from the solids)."""
    nen = SPRING_ELEMENTS[etype]
    a = numbers(c, 1 + nen, f"a {etype} element (label and {nen} node{'s' if nen > 1 else ''})", integer=True)
    if a.dtype != np.int64:
        if np.any(a != np.round(a)):
            raise c.fail("element and node labels are whole numbers")
        a = a.astype(np.int64)
    lines = [c.where(k) for k in range(len(c.data))] if len(c.data) == len(a) else [c.where()] * len(a)
    _store(reader.m).append(SpringElements(etype, a[:, 0], a[:, 1:], lines))
    if "ELSET" in c.params:
        reader._add(reader.m.elsets, c.params["ELSET"], a[:, 0])


def _integers(row: list[str]) -> bool:
    """CalculiX's test for the dofs line under *SPRING: whole numbers written without a decimal point."""
    return bool(row) and all(f.lstrip("+-").isdigit() for f in row if f)


def read_spring_card(reader, c: Card) -> None:
    """*SPRING, *DASHPOT (model data)."""
    m = reader.m
    if reader.step is not None:
        raise c.fail("is model data: it belongs before the first *STEP")
    for p, v in c.params.items():
        if p == "ELSET" or (p == "NONLINEAR" and c.name == "SPRING"):
            continue
        m.unsupported.append(f"{c.where()}: *{c.name}, {p}{'=' + v if v else ''} is not supported"
                             + (" (the dofs in the global axes only)" if p == "ORIENTATION" else ""))
    elset = c.param("ELSET", required=True).upper()
    rows = c.rows()
    dofs: tuple[int, ...] = ()
    if rows and _integers(rows[0]):
        if c.name == "DASHPOT":
            raise c.fail("a dashpot's line is 'coefficient' (DASHPOTA acts along its line: no dofs line)", 0)
        dofs = tuple(int(f) for f in rows[0] if f)
        rows = rows[1:]
        start = 1
    else:
        start = 0
    if not rows:
        raise c.fail(f"needs its {'spring constant' if c.name == 'SPRING' else 'dashpot coefficient'} (a line after "
                     f"the dofs line for SPRING1 and SPRING2; real numbers with a decimal point)")
    if c.name == "SPRING" and "NONLINEAR" in c.params:  # (lines 'force, elongation, temperature')
        temps = [c.number(start + k, 2, r, "the temperature", 0.0) for k, r in enumerate(rows)]
        keep = [k for k in range(len(rows)) if temps[k] == temps[0]]
        if len(keep) < len(rows):
            m.unsupported.append(f"{c.where()}: *SPRING, NONLINEAR at several temperatures is not supported; with "
                                 f"--ignore-unsupported the curve at the first temperature, {temps[0]:g}, is used")
        pts = [(c.number(start + k, 1, rows[k], "the elongation"), c.number(start + k, 0, rows[k], "the force"))
               for k in keep]
        if len(pts) < 2:
            raise c.fail("NONLINEAR needs at least two lines 'force, elongation'", start)
        if any(b[0] <= a[0] for a, b in zip(pts, pts[1:])):
            raise c.fail("the elongations of a NONLINEAR spring must increase from line to line", start)
        _store(m).append(SpringCard(c.name, elset, dofs, None, pts, c.where()))
        return
    if len(rows) > 1:
        what = "temperatures" if c.name == "SPRING" else "frequencies or temperatures"
        m.unsupported.append(f"{c.where()}: *{c.name} depending on {what} ({len(rows)} lines) is not supported; with "
                             f"--ignore-unsupported the first line's constant is used")
    value = c.number(start, 0, rows[0], "the spring constant" if c.name == "SPRING" else "the dashpot coefficient")
    if not value > 0.0:
        raise c.fail(f"the {'spring constant' if c.name == 'SPRING' else 'dashpot coefficient'} must be > 0, got "
                     f"{value:g}", start)
    _store(m).append(SpringCard(c.name, elset, dofs, value, None, c.where()))


class DeckSprings:
    """The springs and dashpots of a deck as ``[[spring]]`` and ``[[dashpot]]`` entries, for the importer ``writer``
    (``covcontact.io.deck_import``: its model, parts, node sets and lists of unsupported lines and notes)."""

    _COMP = "xyz"

    def __init__(self, writer):
        self.w, self.m = writer, writer.m
        self.items = [s for s in getattr(self.m, "springs", []) if isinstance(s, SpringElements)]
        self.cards = [s for s in getattr(self.m, "springs", []) if isinstance(s, SpringCard)]
        self._held = None

    def entries(self) -> list[tuple[str, dict]]:
        """("[[spring]]" or "[[dashpot]]", its keys) of every member, in the deck's order."""
        if not self.items:
            for card in self.cards:
                raise DeckError(f"{card.where}: *{card.kind}, ELSET={card.elset}: no spring or dashpot element in it")
            return []
        element = {}
        for blk in self.items:
            for lab, nodes, where in zip(blk.labels, blk.nodes, blk.where):
                if int(lab) in element or int(lab) in self.w.b.el_labels:
                    raise DeckError(f"{where}: *ELEMENT: element {int(lab)} is defined twice (element labels are "
                                    f"unique in a deck)")
                element[int(lab)] = (blk.etype, nodes, where)
        card_of: dict[int, SpringCard] = {}
        for card in self.cards:
            labels = self.m.elsets.get(card.elset)
            if labels is None:
                raise DeckError(f"{card.where}: *{card.kind}, ELSET={card.elset}: no *ELSET of that name")
            for lab in labels:
                lab = int(lab)
                if lab not in element:
                    raise DeckError(f"{card.where}: *{card.kind}, ELSET={card.elset}: element {lab} is no spring or "
                                    f"dashpot element")
                etype = element[lab][0]
                if (etype == "DASHPOTA") != (card.kind == "DASHPOT"):
                    raise DeckError(f"{card.where}: *{card.kind}, ELSET={card.elset}: element {lab} is a {etype} "
                                    f"({'*DASHPOT' if etype == 'DASHPOTA' else '*SPRING'} gives its constant)")
                if lab in card_of:
                    raise DeckError(f"{card.where}: *{card.kind}: element {lab} has its constant from "
                                    f"{card_of[lab].where} already")
                card_of[lab] = card
        dynamic = any(st.dynamic for st in self.m.steps)
        if not dynamic:
            for card in self.cards:
                if card.kind == "DASHPOT":
                    self.w.notes.append(f"{card.where}: *DASHPOT, ELSET={card.elset}: no *DYNAMIC step, so its "
                                        f"dashpots do nothing (they act on velocities; left out)")
        out = []
        grouped: dict[tuple, list] = {}   # (card, dof) -> the SPRING1 elements on body nodes: one entry per body
        for lab, (etype, nodes, where) in element.items():
            card = card_of.get(lab)
            if card is None:
                dash = etype == "DASHPOTA"
                raise DeckError(f"{where}: {etype} element {lab} has no {'*DASHPOT' if dash else '*SPRING'} (its "
                                f"{'coefficient' if dash else 'constant'}) over an element set")
            if etype == "DASHPOTA" and not dynamic:
                continue
            if etype == "SPRING1" and card.dofs and 1 <= card.dofs[0] <= 3 and \
                    self.w.b.nodes_body(np.array([nodes[0]]))[0] >= 0:
                grouped.setdefault((id(card), card.dofs[0]), []).append((lab, nodes, where, card))
                continue
            entry = self._entry(lab, etype, nodes, card, where)
            if entry is not None:
                out.append(("[[dashpot]]" if etype == "DASHPOTA" else "[[spring]]", entry))
        for (_, dof), members in grouped.items():
            labels = np.array([int(nodes[0]) for _, nodes, _, _ in members], dtype=np.int64)
            card = members[0][3]
            if len(members) == 1 or np.unique(labels).size < labels.size:  # (a node twice: an entry per element)
                out += [("[[spring]]", self._entry(lab, "SPRING1", nodes, c, w)) for lab, nodes, w, c in members]
                continue
            name = f"_SPRING1_{card.elset}_{dof}"
            while name in self.m.nsets:
                name += "_"
            law = {"stiffness": card.constant} if card.table is None else {"table": [list(p) for p in card.table]}
            for body, set_name in self.w._node_targets(name, np.sort(labels), card.where):
                out.append(("[[spring]]", {"name": f"{card.elset}_{self._COMP[dof - 1]}", "type": "dof",
                                           "nodes": [self.w._ref(body, set_name)], "dofs": [self._COMP[dof - 1]],
                                           **law}))
        return out

    # -- the ends ---------------------------------------------------------------------------------------------------
    def _held_dofs(self) -> dict[int, set[int]]:
        """Node label -> the dofs 1..3 *BOUNDARY holds at zero (model data or a step), less those any *BOUNDARY moves
        or any *CLOAD loads."""
        if self._held is None:
            held: dict[int, set[int]] = {}
            moved: set[tuple[int, int]] = set()
            for b in list(self.m.model_boundary) + [b for st in self.m.steps for b in st.boundary]:
                for n in b.nodes:
                    for d in b.dofs:
                        if b.value in (None, 0.0) and not b.fixed and b.amplitude is None:
                            held.setdefault(int(n), set()).add(d)
                        else:
                            moved.add((int(n), d))
            for st in self.m.steps:
                for ld in st.loads:
                    if ld.kind == "cload" and ld.value != 0.0:
                        moved.update((int(n), ld.dof) for n in ld.nodes)
            self._held = {n: {d for d in ds if (n, d) not in moved} for n, ds in held.items()}
        return self._held

    def _end(self, label: int, where: str) -> str | None:
        """"BODY.SET" of a node of a body (a set of that one node), None for a node of no solid element."""
        targets = self.w._node_targets(str(label), np.array([label], dtype=np.int64), where)
        return self.w._ref(*targets[0]) if targets else None

    def _free(self, etype: str, lab: int, node: int, dofs, where: str) -> None:
        self.w.unsupported.append(
            f"{where}: {etype} element {lab}: its node {node} belongs to no solid element and is not held in "
            f"{'all of dofs' if len(dofs) > 1 else 'dof'} {', '.join(map(str, dofs))} (a free node of springs alone): "
            f"covcontact's springs join nodes of solid elements, or such a node to a fixed point; with "
            f"--ignore-unsupported the element is left out")

    def _entry(self, lab: int, etype: str, nodes: np.ndarray, card: SpringCard, where: str) -> dict | None:
        index = self.m.node_index()
        for n in nodes:
            if n >= index.size or index[n] < 0:
                raise DeckError(f"{where}: *ELEMENT: element {lab} refers to node {int(n)}, which no *NODE defines")
        nodes = [int(n) for n in nodes]
        shell = [n for n in nodes if self.w.shells.n and self.w.shells.is_shell(np.array([n]))[0]]
        if shell:  # (its two layers: no single node for the spring's end)
            self.w.unsupported.append(f"{where}: {etype} element {lab}: its node {shell[0]} is a shell node (two "
                                      f"nodes here, bottom and top): springs and dashpots on shell nodes are not "
                                      f"supported; with --ignore-unsupported the element is left out")
            return None
        ends = [self._end(n, where) for n in nodes]
        law = ({"coefficient": card.constant} if etype == "DASHPOTA" else
               {"stiffness": card.constant} if card.table is None else {"table": [list(p) for p in card.table]})
        held = self._held_dofs()
        if etype in ("SPRINGA", "DASHPOTA"):
            if card.dofs:
                raise DeckError(f"{card.where}: *SPRING, ELSET={card.elset}: a dofs line for the {etype} element {lab} "
                                f"(it acts along its line; real constants need a decimal point)")
            grounded = [k for k in (0, 1) if ends[k] is None]
            for k in grounded:
                if not {1, 2, 3} <= held.get(nodes[k], set()):
                    self._free(etype, lab, nodes[k], (1, 2, 3), where)
                    return None
            if len(grounded) == 2:
                self.w.notes.append(f"{where}: {etype} element {lab} joins two held nodes of no solid element: it does "
                                    f"nothing (left out)")
                return None
            if grounded:
                body = ends[1 - grounded[0]]
                anchor = self.m.X[index[nodes[grounded[0]]]]
                return {"name": f"E{lab}", "nodes": [body], "anchor": [float(v) for v in anchor], **law}
            return {"name": f"E{lab}", "nodes": ends, **law}
        need = 1 if etype == "SPRING1" else 2
        if len(card.dofs) < need or any(not 1 <= d <= 6 for d in card.dofs[:need]):
            raise DeckError(f"{card.where}: *SPRING, ELSET={card.elset}: the {etype} element {lab} needs its first "
                            f"line '{'dof' if need == 1 else 'dof of node 1, dof of node 2'}' (whole numbers 1..6)")
        dofs = card.dofs[:need]
        if any(d > 3 for d in dofs):
            self.w.unsupported.append(f"{card.where}: *SPRING, ELSET={card.elset}: dof {max(dofs)} of the {etype} "
                                      f"element {lab} is a rotation, which solid nodes do not have; with "
                                      f"--ignore-unsupported the element is left out")
            return None
        comps = [self._COMP[d - 1] for d in dofs]
        base = {"name": f"E{lab}", "type": "dof"}
        if etype == "SPRING1":
            if ends[0] is None:
                if dofs[0] not in held.get(nodes[0], set()):
                    self._free(etype, lab, nodes[0], dofs, where)
                return None
            return {**base, "nodes": ends, "dofs": comps, **law}
        grounded = [k for k in (0, 1) if ends[k] is None]
        for k in grounded:
            if dofs[k] not in held.get(nodes[k], set()):
                self._free(etype, lab, nodes[k], dofs[k:k + 1], where)
                return None
        if len(grounded) == 2:
            return None
        if not grounded:
            return {**base, "nodes": ends, "dofs": comps, **law}
        k = 1 - grounded[0]
        if k == 1 and "table" in law:  # (node 2 alone: e = -u2 . n2, its force -f(e) n2: the curve g(e) = -f(-e))
            law = {"table": [[-e, -f] for e, f in reversed(law["table"])]}
        return {**base, "nodes": [ends[k]], "dofs": [comps[k]], **law}
