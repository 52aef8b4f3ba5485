"""The cards of a deck that prescribe and load: *BOUNDARY, *CLOAD, *DLOAD (face pressures, GRAV, CENTRIF) with their
amplitudes' TIME DELAY, read into :class:`Boundary` and :class:`Load` entries of the model or of its steps
(docs/input.md, "Abaqus and CalculiX decks"). :class:`LoadCards` is a part of the deck reader
(``covcontact.io.deck_model``), which keeps the model (``self.m``) and the step being read (``self.step``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .deck import Card


@dataclass
class Boundary:
    """A *BOUNDARY entry: node labels, dofs (1..6: 4-6 the rotations of a reference node) and value (None: fixed at
    zero)."""

    nodes: np.ndarray
    dofs: tuple[int, ...]
    value: float | None
    where: str
    name: str            # the set name or node label as written
    amplitude: str | None = None
    fixed: bool = False  # *BOUNDARY, FIXED: held at the displacement the step finds
    delay: float = 0.0   # TIME DELAY: the amplitude read at t - delay


@dataclass
class Load:
    """*CLOAD (node labels, dof, magnitude per node) or *DLOAD (element faces, pressure)."""

    kind: str            # "cload" | "dload" | "grav" | "centrif"
    target: str          # set name or label as written
    dof: int             # CLOAD: 1..6 (4-6: a moment on a reference node); DLOAD: face number 1..6
    value: float
    where: str
    nodes: np.ndarray | None = None
    elements: np.ndarray | None = None
    amplitude: str | None = None
    direction: tuple[float, float, float] | None = None   # GRAV: the unit direction (value: the magnitude)
    point: tuple[float, float, float] | None = None       # CENTRIF: a point of the axis (direction: the axis)
    delay: float = 0.0   # TIME DELAY: the amplitude read at t - delay
    edge: int = 0        # EDNORk on shell elements: their edge k (force per length normal to it, in the shell)


class LoadCards:
    """The reader's methods for the cards that prescribe and load (see the module)."""

    def _resolve_nodes(self, c: Card, k: int, ref: str) -> np.ndarray:
        if ref.isdigit():
            return np.array([int(ref)], dtype=np.int64)
        if ref.upper() in self.m.nsets:
            return self.m.nsets[ref.upper()]
        raise c.fail(f"{ref!r} is neither a node label nor a *NSET defined above", k)

    @staticmethod
    def _delay(c: Card) -> float:
        """TIME DELAY= of a *BOUNDARY, *CLOAD or *DLOAD with an amplitude (0 without)."""
        text = c.param("TIME DELAY")
        if text is None:
            return 0.0
        if c.param("AMPLITUDE") is None:
            raise c.fail("TIME DELAY shifts an amplitude: it needs AMPLITUDE= as well")
        try:
            return float(text)
        except ValueError:
            raise c.fail(f"TIME DELAY must be a number, got {text!r}") from None

    def _boundary(self, c: Card) -> None:
        out = []
        for k, row in enumerate(c.rows()):
            if len(row) < 2:
                raise c.fail("a boundary line is 'node or set, first dof[, last dof[, value]]'", k)
            first = int(c.number(k, 1, row, "the first dof"))
            last = int(c.number(k, 2, row, "the last dof", first))
            value = c.number(k, 3, row, "the value") if len(row) > 3 and row[3] else None
            # (dofs 4-6: a reference node's rotations, else listed at import: covcontact.io.deck_coupling)
            dofs = tuple(d for d in range(first, last + 1) if 1 <= d <= 6)
            if any(d > 6 for d in range(first, last + 1)):
                self.m.unsupported.append(f"{c.where(k)}: *BOUNDARY on dofs above 6 (temperature, ...)")
            if dofs:
                out.append(Boundary(self._resolve_nodes(c, k, row[0]), dofs, value, c.where(k), row[0].upper(),
                                    c.param("AMPLITUDE"), "FIXED" in c.params, self._delay(c)))
        if self.step is None:  # (model data: in force from the first step on, a value reached over it)
            if c.params.get("OP", "MOD").upper() == "NEW":
                raise c.fail("OP=NEW belongs inside a *STEP")
            self.m.model_boundary += out
        else:
            self.step.boundary += out
            self.step.boundary_new |= c.params.get("OP", "MOD").upper() == "NEW"

    def _load(self, c: Card) -> None:
        st = self._in_step(c)
        kind = "dload" if c.name == "DSLOAD" else c.name.lower()   # (CalculiX keeps both as distributed loads)
        if c.params.get("OP", "MOD").upper() == "NEW":
            st.loads_new.add(kind)
        for k, row in enumerate(c.rows()):
            if c.name == "DSLOAD":  # 'surface, P, magnitude': the pressure on each face of an element surface
                if len(row) < 3:
                    raise c.fail("a *DSLOAD line is 'surface, P, magnitude'", k)
                if row[1].upper() != "P":
                    self.m.unsupported.append(f"{c.where(k)}: *DSLOAD type {row[1]} (the pressure P is read)")
                    continue
                name = row[0].upper()
                surf = self.m.surfaces.get(name)
                if surf is None or name in getattr(self.m, "shell_surfaces", {}):
                    raise c.fail(f"{row[0]!r} is no element *SURFACE of solid or planar elements defined above" if
                                 surf is None else f"*DSLOAD on the shell surface {row[0]}: not supported (*DLOAD P "
                                 f"on the shell elements is)", k)
                if surf[0] != "ELEMENT":
                    raise c.fail(f"the surface {row[0]} is a node surface: *DSLOAD needs element faces", k)
                value = c.number(k, 2, row, "the magnitude")
                by_face: dict[int, list] = {}   # (one load per face number: the surface's lines grouped)
                for els, face, _ in surf[1]:
                    by_face.setdefault(face, []).append(np.asarray(els, dtype=np.int64))
                for face, parts in by_face.items():
                    st.loads.append(Load("dload", name, face, value, c.where(k), elements=np.concatenate(parts),
                                         amplitude=c.param("AMPLITUDE"), delay=self._delay(c)))
                continue
            if c.name == "CLOAD":
                if len(row) < 3:
                    raise c.fail("a *CLOAD line is 'node or set, dof, magnitude'", k)
                dof = int(c.number(k, 1, row, "the dof"))
                if not 1 <= dof <= 6:  # (4-6: a moment on a reference node, else listed at import)
                    self.m.unsupported.append(f"{c.where(k)}: *CLOAD on dof {dof} (forces 1..3, moments 4..6 on a "
                                              f"reference node)")
                    continue
                st.loads.append(Load("cload", row[0].upper(), dof, c.number(k, 2, row, "the magnitude"), c.where(k),
                                     nodes=self._resolve_nodes(c, k, row[0]), amplitude=c.param("AMPLITUDE"),
                                     delay=self._delay(c)))
            else:
                if len(row) < 3:
                    raise c.fail("a *DLOAD line is 'element or set, Pn, magnitude'", k)
                lab = row[1].upper()
                if lab == "CENTRIF":  # a spin: omega^2, a point of the axis, the axis' direction
                    if len(row) < 9:
                        raise c.fail("a CENTRIF load is 'element set, CENTRIF, omega^2, x, y, z, ax, ay, az' (a point "
                                     "of the axis and its direction)", k)
                    ref = row[0].upper()
                    els = self.m.element_set(ref) if not ref.isdigit() else np.array([int(ref)])
                    if els is None:
                        raise c.fail(f"{row[0]!r} is neither an element label nor an *ELSET defined above", k)
                    w2 = c.number(k, 2, row, "omega^2")
                    pt = tuple(c.number(k, 3 + i, row, "the point of the axis") for i in range(3))
                    ax = np.array([c.number(k, 6 + i, row, "the axis") for i in range(3)])
                    if w2 < 0.0:
                        raise c.fail(f"omega^2 must be >= 0, got {w2}", k)
                    if not np.linalg.norm(ax) > 0:
                        raise c.fail("the axis of CENTRIF must not be zero", k)
                    st.loads.append(Load("centrif", ref, 0, w2, c.where(k), elements=els,
                                         amplitude=c.param("AMPLITUDE"), direction=tuple(ax / np.linalg.norm(ax)),
                                         point=pt, delay=self._delay(c)))
                    continue
                if lab == "GRAV":  # gravity: magnitude, direction
                    if len(row) < 6:
                        raise c.fail("a GRAV load is 'element set, GRAV, magnitude, nx, ny, nz'", k)
                    ref = row[0].upper()
                    els = self.m.element_set(ref) if not ref.isdigit() else np.array([int(ref)])
                    if els is None:
                        raise c.fail(f"{row[0]!r} is neither an element label nor an *ELSET defined above", k)
                    g = c.number(k, 2, row, "the magnitude")
                    n = np.array([c.number(k, 3 + i, row, "the direction") for i in range(3)])
                    if not np.linalg.norm(n) > 0:
                        raise c.fail("the direction of GRAV must not be zero", k)
                    st.loads.append(Load("grav", ref, 0, g, c.where(k), elements=els, amplitude=c.param("AMPLITUDE"),
                                         direction=tuple(n / np.linalg.norm(n)), delay=self._delay(c)))
                    continue
                if lab == "P":  # (a shell's pressure, without a face number: deck_shells; refused on solids)
                    lab = "P0"
                edge = 0
                if lab[:5] == "EDNOR" and lab[5:] in ("1", "2", "3", "4"):  # (a shell edge's load: deck_shells)
                    edge, lab = int(lab[5:]), "P0"
                if not (lab.startswith("P") and lab[1:].isdigit()):
                    self.m.unsupported.append(f"{c.where(k)}: *DLOAD type {row[1]} (face pressures P1..P6, shell edge "
                                              f"loads EDNOR1..EDNOR4, GRAV and CENTRIF are read)")
                    continue
                ref = row[0].upper()
                els = np.array([int(ref)], dtype=np.int64) if ref.isdigit() else self.m.element_set(ref)
                if els is None:
                    raise c.fail(f"{row[0]!r} is neither an element label nor an *ELSET defined above", k)
                st.loads.append(Load("dload", ref, int(lab[1:]), c.number(k, 2, row, "the magnitude"), c.where(k),
                                     elements=els, amplitude=c.param("AMPLITUDE"), delay=self._delay(c), edge=edge))
