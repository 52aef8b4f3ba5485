"""An Abaqus or CalculiX deck as a covcontact problem: ``covcontact import DECK.inp`` and ``covcontact run DECK.inp``
(docs/input.md, "Abaqus and CalculiX decks").

:func:`import_deck` maps a :class:`covcontact.io.deck_model.DeckModel` onto covcontact's own input: a mesh file
(``NAME.mesh.K.inp`` for body K: its nodes, elements, sets and surfaces, in the plain Abaqus form covcontact's mesh
reader takes) and a problem file (``NAME.toml``). Each connected part of the mesh (elements joined through shared
nodes) is a body; its materials come from the *SOLID SECTIONs over it; the first *STEP is the problem's first
stage and each further step a stage. The node labels of each body are written beside them (``NAME.nodes.json``) so
that the ``.dat`` table (:class:`DatTable`) can print the deck's labels.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from .deck import DeckError
from .deck_mesh import Parts, body_content, body_meshio, body_text, surface_refs
from .deck_mesh import safe_name as _name
from .deck_toml import _table
from .deck_contacts import ContactMapping
from .deck_model import ELEMENTS, NFACES, Boundary, DeckModel, Load, nlgeom_steps, read_model
from .deck_coupling import DeckCouplings
from .deck_planar import element_names, is_planar_type, planar_body, planar_dof3
from .deck_rigid import DeckRigid
from .deck_knots import hinge_equations
from .deck_labels import DeckLabels
from .deck_shells import DeckShells
from .deck_mpc import DeckMPCs
from .deck_springs import DeckSprings

_COMP = "xyz"


@dataclass
class Imported:
    """What :func:`import_deck` wrote, and what the deck has that covcontact does not (with the lines)."""

    problem: Path
    meshes: list[Path]
    labels: Path
    unsupported: list[str] = field(default_factory=list)
    #: what the deck leaves to defaults and how covcontact fills them in (said before solving, kept in summary.json)
    notes: list[str] = field(default_factory=list)
    #: each mesh file's Mesh, built while writing it (``bodies_input.preload`` spares reading them back)
    read: dict = field(default_factory=dict, repr=False)


#: the dialects a deck is read in (docs/input.md, "Dialect"): what a keyword means where the two codes differ
DIALECTS = ("calculix", "abaqus")


def import_deck(deck: str | Path, out: str | Path, dialect: str = "auto") -> Imported:
    """Write the covcontact problem of ``deck`` as ``out`` (a .toml path; the mesh and the labels beside it).
    ``dialect``: "calculix", "abaqus" or "auto" (Abaqus where the deck has Abaqus-only keywords such as *PART or
    *ASSEMBLY, else CalculiX)."""
    deck, out = Path(deck), Path(out)
    m = read_model(deck)
    return _Writer(m, deck, out, m.dialect if dialect == "auto" else dialect).write()


class _Writer(ContactMapping, DeckLabels):
    def __init__(self, m: DeckModel, deck: Path, out: Path, dialect: str = "calculix"):
        self.m, self.deck, self.out, self.dialect = m, deck, out, dialect
        self.unsupported = list(m.unsupported)
        self.notes: list[str] = list(m.notes)
        self.body_forms: dict[int, str] = {}  # body index -> its formulation ("solid" for volume elements)
        if not m.blocks and not m.shell_blocks:  # (the types it has, at their *ELEMENT lines: the first is said)
            first = m.skipped_blocks[0][1] if m.skipped_blocks else str(deck)
            found = f"the deck's elements are {m.element_types()}" if m.skipped_blocks else "the deck has no *ELEMENT"
            raise DeckError(f"{first}: no solid elements: {found}; covcontact reads {element_names(ELEMENTS)}")
        self.b = Parts(m)
        self.shells = DeckShells(m, self.b, dialect)  # (shell elements made into solid-shells: bodies after these)
        self.notes += self.shells.notes
        self.unsupported += self.shells.unsupported
        self.body_names = self._body_names()
        self.rigid = DeckRigid(m, self.b, self.shells)
        self.couplings = DeckCouplings(m, self.b, self.rigid, self.unsupported, self.notes, dialect)
        self._eq_removed: set[str] = set()   # the equations stages removed so far
        self.extra_nsets: dict[str, np.ndarray] = {}
        self.extra_elsets: dict[str, np.ndarray] = {}
        self.extra_surfaces: dict[str, list[tuple[np.ndarray, int]]] = {}
        cell_of = np.concatenate([np.full(len(b[2]), b[1], dtype=object) for b in m.blocks] + [np.zeros(0, object)])
        faces = [(els, face, where, "S") for kind, refs in m.surfaces.values() if kind == "ELEMENT"
                 for els, face, where in refs]
        faces += [(ld.elements, ld.edge or ld.dof, ld.where, "EDNOR" if ld.edge else "P") for st in m.steps
                  for ld in st.loads if ld.kind == "dload"]
        faces = [(els[self.shells.elements_body(els) < 0], face, where, letter) for els, face, where, letter in faces]
        for els, face, where, letter in faces:  # a face the element does not have: the line that names it
            idx = self.b.el_index[els[(els >= 0) & (els < self.b.el_index.size)]]
            if idx.size < els.size or np.any(idx < 0):
                bad = [int(e) for e in els if e < 0 or e >= self.b.el_index.size or self.b.el_index[e] < 0]
                skipped = [e for e in bad if e in m.skipped_elements]
                if skipped:  # (a surface on elements not read: the surface cannot be built; listed)
                    self.unsupported.append(f"{where}: {letter}{face} on element {skipped[0]}, a "
                                            f"{m.skipped_elements[skipped[0]]} (not read), from "
                                            f"{m.skipped_card(skipped[0])}")
                    continue
                raise DeckError(f"{where}: {'*SURFACE' if letter == 'S' else '*DLOAD'}: element {bad[0]} is not "
                                f"defined")
            if letter == "EDNOR" and idx.size:
                raise DeckError(f"{where}: *DLOAD EDNOR{face} on element {int(els[0])}, a {cell_of[idx[0]]} element: "
                                f"edge loads act on the edges of shell elements")
            for cell in set(cell_of[idx]):
                if not 1 <= face <= NFACES[cell]:
                    raise DeckError(f"{where}: {letter}{face}: {cell} elements have the faces {letter}1..{letter}"
                                    f"{NFACES[cell]}")

    # -- bodies -------------------------------------------------------------------------------
    def _body_names(self) -> list[str]:
        names = []
        for k in range(self.b.n):
            els = set(self.b.el_labels[self.b.of_element == k].tolist())
            exact = [s for s, _, _ in self.m.sections if set(self.m.elsets.get(s, np.zeros(0)).tolist()) == els]
            name = _name(exact[0]) if exact else f"PART{k + 1}"
            names.append(name if name not in names else f"{name}_{k + 1}")
        for j, info in enumerate(self.shells.bodies):
            els = set(info["elements"].tolist())
            exact = [s for s, _, _, _, _ in self.m.shell_sections
                     if set(self.m.elsets.get(s, np.zeros(0)).tolist()) == els]
            name = _name(exact[0]) if exact else f"SHELL{j + 1}"
            names.append(name if name not in names else f"{name}_{self.b.n + j + 1}")
        return names

    def _material(self, name: str, where: str, card: str = "*SOLID SECTION") -> dict:
        mat = self.m.materials.get(name)
        if mat is None:
            raise DeckError(f"{where}: {card} names the material {name!r}, which no *MATERIAL defines")
        if "unsupported" in mat:
            raise DeckError(mat["unsupported"])
        if "hyperelastic" in mat:  # (*HYPERELASTIC: a rubber model of covcontact.materials.rubber)
            if "E" in mat or "plastic" in mat or "kinematic" in mat:
                raise DeckError(f"{mat['hyperelastic_where']}: *MATERIAL {name} has *HYPERELASTIC with *ELASTIC or "
                                f"*PLASTIC: give one elastic law (covcontact's rubber models are elastic)")
            for note in mat.get("notes", []):
                if note not in self.notes:
                    self.notes.append(note)
            out = dict(mat["hyperelastic"])
            if "density" in mat:
                out["density"] = mat["density"]
            return out
        if "E" not in mat:
            raise DeckError(f"{mat['where']}: *MATERIAL {name} has no *ELASTIC")
        out: dict = {"model": "svk", "E": mat["E"], "nu": mat["nu"]}
        if "plastic" in mat:
            pts = mat["plastic"]
            out = {"model": "j2", "E": mat["E"], "nu": mat["nu"]}
            if len(pts) == 1 or pts[0][1] != 0.0:
                if pts[0][1] != 0.0:
                    raise DeckError(f"{mat['where']}: *PLASTIC of {name}: the first plastic strain must be 0")
                out["yield_stress"] = pts[0][0]
                out["hardening"] = {"law": "linear", "modulus": 0.0}
            else:
                out["hardening"] = {"law": "table", "stress": [p[0] for p in pts], "strain": [p[1] for p in pts]}
        if "kinematic" in mat:  # linear (Prager) kinematic hardening from a two-point *PLASTIC, HARDENING=KINEMATIC
            s0, slope = mat["kinematic"]
            out = {"model": "j2", "E": mat["E"], "nu": mat["nu"], "yield_stress": s0,
                   "hardening": {"law": "linear", "modulus": 0.0}, "kinematic_modulus": slope}
        if "density" in mat:
            out["density"] = mat["density"]
        return out

    def _shell_bodies_toml(self) -> str:
        """The shell bodies (deck_shells): their surface mesh files, ``shell = { thickness, offset, faces }``, the
        materials of their *SHELL SECTIONs; the meshes are built here (``self.shell_meshes``) with every set the
        conditions and contacts made."""
        text = ""
        self.shell_meshes = {}
        nsets = {**{_name(n): v for n, v in self.m.nsets.items()}, **self.extra_nsets}
        nsets.update({_name(n): v for n, (kind, v) in self.m.surfaces.items() if kind == "NODE" and _name(n) not in nsets})
        elsets = {**{_name(n): v for n, v in self.m.elsets.items()}, **self.extra_elsets}
        faces = {**{n: [(els, side) for els, side, _ in rows] for n, rows in self.m.shell_surfaces.items()},
                 **self.shell_faces}
        for j, info in enumerate(self.shells.bodies):
            k = self.b.n + j
            name = self.body_names[k]
            mesh, surface, table = self.shells.build(j, nsets, elsets, faces)
            path = self.mesh_path.with_suffix(f".{k + 1}.inp")
            self.shell_meshes[path] = (mesh, surface)
            secs = info["sections"]
            entries: dict = {"name": name, "mesh": {"file": path.name}, "shell": table}
            entries["material"] = self._material(secs[0][1], secs[0][2], "*SHELL SECTION")
            if len(secs) > 1:
                entries["materials"] = {_name(s): self._material(mat, w, "*SHELL SECTION") for s, mat, w in secs[1:]}
            if info["cell"] == "quad4" and any(t == "S4R" for t, _, labs, _ in self.m.shell_blocks
                                               if np.intersect1d(labs, info["elements"]).size):
                self.notes.append(f"{info['where']}: S4R: the solid-shell (ANS + EAS, full integration) has no "
                                  f"reduced-integration counterpart; S4R elements are read as S4")
            sets = self.shells.layer_sets(k)
            if sets:
                entries["sets"] = sets
            text += _table("[[bodies]]", entries)
        return text

    def _bodies_toml(self) -> str:
        text = ""
        for k, name in enumerate(self.body_names[: self.b.n]):
            mine = self.b.of_element == k
            labels = self.b.el_labels[mine]
            types = {self.m.blocks[j][0] for j in range(len(self.m.blocks))
                     if np.any(self.b.of_element[self.b.block_range(j)] == k)}
            reduced = {ELEMENTS[t][1].get("integration") == "reduced" for t in types}
            if len(reduced) > 1:
                self.unsupported.append(f"{self.deck}: body {name} mixes C3D20 and C3D20R elements")
            if len({ELEMENTS[t][1].get("incompatible_modes", False) for t in types if ELEMENTS[t][0] == "hex8"}) > 1:
                self.unsupported.append(f"{self.deck}: body {name} mixes C3D8I with C3D8 or C3D8R elements")
            options = {k: v for t in sorted(types) for k, v in ELEMENTS[t][1].items()}  # its element types' options
            hybrid = self._hybrid(name, types, options)
            secs = [(s, mat, w) for s, mat, w in self.m.sections
                    if np.intersect1d(self.m.elsets.get(s, np.zeros(0, np.int64)), labels).size]
            for s, _, w in self.m.sections:
                if s not in self.m.elsets:
                    raise DeckError(f"{w}: *SOLID SECTION names the element set {s!r}, which no *ELSET defines")
            covered = np.zeros(labels.size, dtype=bool)
            for s, _, _ in secs:
                covered |= np.isin(labels, self.m.elsets[s])
            if not covered.all():
                raise DeckError(f"{self.deck}: element {int(labels[~covered][0])} has no *SOLID SECTION (a material "
                                f"for its element set)")
            entries: dict = {"name": name, "mesh": {"file": self.mesh_path.with_suffix(f".{k + 1}.inp").name}}
            entries["material"] = self._material(secs[0][1], secs[0][2])
            entries.update(planar_body(self, k, name, types, secs, labels))  # (CPE, CPS, CAX: deck_planar)
            self.body_forms[k] = entries.get("formulation", "solid")
            if len(secs) > 1:
                entries["materials"] = {_name(s): self._material(mat, w) for s, mat, w in secs[1:]}
            if hybrid and "formulation" in entries:  # (planar: the planar F-bar)
                options["fbar"] = True
            elif hybrid:
                entries["formulation"] = "fbar"
            if options:
                entries["options"] = options
            text += _table("[[bodies]]", entries)
        return text

    def _hybrid(self, name: str, types: set, options: dict) -> bool:
        """Whether body ``name`` (of deck element ``types``) is of hybrid elements, which become F-bar bodies (the
        mixed u/p elements of the manuals have no counterpart; F-bar is covcontact's element without volumetric
        locking, docs/theory.md), said in a note; ``options`` lose the flag. Mixing hybrid and other elements in a
        body, and hybrid cells F-bar does not have, are listed as unsupported."""
        from ..elements.fbar import FBAR_CELLS
        from ..elements.planar_fbar import PLANAR_FBAR_CELLS

        flags = {ELEMENTS[t][1].get("hybrid", False) for t in types}
        options.pop("hybrid", None)
        if True not in flags:
            return False
        hyb = sorted(t for t in types if ELEMENTS[t][1].get("hybrid", False))
        if len(flags) > 1:
            self.unsupported.append(f"{self.deck}: body {name} mixes hybrid ({', '.join(hyb)}) with other elements "
                                    f"({', '.join(sorted(set(types) - set(hyb)))}): give all of them one kind")
            return False
        cells = {ELEMENTS[t][0] for t in hyb}
        if is_planar_type(hyb[0]) and cells == {"tri3"}:
            self.notes.append(f"{self.deck}: body {name}: {', '.join(hyb)} (hybrid) read as {', '.join(t[:-1] for t in hyb)}"
                              f": a linear triangle has one volume change, which its constant pressure takes as it is "
                              f"(the same element for a compressible material; it locks as nearly incompressible)")
            return False
        if is_planar_type(hyb[0]) and not cells <= set(PLANAR_FBAR_CELLS):
            self.unsupported.append(f"{self.deck}: body {name}: {', '.join(hyb)} (hybrid): covcontact's planar "
                                    f"element without volumetric locking (F-bar) has {', '.join(PLANAR_FBAR_CELLS)} "
                                    f"cells; mesh the body with quadrilaterals only, or take CPE3 / CAX3")
            return False
        if is_planar_type(hyb[0]):
            options.pop("integration", None)  # (the planar F-bar integrates fully)
            self.notes.append(f"{self.deck}: body {name}: {', '.join(hyb)} (hybrid, mixed u/p in the manuals) become "
                              f"planar F-bar elements (options.fbar: the volume change of the element centre or its "
                              f"projection; no volumetric locking; docs/theory.md section 27)")
            return True
        if not cells <= set(FBAR_CELLS):
            self.unsupported.append(f"{self.deck}: body {name}: {', '.join(hyb)} (hybrid): covcontact's element "
                                    f"without volumetric locking (F-bar) has {', '.join(FBAR_CELLS)} cells only")
            return False
        if options.pop("integration", None) == "reduced":
            pass  # (F-bar hex20 integrates on its 27 points)
        self.notes.append(f"{self.deck}: body {name}: {', '.join(hyb)} (hybrid, mixed u/p in the manuals) become "
                          f"F-bar elements (formulation = \"fbar\": the volume change of the element centre or its "
                          f"projection; no volumetric locking; docs/theory.md)")
        return True

    # -- sets per body --------------------------------------------------------------------------
    def _node_targets(self, name: str, labels: np.ndarray, where: str) -> list[tuple[int, str]]:
        """(body, set name) of the nodes ``labels`` (a deck set ``name`` or a single node), per body."""
        bodies = self.b.nodes_body(labels)
        bodies = np.where(bodies >= 0, bodies, self.shells.nodes_body(labels))
        if np.all(bodies < 0):  # nodes of no element carry no unknowns (a support of nothing)
            return []
        set_name = _name(name) if not name.isdigit() else f"_N{name}"
        if name.isdigit() or name not in self.m.nsets:
            self.extra_nsets[set_name] = np.asarray(labels, dtype=np.int64)
        return [(int(k), set_name) for k in np.unique(bodies[bodies >= 0])]

    def _ref(self, body: int, set_name: str) -> str:
        return f"{self.body_names[body]}.{set_name}"

    # -- conditions and steps ---------------------------------------------------------------------
    def _amplitude(self, name: str | None, where: str, delay: float = 0.0):
        """The table (times, values, total time?) of amplitude ``name`` (None: none), its times shifted by the
        TIME DELAY ``delay`` (before the first point the first value holds, after the last the last)."""
        if name is None or name.upper() in self.m.skipped_amplitudes:
            return None
        amp = self.m.amplitudes.get(name.upper())
        if amp is None:
            raise DeckError(f"{where}: AMPLITUDE={name}: no *AMPLITUDE of that name (defined: "
                            f"{', '.join(sorted(self.m.amplitudes)) or 'none'})")
        return (amp[0] + delay, amp[1], amp[2]) if delay else amp

    def _conditions(self) -> tuple[str, str]:
        """The [[dirichlet]], [[force]], [[pressure]] entries (their first-stage values) and the [[stages]]: one
        stage per step, a step whose loads or conditions follow amplitudes cut at their points (everything is
        linear in time between them, so the stages reproduce the tables exactly)."""
        m = self.m
        if not m.steps:
            raise DeckError(f"{self.deck}: no *STEP")
        names: dict[tuple, str] = {}      # key -> condition name
        first: dict[tuple, object] = {}   # key -> first-stage entry (dict)
        stages: list[dict] = []
        self.stage_steps: list[tuple[int, float]] = []   # per covcontact stage: (deck step, duration)
        self.print_end: list[bool] = []   # per stage: its end is an output time (the step's end, a time point)
        self.print_every: list[int] = []  # per stage: output every Nth increment of the deck step (0: at ends only)
        self.stage_jump: list[bool] = []                  # per covcontact stage: its loads applied at once
        active: dict[tuple, float] = {}   # boundary key (body, set, dof) -> value held at the end of the last step
        loads: dict[tuple, float] = {}    # load key -> value at the end of the last step
        where: dict[tuple, str] = {}
        model: dict[tuple, tuple] = {}
        for b in m.model_boundary:
            amp = self._amplitude(b.amplitude, b.where, b.delay)
            for key, v in self._boundary_keys(b, where).items():
                model[key] = (v, amp)
        total = 0.0
        nlgeom = nlgeom_steps(m.steps)
        for s, step in enumerate(m.steps):
            period = step.increments[1]
            # (start value, end magnitude, amplitude) of every condition and load in force in this step
            if step.boundary_new:
                bspec: dict[tuple, tuple] = {}
            elif s == 0:
                bspec = {k: (0.0, v, a) for k, (v, a) in model.items()}
            else:
                bspec = {k: (v, v, None) for k, v in active.items()}
            for b in step.boundary:
                amp = self._amplitude(b.amplitude, b.where, b.delay)
                for key, v in self._boundary_keys(b, where).items():
                    if b.fixed:  # held where the step finds it: a held dof stays, a free one starts held
                        bspec[key] = (active[key], active[key], None) if key in active else (0.0, None, None)
                    else:
                        bspec[key] = (0.0 if s == 0 else active.get(key, 0.0), v, amp)
            lspec: dict[tuple, tuple] = {k: (v, v, None) for k, v in loads.items()}
            for kind in step.loads_new:  # loads not restated go to zero over the step
                for key, v in loads.items():
                    if key[0] == kind:
                        lspec[key] = (v, 0.0, None)
            for ld in step.loads:
                amp = self._amplitude(ld.amplitude, ld.where, ld.delay)
                for key in self._load_keys(ld):
                    lspec[key] = (loads.get(key, 0.0), ld.value, amp)
            # conditions on dofs free before (new ones, or released in an earlier step): they start in this step
            # from the displacement their dofs have then (FIXED: keep it)
            late = {key for key in bspec if s > 0 and (key not in names or key not in active)
                    and (key[0] != "rigid" or key not in active) and key[0] != "shellsum"}
            release = [names[key] for key in active if key not in bspec and key[0] not in ("rigid", "shellsum")]
            if any(key not in bspec and key[0] == "rigid" for key in active):
                self.unsupported.append(f"{step.where}: *BOUNDARY, OP=NEW drops a rigid body's prescribed component")
            breaks = {period}
            for _, _, amp in list(bspec.values()) + list(lspec.values()):
                if amp is not None:
                    times = np.asarray(amp[0]) - (total if amp[2] else 0.0)
                    breaks |= {float(t) for t in times if 0.0 < t < period * (1 - 1e-12)}
            points = set()
            if step.time_points is not None:  # output exactly at the time points: the step cut there
                times, on_total = self.m.time_points[step.time_points]
                times = np.asarray(times) - (total if on_total else 0.0)
                points = {float(t) for t in times if 0.0 < t < period * (1 - 1e-12)}
                breaks |= points
            breaks = sorted(breaks)
            self.print_end += [tau in points or tau == breaks[-1] for tau in breaks]
            self.print_every += [0 if step.time_points is not None else step.frequency] * len(breaks)
            prev_b = {k: spec[0] for k, spec in bspec.items()}
            prev_l = {k: spec[0] for k, spec in lspec.items()}
            for j, tau in enumerate(breaks):
                targets = {}

                def at(spec, tau=tau, period=period, total=total, dynamic=step.dynamic):
                    v0, M, amp = spec
                    if amp is None:  # a static step ramps its changes, a dynamic one applies them at once
                        return M if dynamic else v0 + (M - v0) * tau / period
                    return float(np.interp(tau + (total if amp[2] else 0.0), amp[0], amp[1])) * M

                # a dynamic stage whose loads are constant over it (no amplitude, or a flat piece of one) takes them
                # at once (CalculiX's and Abaqus' step amplitude of *DYNAMIC); else they go linearly between the cuts
                t0 = breaks[j - 1] if j else 0.0
                jump = step.dynamic and all(amp is None or at((0.0, 1.0, amp), t0) == at((0.0, 1.0, amp))
                                            for _, _, amp in list(lspec.values()))
                self.stage_jump.append(jump)

                stage_name = f"step{s + 1}" + (f"_{j + 1}" if len(breaks) > 1 else "")
                rigid_v, rigid_l, dist_l = {}, {}, {}
                for key, spec in bspec.items():
                    if key[0] == "shellsum":  # a shell node's mean (its equation's right-hand side 2 v: deck_shells)
                        v = at(spec)
                        if (s, j) == (0, 0):
                            self.shells.sum_values[key[1:]] = 2.0 * v
                        elif v != prev_b[key]:
                            targets[f"shell{key[1]}_{_COMP[key[2]]}"] = 2.0 * v
                        prev_b[key] = v
                        continue
                    if key[0] == "rigid":  # a rigid body's REF or ROT node: its motion (DeckRigid)
                        if key in late or spec[1] is None:
                            self.unsupported.append(f"{where[key]}: a *BOUNDARY on a rigid body's REF or ROT node "
                                                    f"that starts after the first step, or FIXED")
                            continue
                        rigid_v[key[1:]] = prev_b[key] = at(spec)
                        continue
                    if key in late:
                        if j == 0:
                            names[key] = f"bc{len(names) + 1}"
                            entry = {"name": names[key], "set": self._ref(key[0], key[1]),
                                     "components": _COMP[key[2]], "stage": stage_name}
                            if spec[1] is None:  # *BOUNDARY, FIXED
                                entry["value"] = "held"
                            elif spec[2] is None and len(breaks) > 1:
                                self.unsupported.append(f"{where[key]}: a *BOUNDARY that starts in a step cut by "
                                                        f"amplitudes without an amplitude of its own")
                            else:
                                entry["value"] = at((0.0, spec[1], spec[2]))
                            first[(*key, s)] = entry
                            prev_b[key] = entry.get("value")
                        elif spec[1] is not None and prev_b[key] != "held":
                            v = at((0.0, spec[1], spec[2]))
                            if v != prev_b[key]:
                                targets[names[key]] = v
                            prev_b[key] = v
                        continue
                    v = at(spec)
                    if key not in names:
                        names[key] = f"bc{len(names) + 1}"
                        first[key] = {"name": names[key], "set": self._ref(key[0], key[1]),
                                      "components": _COMP[key[2]], "value": v}
                    elif v != prev_b[key]:
                        targets[names[key]] = v
                    prev_b[key] = v
                for key, spec in lspec.items():
                    v = at(spec)
                    if key[0] == "rforce":
                        rigid_l[key[1:]] = prev_l[key] = v
                        continue
                    if key[0] == "dforce":  # a *DISTRIBUTING coupling's REF NODE: its nodes' forces (DeckCouplings)
                        dist_l[key[1:]] = prev_l[key] = v
                        continue
                    if key not in names:
                        names[key] = f"{ {'cload': 'f', 'dload': 'p'}.get(key[0], 'g') }{len(names) + 1}"
                        first[key] = self._load_entry(key, names[key], v if (s, j) == (0, 0) else 0.0, nlgeom[s])
                        if (s, j) != (0, 0):
                            targets[names[key]] = self._load_value(key, v)
                    elif v != prev_l[key]:
                        targets[names[key]] = self._load_value(key, v)
                    prev_l[key] = v
                duration = tau - (breaks[j - 1] if j else 0.0)
                self.stage_steps.append((s, duration))
                motions, rigid_targets = self.rigid.stage(rigid_v, rigid_l)
                targets.update(rigid_targets)
                targets.update(self.couplings.stage(dist_l))
                if (s, j) == (0, 0):
                    continue
                st = {"name": stage_name, **self._timing(step, duration, jump)}
                if motions:
                    st["motions"] = motions
                removed = self._removed_equations(step) if j == 0 else []
                if s == 0 and j == 0 and (step.remove_equations is None or step.remove_equations):
                    self.unsupported.append(f"{step.where}: *EQUATION, REMOVE in the first step (the equations are "
                                            f"model data; leave them out instead)")
                if removed:
                    st["remove"] = removed
                if release and j == 0:
                    st["release"] = release
                changed = {f"pair{k + 1}": mu for k, (inter, *_rest) in enumerate(m.pairs)
                           for name, mu in step.friction.items() if inter == name}
                if changed and j == 0:
                    st["friction"] = changed
                if targets:
                    st["targets"] = targets
                stages.append(st)
            active = {k: (v if isinstance(v, float) else 0.0) for k, v in prev_b.items()}
            loads = dict(prev_l)
            total += period
        conds = ""
        for key, entry in first.items():
            kind = {"cload": "force", "dload": "pressure", "grav": "body_force", "centrif": "body_force"}.get(key[0],
                                                                                                            "dirichlet")
            if kind == "dirichlet" and entry.get("value", 0.0) is None:
                continue  # (a late condition the step cannot give: listed as unsupported)
            conds += _table(f"[[{kind}]]", entry)
        text = "" if m.steps[0].dynamic else _table("[steps]",
                                                    self._timing(m.steps[0], self.stage_steps[0][1])["steps"])
        for st in stages:
            steps = st.pop("steps", None)
            text += _table("[[stages]]", {**st, "steps": steps})
        return conds, text

    def _timing(self, step, duration: float, jump: bool = False) -> dict:
        """The steps (``steps``) of a stage that makes ``duration`` of the deck's step or, for *DYNAMIC, its dynamic
        keys: HHT with rho_inf = (1 + alpha) / (1 - alpha), CalculiX's consistent mass of implicit dynamics (with contact
        the run says that it can rattle, see docs/input.md "Dynamics"), the deck's increment as dt (automatic within
        its min and max unless DIRECT)."""
        a, _, lo, hi = step.increments
        if not step.dynamic:
            if step.direct:
                return {"steps": {"count": max(1, round(duration / a))}}
            out = {"initial": min(1.0, a / duration)}
            if lo is not None and lo > 0:
                out["min"] = min(out["initial"], lo / duration)
            if hi is not None and hi > 0:
                out["max"] = min(1.0, hi / duration)
            return {"steps": out}
        out = {"procedure": "dynamic", "dt": min(a, duration), "t_end": duration, "method": "hht",
               "rho_inf": (1.0 + step.alpha) / (1.0 - step.alpha), "mass": "consistent"}
        if jump:
            out["ramp"] = False
        if not step.direct and lo and hi:
            out.update({"dt_min": min(lo, a, duration), "dt_max": max(min(hi, duration), min(a, duration))})
        return out

    def _boundary_keys(self, b: Boundary, where: dict) -> dict:
        out = {}
        if self.shells.n:  # shell nodes: the components their two layers share (the rest are equations: deck_shells)
            plain, both = self.shells.boundary_split(b.nodes, b.dofs)
            for c, labs in both.items():
                name = self._shell_set(labs)
                for body, set_name in self._node_targets(name, labs, b.where):
                    key = (body, set_name, c)
                    where.setdefault(key, b.where)
                    out[key] = 0.0 if b.value is None else b.value
            for lab in b.nodes[self.shells.is_shell(b.nodes)].tolist():  # (the means: their equations' values)
                for c in (d - 1 for d in b.dofs if d <= 3 and d - 1 in self.shells.plan.get(lab, ((), ()))[1]):
                    key = ("shellsum", lab, c)
                    where.setdefault(key, b.where)
                    out[key] = 0.0 if b.value is None else b.value
            if plain.size == 0:
                return out
            b = replace(b, nodes=plain)
        labels, keys = self.couplings.boundary_keys(b)  # (reference nodes' dofs 1-6: deck_coupling)
        for key in keys:
            where.setdefault(key, b.where)
            out[key] = 0.0 if b.value is None else b.value
        for body, set_name in self._node_targets(b.name, labels, b.where):
            for d in (d for d in b.dofs if d <= 3):
                if d == 3 and planar_dof3(self, body, b.where, b.value):  # (held anyway: deck_planar)
                    continue
                key = (body, set_name, d - 1)
                where.setdefault(key, b.where)
                out[key] = 0.0 if b.value is None else b.value
        return out

    def _shell_set(self, labels: np.ndarray) -> str:
        """The name of a node set of these shell node labels (one per distinct set)."""
        key = tuple(np.asarray(labels).tolist())
        names = self.__dict__.setdefault("_shell_sets", {})
        if key not in names:
            names[key] = f"_SB{len(names) + 1}"
        return names[key]

    def _load_keys(self, ld: Load):
        if ld.kind == "cload" and self.shells.n and ld.dof > 3 and np.any(self.shells.is_shell(ld.nodes)):
            lab = int(ld.nodes[self.shells.is_shell(ld.nodes)][0])
            raise DeckError(f"{ld.where}: *CLOAD: a moment (dof {ld.dof}) on shell node {lab}: not supported "
                            f"(CalculiX turns it into a mean rotation of the node's expansion)")
        if ld.kind == "dload" and self.shells.n and np.any(self.shells.elements_body(ld.elements) >= 0):
            sb = self.shells.elements_body(ld.elements)
            side = f"EDGE{ld.edge}" if ld.edge else self.shells.pressure_side(ld.dof, ld.where)
            for body in np.unique(sb[sb >= 0]):
                els = ld.elements[sb == body]
                if not ld.edge:
                    name = f"_P{_name(ld.target)}_{side}"
                    self.shell_faces[name] = [(els, side)]
                    yield ("dload", int(body), name, ld.dof)
                    continue
                # (an edge load, force per length: the pressure on the solid-shell's side face is it over the
                # thickness, CalculiX's replacement by a pressure on its expanded element's side)
                t = self.shells.edge_thickness(els, ld.where)
                for k, value in enumerate(np.unique(t)):
                    name = f"_P{_name(ld.target)}_{side}" + (f"_{k + 1}" if k else "")
                    self.shell_faces[name] = [(els[t == value], side)]
                    yield ("dload", int(body), name, ld.dof, 1.0 / float(value))
            ld = replace(ld, elements=ld.elements[sb < 0])
            if not ld.elements.size:
                return
        if ld.kind in ("grav", "centrif") and self.shells.n:
            sb = self.shells.elements_body(ld.elements)
            for body in np.unique(sb[sb >= 0]):
                name = _name(ld.target) if not ld.target.isdigit() else f"_E{ld.target}"
                if ld.target.isdigit():
                    self.extra_elsets[name] = ld.elements
                yield (ld.kind, int(body), name, ld.direction) if ld.kind == "grav" else \
                    (ld.kind, int(body), name, ld.direction, ld.point)
            if np.all(sb >= 0):
                return
            ld = replace(ld, elements=ld.elements[sb < 0])
        if ld.kind == "cload":
            labels, rigid = self.couplings.load_keys(ld)  # (reference nodes' dofs 1-6: deck_coupling)
            yield from rigid
            if ld.dof > 3 or (labels.size == 0 and ld.nodes.size > 0):
                return  # (moments act on reference nodes alone; what they refuse is listed)
            targets = self._node_targets(ld.target, labels, ld.where)
            if not targets and not rigid:
                owner = [self.m.unsupported_nodes[int(n)] for n in ld.nodes if int(n) in self.m.unsupported_nodes]
                if owner and len(owner) == ld.nodes.size:  # (the reference node of a keyword listed as unsupported)
                    self.unsupported.append(f"{ld.where}: *CLOAD on {ld.target}, the reference node of {owner[0]}; "
                                            f"with --ignore-unsupported the load is left out")
                    return
                raise DeckError(f"{ld.where}: *CLOAD on nodes of no element ({ld.target})")
            for body, set_name in targets:
                if ld.dof == 3 and planar_dof3(self, body, ld.where, None, load=True):
                    continue
                yield ("cload", body, set_name, ld.dof - 1)
        else:
            bodies = self.b.elements_body(ld.elements)
            if np.any(bodies < 0):  # (elements of a type not read: listed, the load on the others kept)
                gone = [int(e) for e in ld.elements[bodies < 0] if int(e) in self.m.skipped_elements]
                if len(gone) < int(np.sum(bodies < 0)):
                    bad = next(int(e) for e in ld.elements[bodies < 0] if int(e) not in self.m.skipped_elements)
                    raise DeckError(f"{ld.where}: *DLOAD: element {bad} is not defined")
                if ld.kind in ("grav", "centrif"):  # (a face load's such faces are listed with the surfaces)
                    self.unsupported.append(f"{ld.where}: *DLOAD {ld.kind.upper()} on {ld.target}: element "
                                            f"{gone[0]} is {self.m.skipped(gone[0])}, a type covcontact does not "
                                            f"read; with --ignore-unsupported the load acts on "
                                            + ("the set's other elements alone" if np.any(bodies >= 0) else
                                               "no element (left out)"))
                ld, bodies = replace(ld, elements=ld.elements[bodies >= 0]), bodies[bodies >= 0]
            for body in np.unique(bodies):
                if ld.kind in ("grav", "centrif"):  # an acceleration on the element set (times the density)
                    name = _name(ld.target) if not ld.target.isdigit() else f"_E{ld.target}"
                    if ld.target.isdigit():
                        self.extra_elsets[name] = ld.elements
                    yield (ld.kind, int(body), name, ld.direction) if ld.kind == "grav" else \
                        (ld.kind, int(body), name, ld.direction, ld.point)
                    continue
                name = f"_P{_name(ld.target)}_{ld.dof}"
                self.extra_surfaces[name] = [(ld.elements[bodies == body], ld.dof)]
                yield ("dload", int(body), name, ld.dof)

    def _load_entry(self, key: tuple, name: str, v: float, nlgeom: bool = False) -> dict:
        """A load's entry; a face pressure given in a geometrically nonlinear step follows the faces (CalculiX and
        Abaqus apply pressures on the deformed faces with NLGEOM)."""
        follower = key[0] == "dload" and nlgeom
        if follower and self.body_forms.get(key[1]) == "plane_stress":
            note = (f"{self.deck}: body {self.body_names[key[1]]}: a pressure with NLGEOM follows the plane stress "
                    f"edges on their reference thickness (CalculiX's expanded elements: on the current one, a "
                    f"difference of the order of nu times the strain)")
            if note not in self.notes:
                self.notes.append(note)
        if key[0] == "grav":
            return {"name": name, "body": self.body_names[key[1]], "cells": key[2],
                    "acceleration": self._load_value(key, v)}
        if key[0] == "centrif":  # (the deck's magnitude is omega^2)
            return {"name": name, "body": self.body_names[key[1]], "cells": key[2],
                    "centrifugal": {"omega": self._load_value(key, v), "axis": list(key[3]), "center": list(key[4])}}
        return {"name": name, "set": self._ref(key[1], key[2]), "value": self._load_value(key, v)} | (
            {"distribution": "per_node"} if key[0] == "cload" else {}) | ({"follower": True} if follower else {})

    def _load_value(self, key: tuple, v: float):
        if key[0] == "centrif":  # a stage target of a spin is its angular velocity
            return float(np.sqrt(max(v, 0.0)))
        if key[0] == "grav":
            return [float(v) * d for d in key[3]]
        if key[0] == "dload" and len(key) > 4:  # (a shell edge's load over the thickness)
            return float(v) * key[4]
        if key[0] == "cload":
            vec = [0.0, 0.0, 0.0]
            vec[key[3]] = float(v) * (0.5 if key[1] >= self.b.n else 1.0)  # (a shell node: half on each layer)
            return vec
        return float(v)

    def _solver(self) -> str:
        """[solver] from *CONTROLS, TIME INCREMENTATION: CalculiX's I_C and I_A where they exceed covcontact's own
        limits (25 iterations, 6 cutbacks: a deck that allows more gets more; fewer is not imposed, since covcontact's
        iterations are not CalculiX's); and the line search where the deck has surface-to-surface pairs and static
        steps, as CalculiX searches along its Newton corrections in static face-to-face penalty contact."""
        from ..description import SolverOptions

        d = SolverOptions()
        entries = {k: v for k, v in self.m.controls.items() if v > getattr(d, k)}
        if any(kind == "SURFACE TO SURFACE" for _, kind, _, _, _ in self.m.pairs) and any(
                not st.dynamic for st in self.m.steps):  # (CalculiX's line search of face-to-face penalty contact)
            entries["line_search"] = True
        for k, v in self.m.controls.items():
            if v <= getattr(d, k):
                self.notes.append(f"{self.deck}: *CONTROLS, TIME INCREMENTATION: {k} {v} is below covcontact's "
                                  f"{getattr(d, k)}, which is kept")
        return _table("[solver]", entries) if entries else ""

    # -- files ---------------------------------------------------------------------------------------
    def _equations(self) -> str:
        text = ""
        for k, (terms, where) in enumerate(self.m.equations):
            out = []
            for node, dof, coef in terms:
                if not 1 <= dof <= 3:
                    break
                if self.shells.n and self.shells.is_shell(np.array([node]))[0]:  # (its mean: half on each layer,
                    body = int(self.shells.label_body[node])                       # as CalculiX's expanded nodes)
                    self.shells.equation_nodes.setdefault(body, set()).add(int(node))
                    out += [[self._ref(body, f"_SN{node}_{side}"), _COMP[dof - 1], 0.5 * coef] for side in "bt"]
                    continue
                (body, set_name), = self._node_targets(str(node), np.array([node]), where)
                out.append([self._ref(body, set_name), _COMP[dof - 1], coef])
            else:
                text += _table("[[equation]]", {"name": f"eq{k + 1}", "terms": out})
        for entry in self.shells.equations(self._ref):  # (shell nodes' conditions: deck_shells)
            text += _table("[[equation]]", entry)

        def solid_ref(lab: int) -> str:
            (body, set_name), = [t for t in self._node_targets(str(lab), np.array([lab]), "") if t[0] < self.b.n]
            return self._ref(body, set_name)

        for entry in hinge_equations(self.shells, self._ref, solid_ref):  # (shell nodes on solid elements: hinges)
            text += _table("[[equation]]", entry)
        return text

    def _removed_equations(self, step) -> list[str]:
        """The names of the equations a step's *EQUATION, REMOVE removes (by their dependent node and dof)."""
        gone = set(step.remove_equations or ())
        names = [f"eq{k + 1}" for k, (terms, _) in enumerate(self.m.equations)
                 if step.remove_equations is None or (terms[0][0], terms[0][1]) in gone]
        new = [n for n in names if n not in self._eq_removed]
        self._eq_removed |= set(new)
        return new

    def write(self) -> Imported:
        self.mesh_path = self.out.with_suffix(".mesh.inp")
        self.shell_faces: dict = {}
        knot_labels = {lab for lab, _ in self.shells.knots.values()}
        for r, (nodes, _, _, where) in enumerate(self.m.rigid_bodies):
            hit = [int(n) for n in nodes if int(n) in knot_labels] if r not in self.shells.knots else []
            if hit:
                raise DeckError(f"{where}: *RIGID BODY on shell node {hit[0]}, a knot of the shell expansion (a rigid "
                                f"body of its own): not supported")
        bodies = self._bodies_toml()
        self.shells.plan_boundaries()
        self.notes += [n for n in self.shells.notes if n not in self.notes]
        conds, stages = self._conditions()
        contacts = self._contacts() + self._equations()
        rigid = "".join(_table("[[rigid]]", e) for e in self.rigid.entries(self.extra_nsets, self._ref))
        bodies += self._shell_bodies_toml()  # (after the rigid bodies: their sets of shell nodes)
        self.notes += self.rigid.notes
        springs = "".join(_table(kind, e) for kind, e in DeckSprings(self).entries())  # (SPRINGA, ..., DASHPOTA)
        springs += "".join(_table("[[mpc]]", e) for e in DeckMPCs(self).entries())  # (*MPC: deck_mpc)
        conds += "".join(_table("[[force]]", e) for e in self.couplings.entries(self.extra_nsets, self._ref))
        self.unsupported += self.rigid.unsupported
        first = self.m.steps[0]
        head = _table("[problem]", {"name": _name(self.deck.stem), **(self._timing(
            first, self.stage_steps[0][1], self.stage_jump[0]) if first.dynamic else {})}) + self._solver()
        self.out.parent.mkdir(parents=True, exist_ok=True)
        self.out.write_text(f"# imported from {self.deck.name} by covcontact import\n" + head + bodies + rigid
                            + contacts + springs + conds + stages)
        self._write_mesh()
        labels = self._write_labels()
        meshes = [self.mesh_path.with_suffix(f".{k + 1}.inp") for k in range(self.b.n + self.shells.n)]
        return Imported(self.out, meshes, labels, list(dict.fromkeys(self.unsupported)),
                        list(dict.fromkeys(self.notes)), self.meshes)

    def _write_mesh(self) -> None:
        """One mesh file per body (its nodes, elements, sets and surfaces): bodies of cell types that do not mix
        (a hex20 part and a tet10 part) each read on their own. ``self.meshes``: each file's Mesh, built from the
        same content without reading the file back (``covcontact run DECK.inp`` hands them to the loader)."""
        from ..mesh.io import MeshError, mesh_from_meshio

        import dataclasses

        self.meshes = {}
        self.element_labels = {}  # body -> the deck's element labels in the mesh's element order
        # (a surface only *SECTION PRINT names may cut through a body: the .dat reads its faces from the labels file)
        sections = {s[0] for st in self.m.steps for s in st.section_print} | self.m.unsupported_surfaces
        used = {name for pair in self.m.pairs for name in pair[2:4]} | {name for tie in self.m.ties for name in tie[1:3]}
        model = dataclasses.replace(self.m, surfaces={name: v for name, v in self.m.surfaces.items()
                                                      if name in used or name not in sections})
        for k in range(self.b.n):
            path = self.mesh_path.with_suffix(f".{k + 1}.inp")
            content = body_content(model, self.b, k, self.extra_nsets, self.extra_elsets, self.extra_surfaces)
            self.element_labels[self.body_names[k]] = np.concatenate([lab for _, lab, _ in content["blocks"]]).tolist()
            path.write_text(body_text(content))
            try:
                self.meshes[path] = mesh_from_meshio(body_meshio(content), path,
                                                     surfaces=(surface_refs(content), {}))
            except MeshError as exc:  # (named by the deck, not by the mesh file written from it)
                raise DeckError(f"{self.deck}: body {self.body_names[k]}: {str(exc).split(': ', 1)[-1]}") from None
        start = max([int(e) for labs in self.element_labels.values() for e in labs]
                    + [int(e) for _, _, labs, _ in self.m.shell_blocks for e in labs] + [0]) + 1
        for j, info in enumerate(self.shells.bodies):  # shell bodies: their surface files, the solid-shells built
            k = self.b.n + j
            path = self.mesh_path.with_suffix(f".{k + 1}.inp")
            mesh, text = self.shell_meshes[path]
            path.write_text(text)
            self.meshes[path] = mesh
            # (a split triangle's three cells: labels after the deck's largest, so that no deck label names a third of
            # a triangle in the .dat's element tables)
            split = info["cell"] in ("tri3", "tri6")
            per_cell = start + np.arange(3 * info["elements"].size) if split else info["elements"]
            if split:
                start += per_cell.size
            self.element_labels[self.body_names[k]] = per_cell.tolist()
