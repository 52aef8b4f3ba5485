"""The model an Abaqus or CalculiX deck describes: nodes, elements, sets, surfaces, materials, sections, contact,
multi-point constraints and steps (docs/input.md, "Abaqus and CalculiX decks").

:func:`read_model` turns the cards of :func:`covcontact.io.deck.read_deck` into a :class:`DeckModel` in the deck's
own terms (node and element labels, set names upper-case, dofs 1..3). What covcontact does not have is collected in
``DeckModel.unsupported`` (file, line and what), so that a run can list all of it before solving; malformed input is
a :class:`covcontact.io.deck.DeckError` naming the line.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .deck import Card, DeckError, numbers, read_deck
from .deck_coupling import COUPLING_CARDS, read_coupling_card
from .deck_loads import Boundary, Load, LoadCards
from .deck_materials import MaterialCards, rubber_option as _rubber_option
from .deck_elements import ELEMENTS, NFACES, NNODE
from .deck_planar import element_names
from .deck_shells import (SHELL_CARDS, SHELL_ELEMENTS, read_shell_card, read_shell_elements, refuse_shell_type,
                          shell_surface_row)
from .deck_mpc import read_mpc_card
from .deck_springs import BEAMS, SPRING_CARDS, SPRING_ELEMENTS, read_spring_card, read_spring_elements
from .deck_testdata import TEST_DATA_CARDS, finish_test_data, read_test_data_card

# the element types read and their cells (deck_elements: the deck modules share them without an import cycle)

#: the keywords read (everything else is unsupported); output requests are read for the .dat table
SUPPORTED = ("HEADING", "NODE", "ELEMENT", "NSET", "ELSET", "SURFACE", "MATERIAL", "ELASTIC", "PLASTIC", "DENSITY",
             "HYPERELASTIC",
             "SOLID SECTION", "BOUNDARY", "CLOAD", "DLOAD", "DSLOAD", "STEP", "STATIC", "DYNAMIC", "END STEP",
             "CONTACT PAIR",
             "SURFACE INTERACTION", "SURFACE BEHAVIOR", "FRICTION", "EQUATION", "NODE PRINT", "EL PRINT",
             "NODE FILE", "EL FILE", "CONTACT PRINT", "CONTACT FILE", "NODE OUTPUT", "ELEMENT OUTPUT",
             "CONTACT OUTPUT", "OUTPUT", "RESTART", "AMPLITUDE", "TIE", "CONTROLS", "CHANGE FRICTION", "RIGID BODY",
             "TIME POINTS", "SECTION PRINT") + COUPLING_CARDS + SHELL_CARDS + TEST_DATA_CARDS
#: keywords only Abaqus reads: a deck with one of them is read in Abaqus' dialect (import_deck's "auto")
_ABAQUS_ONLY = ("PART", "END PART", "ASSEMBLY", "END ASSEMBLY", "INSTANCE", "END INSTANCE")
#: output requests: accepted; the .dat tabulates what _print lists for *NODE PRINT, *EL PRINT, *CONTACT PRINT and
#: *SECTION PRINT
_OUTPUT = ("NODE PRINT", "EL PRINT", "NODE FILE", "EL FILE", "CONTACT PRINT", "CONTACT FILE", "NODE OUTPUT",
           "ELEMENT OUTPUT", "CONTACT OUTPUT", "OUTPUT", "RESTART", "SECTION PRINT")
#: parameters that do not change what covcontact computes (solver, output and bookkeeping choices)
_HARMLESS = {"NSET", "ELSET", "NAME", "GENERATE", "TYPE", "INPUT", "FREQUENCY", "GLOBAL", "TOTALS", "OUTPUT",
             "SOLVER", "INC", "NLGEOM", "OP", "INTERACTION", "MATERIAL", "PRESSURE-OVERCLOSURE", "UNSYMM", "READ",
             "WRITE", "TIME POINTS", "CONTACT ELEMENTS", "LAST ITERATIONS", "SECTION FORCES", "POSITION",
             "DIRECT", "PERTURBATION", "MODE"}


@dataclass
class Step:
    """One *STEP ... *END STEP."""

    where: str
    nlgeom: bool | None       # NLGEOM (=YES) / NLGEOM=NO / not given (kept from the step before: nlgeom_steps)
    increments: tuple[float, float, float | None, float | None]   # initial, period, min, max
    direct: bool
    dynamic: bool = False     # *DYNAMIC (implicit): the increments are times
    alpha: float = -0.05      # its HHT parameter (ALPHA=, in [-1/3, 0])
    boundary: list[Boundary] = field(default_factory=list)
    boundary_new: bool = False
    loads: list[Load] = field(default_factory=list)
    loads_new: set[str] = field(default_factory=set)   # "cload"/"dload" with OP=NEW in this step
    #: (nset, variables, where, totals: "NO" | "YES" | "ONLY")
    node_print: list[tuple[str, tuple[str, ...], str, str]] = field(default_factory=list)
    #: (elset, variables, where, totals)
    el_print: list[tuple[str, tuple[str, ...], str, str]] = field(default_factory=list)
    contact_print: tuple[str, ...] = ()    # *CONTACT PRINT variables
    contact_card: tuple[str, str] = ("", "NO")   # where the step's *CONTACT PRINT is, its TOTALS
    #: *SECTION PRINT: (surface, NAME, variables, where)
    section_print: list[tuple[str, str, tuple[str, ...], str]] = field(default_factory=list)
    #: which print requests the step itself gives (the others carry over from the step before, as in CalculiX)
    prints_given: set[str] = field(default_factory=set)
    #: FREQUENCY of the output (every Nth increment and the step's end; carried over from step to step)
    frequency: int = 1
    #: TIME POINTS= of the output: the name of a *TIME POINTS (output there and at the step's end), or None
    time_points: str | None = None
    #: *EQUATION, REMOVE: the dependent (node, dof) of the equations removed from this step on; None: REMOVE ALL
    remove_equations: list | None = field(default_factory=list)
    friction: dict[str, float] = field(default_factory=dict)  # *CHANGE FRICTION: interaction -> new mu


@dataclass
class Interaction:
    name: str
    behavior: str = "hard"                         # hard | linear | exponential
    values: tuple[float, ...] = ()
    friction: tuple[float, float | None] | None = None   # (mu, stick slope)
    where: str = ""

    def curve(self, dialect: str) -> dict:
        """The [[contact]] keys of an EXPONENTIAL (c0, p0; in the deck's dialect) or TABULAR (pressure, overclosure
        lines, here [overclosure, pressure] pairs; one point: a constant pressure) curve."""
        if self.behavior == "exponential":
            return {"law": "exponential", "clearance": self.values[0], "pressure": self.values[1], "form": dialect}
        pts = self.values
        table = [[pts[j], pts[j + 1]] for j in range(0, len(pts), 2)]
        if len(pts) == 2:  # (a second point with the same pressure makes a table)
            table.append([pts[0] + 1.0, pts[1]])
        return {"law": "table", "table": table}


@dataclass
class DeckModel:
    """A deck's model in its own terms (labels, upper-case names)."""

    heading: str = ""
    node_labels: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    X: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    #: element blocks: (deck type, covcontact cell type, labels (n,), connectivity as node labels (n, nen))
    blocks: list[tuple[str, str, np.ndarray, np.ndarray]] = field(default_factory=list)
    #: where each block's *ELEMENT line is
    block_where: list[str] = field(default_factory=list)
    nsets: dict[str, np.ndarray] = field(default_factory=dict)
    #: each *NSET's labels in the order written (``nsets`` sorts them; an *MPC's defining nodes come first)
    nset_order: dict[str, list] = field(default_factory=dict)
    elsets: dict[str, np.ndarray] = field(default_factory=dict)
    #: name -> ("ELEMENT", [(element labels, face 1..6)]) or ("NODE", node labels)
    surfaces: dict[str, tuple[str, object]] = field(default_factory=dict)
    materials: dict[str, dict] = field(default_factory=dict)
    sections: list[tuple[str, str, str]] = field(default_factory=list)   # (elset, material, where)
    #: the first field of each *SOLID SECTION's data line (the thickness of planar elements) by the card's where:
    #: (text, where of the data line)
    section_thickness: dict[str, tuple[str, str]] = field(default_factory=dict)
    interactions: dict[str, Interaction] = field(default_factory=dict)
    pairs: list[tuple[str, str, str, str, str]] = field(default_factory=list)  # (interaction, type, slave, master, where)
    #: ADJUST= of a *CONTACT PAIR by its line (where): a distance, or a node set's name
    pair_adjust: dict[str, float | str] = field(default_factory=dict)
    #: *TIE: (name, slave, master, position tolerance or None, where)
    ties: list[tuple[str, str, str, float | None, str]] = field(default_factory=list)
    equations: list[tuple[list[tuple[int, int, float]], str]] = field(default_factory=list)
    #: name -> (times, values, on the total time?) of a tabular *AMPLITUDE
    amplitudes: dict[str, tuple[np.ndarray, np.ndarray, bool]] = field(default_factory=dict)
    #: amplitudes of a kind not read (listed as unsupported): the loads that use them are left as they are
    skipped_amplitudes: set[str] = field(default_factory=set)
    model_boundary: list[Boundary] = field(default_factory=list)
    #: *RIGID BODY: (node labels, REF NODE label or None, ROT NODE label or None, where)
    rigid_bodies: list[tuple[np.ndarray, int | None, int | None, str]] = field(default_factory=list)
    #: *COUPLING with *KINEMATIC (also in rigid_bodies) or *DISTRIBUTING (covcontact.io.deck_coupling.Coupling)
    couplings: list = field(default_factory=list)
    steps: list[Step] = field(default_factory=list)
    unsupported: list[str] = field(default_factory=list)
    #: surfaces named by unsupported keywords (left out of the meshes unless a contact pair or tie uses them)
    unsupported_surfaces: set[str] = field(default_factory=set)
    #: reference nodes named by unsupported keywords (a *PRE-TENSION SECTION's NODE=): label -> "file:line: *KEYWORD"
    unsupported_nodes: dict[int, str] = field(default_factory=dict)
    #: elements of types covcontact does not read (listed as unsupported): label -> type; and their nodes
    skipped_elements: dict[int, str] = field(default_factory=dict)
    skipped_nodes: set[int] = field(default_factory=set)
    #: their *ELEMENT cards: (type, where, labels); and the sets their ELSET= names: set name -> those cards' indices
    skipped_blocks: list[tuple[str, str, np.ndarray]] = field(default_factory=list)
    skipped_elsets: dict[str, list[int]] = field(default_factory=dict)
    #: *CONTROLS, TIME INCREMENTATION: "max_iterations" (I_C), "max_cutbacks" (I_A), the largest given
    controls: dict[str, int] = field(default_factory=dict)
    #: *TIME POINTS: name -> (times, on the total time?)
    time_points: dict[str, tuple[np.ndarray, bool]] = field(default_factory=dict)
    #: what the deck leaves to defaults, or reads in a way worth saying (listed before solving, not refused)
    notes: list[str] = field(default_factory=list)
    #: "abaqus" where the deck has keywords only Abaqus reads (*PART, *ASSEMBLY, *INSTANCE), else "calculix"
    dialect: str = "calculix"
    #: shell elements (S3, S4, S4R, S6, S8, S8R; covcontact.io.deck_shells): (deck type, surface cell type, labels,
    #: connectivity as node labels) per *ELEMENT card, and where each card is
    shell_blocks: list[tuple[str, str, np.ndarray, np.ndarray]] = field(default_factory=list)
    shell_where: list[str] = field(default_factory=list)
    #: *SHELL SECTION: (elset, material, thickness or None, offset, where)
    shell_sections: list[tuple[str, str, float | None, float, str]] = field(default_factory=list)
    #: *NODAL THICKNESS: node label -> (thickness, where)
    nodal_thickness: dict[int, tuple[float, str]] = field(default_factory=dict)
    #: the shell faces of element surfaces: name -> [(element labels, "SPOS" | "SNEG", where)]
    shell_surfaces: dict[str, list[tuple[np.ndarray, str, str]]] = field(default_factory=dict)

    def skipped_card(self, label: int) -> str:
        """The *ELEMENT line of element ``label`` of a type covcontact does not read: '*ELEMENT, TYPE=S8R at
        FILE:LINE'."""
        etype = self.skipped_elements[int(label)]
        where = next((w for t, w, labels in self.skipped_blocks if t == etype and np.any(labels == int(label))), "?")
        return f"*ELEMENT, TYPE={etype} at {where}"

    def skipped(self, label: int) -> str | None:
        """What element ``label`` is when covcontact does not read its type: 'an S8R (*ELEMENT, TYPE=S8R at
        FILE:LINE)'; None for an element that is read or not defined."""
        etype = self.skipped_elements.get(int(label))
        if etype is None:
            return None
        return f"{_article(etype)} {etype} ({self.skipped_card(label)})"

    def element_set(self, name: str) -> np.ndarray | None:
        """The labels of element set ``name`` with the elements not read that an ELSET= of their *ELEMENT card put
        in it (a load or surface on them then names their type where it is refused); None: no such set."""
        name = name.upper()
        parts = [self.elsets[name]] if name in self.elsets else []
        parts += [self.skipped_blocks[i][2] for i in self.skipped_elsets.get(name, [])]
        return np.concatenate(parts) if parts else None

    def element_types(self) -> str:
        """The deck's element types that covcontact does not read, each with its first *ELEMENT line: 'S8R (FILE:LINE), S4
        (FILE:LINE)'."""
        first: dict[str, str] = {}
        for t, w, _ in self.skipped_blocks:
            first.setdefault(t, w)
        return ", ".join(f"{t} ({w})" for t, w in first.items())

    def node_index(self) -> np.ndarray:
        """label -> row of X (-1: no such node)."""
        top = int(self.node_labels.max()) + 1 if self.node_labels.size else 1
        idx = np.full(top, -1, dtype=np.int64)
        idx[self.node_labels] = np.arange(self.node_labels.size)
        return idx


def nlgeom_steps(steps: list[Step]) -> list[bool]:
    """Whether each step is geometrically nonlinear: NLGEOM, once given, holds in the later steps until NLGEOM=NO
    (CalculiX's manual, *STEP)."""
    out, on = [], False
    for st in steps:
        on = on if st.nlgeom is None else st.nlgeom
        out.append(on)
    return out


def _article(word: str) -> str:
    """'a' or 'an' before an element type as it is said (an S8R, an SPRINGA, a CPS6, a C3D15)."""
    return "an" if word[:1].upper() in "AEFHILMNORSX" else "a"


def read_model(path) -> DeckModel:
    """The model of the deck at ``path`` (a DeckError for malformed input)."""
    return _Reader(read_deck(path)).m


class _Reader(LoadCards, MaterialCards):
    def __init__(self, cards: list[Card]):
        self.m = m = DeckModel()
        self.material: str | None = None
        self.interaction: str | None = None
        self.step: Step | None = None
        self.changing: str | None = None  # the interaction of the step's *CHANGE FRICTION
        self.node_cards: list[str] = []
        self.frequency = 1  # (FREQUENCY stays in force from step to step until another is given)
        nodes, coords = [], []
        k = 0
        while k < len(cards):
            c = cards[k]
            k += 1
            if c.name in _ABAQUS_ONLY:
                m.dialect = "abaqus"
            if c.name in SPRING_CARDS:  # (*SPRING, *DASHPOT: deck_springs checks its own parameters)
                read_spring_card(self, c)
                continue
            if c.name == "MPC":  # (deck_mpc)
                read_mpc_card(self, c)
                continue
            if c.name not in SUPPORTED:
                m.unsupported.append(f"{c.where()}: *{c.name} is not supported")
                if c.params.get("SURFACE"):  # (a *PRE-TENSION SECTION's surface cuts through its body)
                    m.unsupported_surfaces.add(c.params["SURFACE"].upper())
                if str(c.params.get("NODE", "")).strip().isdigit():  # (its reference node: loads on it act on nothing)
                    m.unsupported_nodes[int(c.params["NODE"])] = f"{c.where()}: *{c.name}"
                continue
            if c.name in COUPLING_CARDS:  # (deck_coupling checks its own parameters)
                read_coupling_card(self, c, cards[k] if k < len(cards) else None)
                continue
            if c.name in SHELL_CARDS:  # (*SHELL SECTION, *NODAL THICKNESS: deck_shells)
                read_shell_card(self, c)
                continue
            if c.name in TEST_DATA_CARDS:  # (*UNIAXIAL TEST DATA, ...: deck_testdata)
                read_test_data_card(self, c)
                continue
            self._check_params(c)
            if c.name == "HEADING":
                m.heading = " ".join(c.data)[:200]
            elif c.name == "NODE":
                self.node_cards.append(c.where())
                lab, xyz = self._nodes(c)
                nodes.append(lab)
                coords.append(xyz)
                if "NSET" in c.params:
                    self._add(m.nsets, c.params["NSET"], lab)
            elif c.name == "ELEMENT":
                self._elements(c)
            elif c.name in ("NSET", "ELSET"):
                self._set(c)
            elif c.name == "SURFACE":
                self._surface(c)
            elif c.name == "MATERIAL":
                self.material = c.param("NAME", required=True).upper()
                m.materials[self.material] = {"where": c.where()}
            elif c.name in ("ELASTIC", "PLASTIC", "DENSITY"):
                self._material(c)
            elif c.name == "HYPERELASTIC":
                self._hyperelastic(c)
            elif c.name == "SOLID SECTION":
                m.sections.append((c.param("ELSET", required=True).upper(), c.param("MATERIAL", required=True).upper(),
                                   c.where()))
                if c.rows() and c.rows()[0]:  # (read for planar elements: deck_planar)
                    m.section_thickness[c.where()] = (c.rows()[0][0], c.where(0))
            elif c.name == "SURFACE INTERACTION":
                self.interaction = c.param("NAME", required=True).upper()
                m.interactions[self.interaction] = Interaction(self.interaction, where=c.where())
            elif c.name == "CHANGE FRICTION":
                st = self._in_step(c)
                self.changing = c.param("INTERACTION", required=True).upper()
                if self.changing not in m.interactions:
                    raise c.fail(f"no *SURFACE INTERACTION named {self.changing!r}")
            elif c.name == "FRICTION" and self.step is not None:
                if self.changing is None:
                    raise c.fail("*FRICTION inside a step belongs after *CHANGE FRICTION")
                rows = c.rows()
                if not rows:
                    raise c.fail("needs 'friction coefficient[, stick slope]'")
                self.step.friction[self.changing] = c.number(0, 0, rows[0], "the friction coefficient")
            elif c.name in ("SURFACE BEHAVIOR", "FRICTION"):
                self._interaction(c)
            elif c.name == "CONTACT PAIR":
                kind = " ".join(c.param("TYPE", "NODE TO SURFACE").upper().split())
                if kind not in ("NODE TO SURFACE", "SURFACE TO SURFACE"):
                    m.unsupported.append(f"{c.where()}: *CONTACT PAIR, TYPE={kind} is not supported")
                    continue
                adjust = c.param("ADJUST")
                if adjust is not None:
                    try:
                        adjust = float(adjust)
                    except ValueError:
                        adjust = adjust.upper()
                        if adjust not in m.nsets:
                            raise c.fail(f"ADJUST={c.params['ADJUST']}: neither a distance nor a *NSET defined above")
                    if isinstance(adjust, float) and adjust < 0.0:
                        raise c.fail(f"ADJUST must be >= 0, got {adjust}")
                for j, row in enumerate(c.rows()):
                    if len(row) < 2:
                        raise c.fail("a contact pair needs 'slave surface, master surface'", j)
                    m.pairs.append((c.param("INTERACTION", required=True).upper(), kind, row[0].upper(),
                                    row[1].upper(), c.where(j)))
                    if adjust is not None:
                        m.pair_adjust[c.where(j)] = adjust
            elif c.name == "EQUATION":
                if "REMOVE ALL" in c.params or "REMOVE" in c.params:
                    st = self._in_step(c)
                    if "REMOVE ALL" in c.params:
                        st.remove_equations = None
                    elif st.remove_equations is not None:
                        for j, row in enumerate(c.rows()):
                            if len(row) < 2:
                                raise c.fail("a line of *EQUATION, REMOVE is 'node or set, dof'", j)
                            dof = int(c.number(j, 1, row, "the dof"))
                            st.remove_equations += [(int(n), dof) for n in self._resolve_nodes(c, j, row[0])]
                elif self.step is not None:
                    raise c.fail("new equations belong to the model data, before the first *STEP")
                else:
                    self._equation(c)
            elif c.name == "AMPLITUDE":
                self._amplitude(c)
            elif c.name == "TIE":
                tol = c.param("POSITION TOLERANCE")
                try:
                    tol = float(tol) if tol not in (None, "") else None
                except ValueError:
                    raise c.fail(f"POSITION TOLERANCE must be a number, got {tol!r}") from None
                for j, row in enumerate(c.rows()):
                    if len(row) < 2:
                        raise c.fail("a tie is 'slave surface, master surface'", j)
                    m.ties.append((c.param("NAME", required=True).upper(), row[0].upper(), row[1].upper(), tol,
                                   c.where(j)))
            elif c.name == "STEP":
                if self.step is not None:
                    raise c.fail("a *STEP inside a step (a missing *END STEP?)")
                inc = c.param("INC")
                if inc is not None and not inc.strip().isdigit():
                    raise c.fail(f"INC must be a whole number, got {inc!r}")
                self.step = Step(c.where(), None if "NLGEOM" not in c.params else c.params["NLGEOM"].upper() != "NO",
                                 (1.0, 1.0, None, None), False, frequency=self.frequency)
            elif c.name in ("STATIC", "DYNAMIC"):
                st = self._in_step(c)
                if c.name == "DYNAMIC":
                    st.dynamic = True
                    alpha = c.param("ALPHA", "-0.05")
                    try:
                        st.alpha = float(alpha)
                    except ValueError:
                        raise c.fail(f"ALPHA must be a number, got {alpha!r}") from None
                    if not -1.0 / 3.0 <= st.alpha <= 0.0:
                        raise c.fail(f"ALPHA must lie in [-1/3, 0], got {st.alpha}")
                row = c.rows()[0] if c.data else []
                vals = [c.number(0, j, row, w, d) for j, (w, d) in
                        enumerate((("the initial increment", 1.0), ("the step's period", 1.0)))]
                lo = c.number(0, 2, row, "the smallest increment", 0.0) if len(row) > 2 and row[2] else None
                hi = c.number(0, 3, row, "the largest increment", 0.0) if len(row) > 3 and row[3] else None
                if vals[0] <= 0 or vals[1] <= 0:
                    raise c.fail("the initial increment and the period must be > 0", 0)
                st.increments = (vals[0], vals[1], lo, hi)
                st.direct = "DIRECT" in c.params
            elif c.name == "END STEP":
                if self.step is None:
                    raise c.fail("*END STEP without a *STEP")
                if m.steps:  # print requests a step does not restate carry over from the step before
                    last = m.steps[-1]
                    if "node" not in self.step.prints_given:
                        self.step.node_print = list(last.node_print)
                    if "el" not in self.step.prints_given:
                        self.step.el_print = list(last.el_print)
                    if "contact" not in self.step.prints_given:
                        self.step.contact_print, self.step.contact_card = last.contact_print, last.contact_card
                    if "section" not in self.step.prints_given:
                        self.step.section_print = list(last.section_print)
                m.steps.append(self.step)
                self.step = None
                self.changing = None
            elif c.name == "RIGID BODY":
                self._rigid_body(c)
            elif c.name == "BOUNDARY":
                self._boundary(c)
            elif c.name in ("CLOAD", "DLOAD", "DSLOAD"):
                self._load(c)
            elif c.name == "CONTROLS":
                self._controls(c)
            elif c.name == "TIME POINTS":
                self._time_points(c)
            if c.name in _OUTPUT and self.step is not None:
                self._frequency(c)
            if c.name in ("NODE PRINT", "EL PRINT", "CONTACT PRINT", "SECTION PRINT"):
                self._print(c)
        if self.step is not None:
            raise DeckError(f"{self.step.where}: *STEP without its *END STEP")
        finish_test_data(m)
        self._nodes_ready(nodes, coords)

    # -- helpers ---------------------------------------------------------------------------------
    def _check_params(self, c: Card) -> None:
        for p in c.params:
            if p in _HARMLESS or (c.name == "DYNAMIC" and p == "ALPHA") or (c.name == "CONTROLS") or (
                    c.name == "TIE" and p in ("POSITION TOLERANCE", "ADJUST") and c.params[p].upper() != "NO") or (
                    p in ("AMPLITUDE", "TIME DELAY") and c.name in ("BOUNDARY", "CLOAD", "DLOAD", "DSLOAD")) or (
                    p == "FIXED" and c.name == "BOUNDARY" and self.step is not None) or (
                    c.name == "AMPLITUDE" and p == "TIME") or (c.name == "RIGID BODY" and p in ("REF NODE", "ROT NODE", "REFNODE", "ROTNODE")) or (
                    c.name == "CONTACT PAIR" and p in ("ADJUST", "SMALL SLIDING")) or (
                    c.name == "EQUATION" and p in ("REMOVE", "REMOVE ALL")) or (
                    c.name == "SOLID SECTION" and p == "OFFSET") or (
                    c.name == "PLASTIC" and p == "HARDENING") or (c.name == "SECTION PRINT" and p == "SURFACE") or (
                    c.name == "HYPERELASTIC" and (p in ("N", "POISSON", "TEST DATA INPUT") or _rubber_option(p))):
                continue
            self.m.unsupported.append(f"{c.where()}: *{c.name}, {p}{'=' + c.params[p] if c.params[p] else ''} is not "
                                      f"supported")

    def _controls(self, c: Card) -> None:
        """*CONTROLS, PARAMETERS=TIME INCREMENTATION: CalculiX's I_C (the most iterations of an increment) and I_A
        (the most cutbacks of an increment) raise covcontact's own limits (the largest over the deck); other
        parameters (FIELD, LINE SEARCH, CONTACT, RESET) leave covcontact's own criteria, said in a note."""
        kind = " ".join(c.param("PARAMETERS", "").upper().split())
        if kind == "TIME INCREMENTATION":
            values = [f for row in c.rows() for f in row]
            for j, key in ((3, "max_iterations"), (7, "max_cutbacks")):
                if j < len(values) and values[j]:
                    try:
                        v = int(float(values[j]))
                    except ValueError:
                        raise c.fail(f"TIME INCREMENTATION value {j + 1} must be a number, got {values[j]!r}") from None
                    self.m.controls[key] = max(v, self.m.controls.get(key, 0))
            return
        what = f"PARAMETERS={kind}" if kind else ("RESET" if "RESET" in c.params else "without PARAMETERS")
        self.m.notes.append(f"{c.where()}: *CONTROLS, {what}: covcontact's own Newton criteria apply ([solver])")

    def _time_points(self, c: Card) -> None:
        """*TIME POINTS, NAME=, TIME=TOTAL TIME, GENERATE: the times (step time unless TIME=TOTAL TIME)."""
        name = c.param("NAME", required=True).upper()
        time = " ".join(c.param("TIME", "STEP TIME").upper().split())
        if time not in ("STEP TIME", "TOTAL TIME"):
            raise c.fail(f"TIME must be STEP TIME or TOTAL TIME, got {c.params['TIME']!r}")
        v = numbers(c, None, "the times")
        if "GENERATE" in c.params:
            if v.size % 3:
                raise c.fail("GENERATE takes lines 'start, end, increment'")
            parts = []
            for a, b, d in v.reshape(-1, 3):
                if d <= 0 or b < a:
                    raise c.fail("GENERATE needs start <= end and an increment > 0")
                parts.append(np.arange(a, b + 0.5 * d, d))
            v = np.concatenate(parts) if parts else v
        self.m.time_points[name] = (np.unique(v), time == "TOTAL TIME")

    def _frequency(self, c: Card) -> None:
        """FREQUENCY= and TIME POINTS= of an output request: the step's output increments (the last FREQUENCY
        applies to all output, and stays from step to step, as in CalculiX)."""
        if "FREQUENCY" in c.params:
            try:
                n = int(c.params["FREQUENCY"])
            except ValueError:
                raise c.fail(f"FREQUENCY must be a whole number, got {c.params['FREQUENCY']!r}") from None
            if n < 0:
                raise c.fail(f"FREQUENCY must be >= 0, got {n}")
            if n > 0:
                self.frequency = self.step.frequency = n
                self.step.time_points = None
        if "TIME POINTS" in c.params:
            name = c.params["TIME POINTS"].upper()
            if name not in self.m.time_points:
                raise c.fail(f"TIME POINTS={c.params['TIME POINTS']}: no *TIME POINTS of that name above")
            self.step.time_points = name

    def _print(self, c: Card) -> None:
        """*NODE PRINT, *EL PRINT, *CONTACT PRINT, *SECTION PRINT: the first of a kind in a step replaces the requests
        carried over from the step before (a bare card, without its set, only clears them: CalculiX's way to stop
        printing). CalculiX reads contact variables by their first four letters (CSTRESS is CSTR, CDISP CDIS) and
        section variables by SOF, SOM, SOAREA (one table of the surface's forces and moments for all three)."""
        st = self._in_step(c)
        kind = c.name.split()[0].lower()
        totals = c.param("TOTALS", "NO").upper()
        if totals not in ("NO", "YES", "ONLY"):
            raise c.fail(f"TOTALS must be NO, YES or ONLY, got {c.params['TOTALS']!r}")
        if kind not in st.prints_given:
            st.prints_given.add(kind)
            if kind == "node":
                st.node_print = []
            elif kind == "el":
                st.el_print = []
            elif kind == "section":
                st.section_print = []
            else:
                st.contact_print, st.contact_card = (), (c.where(), "NO")
        variables = tuple(v.upper() for row in c.rows() for v in row)
        if kind == "contact":
            st.contact_print += variables
            st.contact_card = (st.contact_card[0], totals if totals != "NO" else st.contact_card[1])
            self._unprinted(c, variables, ("CSTR", "CDIS", "CELS", "CNUM"), prefix=True)
            return
        if kind == "section":
            surface, name = c.param("SURFACE"), c.param("NAME")
            if name is None:
                raise c.fail("missing parameter NAME= (CalculiX requires it)")
            if surface is None:
                self.m.notes.append(f"{c.where()}: *SECTION PRINT without SURFACE=: nothing printed (as CalculiX)")
                return
            st.section_print.append((surface.upper(), name.upper(), variables, c.where()))
            self._unprinted(c, variables, ("SOF", "SOM", "SOAREA"), prefix=True)
            return
        key = "NSET" if kind == "node" else "ELSET"
        target = c.param(key)
        if target is None:
            if variables:
                raise c.fail(f"missing parameter {key}= (e.g. *{c.name}, {key}=...); a bare *{c.name} without data "
                             f"stops the printing")
            return
        if kind == "node":
            st.node_print.append((target.upper(), variables, c.where(), totals))
            self._unprinted(c, variables, ("U", "RF"))
        else:
            st.el_print.append((target.upper(), variables, c.where(), totals))
            self._unprinted(c, variables, ("S", "E", "PEEQ", "ENER", "ELSE", "EVOL"))

    def _unprinted(self, c: Card, variables: tuple, printed: tuple, prefix: bool = False) -> None:
        """Output variables the .dat does not tabulate: a note each (the run goes on; they are not printed).
        ``prefix``: a variable that starts with one of ``printed`` is printed (CalculiX's reading of contact and
        section variables)."""
        for v in variables:
            if not (any(v.startswith(p) for p in printed) if prefix else v in printed):
                self.m.notes.append(f"{c.where()}: *{c.name} {v}: not printed in the .dat (covcontact tabulates "
                                    f"{', '.join(printed)} there)")

    def _in_step(self, c: Card) -> Step:
        if self.step is None:
            raise c.fail("belongs inside a *STEP")
        return self.step

    def _nodes_ready(self, nodes, coords) -> None:
        if nodes and (len(nodes) > 1 or self.m.node_labels.size == 0):
            lab = np.concatenate([self.m.node_labels, *nodes])
            xyz = np.concatenate([self.m.X, *coords])
            nodes.clear()
            coords.clear()
            order = np.argsort(lab, kind="stable")
            lab, xyz = lab[order], xyz[order]
            if lab.size > 1 and np.any(lab[1:] == lab[:-1]):  # (CalculiX: a node defined again takes the new place)
                again = lab[1:] == lab[:-1]
                moved = again & np.any(xyz[1:] != xyz[:-1], axis=1)
                dup = int(lab[1:][again][0])
                self.m.notes.append(f"*NODE: {int(again.sum())} node(s) defined again (the first {dup}; the *NODE "
                                    f"cards: {', '.join(self.node_cards)}): the last definition holds, as in CalculiX"
                                    + (f" ({int(moved.sum())} of them moved)" if moved.any() else ""))
                last = np.append(lab[1:] != lab[:-1], True)
                lab, xyz = lab[last], xyz[last]
            self.m.node_labels, self.m.X = lab, xyz
        elif nodes:
            nodes.clear()
            coords.clear()

    @staticmethod
    def _add(sets: dict, name: str, labels: np.ndarray) -> None:
        name = name.upper()
        if name in sets:
            labels = np.concatenate([sets[name], labels])
        ordered = labels.size < 2 or bool(np.all(labels[1:] > labels[:-1]))
        sets[name] = labels if ordered else np.unique(labels)

    def _nodes(self, c: Card) -> tuple[np.ndarray, np.ndarray]:
        try:
            a = numbers(c, 4, "a node (label, x, y, z)") if c.data else np.zeros((0, 4))
        except DeckError:  # (2D nodes, or a malformed line: line by line below)
            a = None
        if a is None or len(a) != len(c.data):
            a = np.zeros((len(c.data), 4))
            for k, row in enumerate(c.rows()):
                if not 1 <= len(row) <= 4:  # (coordinates left out are 0, as CalculiX reads them: nodes.f)
                    raise c.fail(f"a node line is 'label, x, y, z', got {len(row)} fields", k)
                for j in range(len(row)):
                    a[k, j] = c.number(k, j, row, ("the node label", "x", "y", "z")[j], 0.0)
        lab = a[:, 0]
        if np.any(lab != np.round(lab)) or np.any(lab <= 0):
            k = int(np.flatnonzero((lab != np.round(lab)) | (lab <= 0))[0])
            raise c.fail(f"node labels are positive whole numbers, got {c.data[k].split(',')[0]!r}", k)
        return lab.astype(np.int64), a[:, 1:4].copy()

    def _elements(self, c: Card) -> None:
        etype = c.param("TYPE", required=True).upper()
        if etype in SPRING_ELEMENTS:  # (springs and dashpots, no solids: deck_springs)
            read_spring_elements(self, c, etype)
            return
        if etype in SHELL_ELEMENTS:  # (shells, made into solid-shells at import: deck_shells)
            read_shell_elements(self, c, etype)
            return
        refuse_shell_type(c, etype)
        if etype not in ELEMENTS:
            self.m.unsupported.append(f"{c.where()}: *ELEMENT, TYPE={etype} is not supported "
                                      + BEAMS.get(etype, f"(covcontact reads {element_names(ELEMENTS)})"))
            cont = False
            labels = []
            for line in c.data:  # (their labels and nodes: a surface or set on them is named as such later)
                fields = [f.strip() for f in line.split(",") if f.strip()]
                if not cont and fields and fields[0].isdigit():
                    self.m.skipped_elements[int(fields[0])] = etype
                    labels.append(int(fields[0]))
                    self.m.skipped_nodes.update(int(f) for f in fields[1:] if f.isdigit())
                elif cont:
                    self.m.skipped_nodes.update(int(f) for f in fields if f.isdigit())
                cont = line.rstrip().endswith(",")
            self.m.skipped_blocks.append((etype, c.where(), np.asarray(labels, dtype=np.int64)))
            if "ELSET" in c.params:  # (a load or section on that set then names the type, not an undefined set)
                self.m.skipped_elsets.setdefault(c.params["ELSET"].upper(), []).append(len(self.m.skipped_blocks) - 1)
            return
        cell = ELEMENTS[etype][0]
        try:
            a = numbers(c, 1 + NNODE[cell], f"a {etype} element (label and {NNODE[cell]} nodes)", integer=True)
        except DeckError:
            if etype != "C3D8I":
                raise
            # (a C3D8I line with more than its eight nodes, as CalculiX writes them with the nodes of its incompatible
            # modes: CalculiX reads the first eight of each line, and so does this)
            rows = [[f for f in r if f] for r in c.rows()]
            if not rows or any(len(r) < 9 for r in rows):
                raise
            a = np.array([[int(c.number(k, j, r, "a node label")) for j in range(9)] for k, r in enumerate(rows)],
                         dtype=np.int64)
        if a.dtype != np.int64:
            if np.any(a != np.round(a)):
                raise c.fail("element and node labels are whole numbers")
            a = a.astype(np.int64)
        self.m.blocks.append((etype, cell, a[:, 0], a[:, 1:]))
        self.m.block_where.append(c.where())
        if "ELSET" in c.params:
            self._add(self.m.elsets, c.params["ELSET"], a[:, 0])

    def _set(self, c: Card) -> None:
        key = "NSET" if c.name == "NSET" else "ELSET"
        name = c.param(key, required=True).upper()
        sets = self.m.nsets if key == "NSET" else self.m.elsets
        labels: list[np.ndarray] = []
        rows = c.rows()
        if "GENERATE" in c.params:
            for k, row in enumerate(rows):
                a, b = (int(c.number(k, j, row, w)) for j, w in enumerate(("the first label", "the last label")))
                s = int(c.number(k, 2, row, "the increment", 1.0))
                if s <= 0 or b < a:
                    raise c.fail("GENERATE needs 'first, last, increment' with first <= last and increment > 0", k)
                labels.append(np.arange(a, b + 1, s, dtype=np.int64))
        else:
            for k, row in enumerate(rows):
                ids = []
                for f in row:
                    if not f:
                        continue
                    if f.lstrip("-").isdigit():
                        ids.append(int(f))
                    elif f.upper() in sets:
                        labels.append(np.asarray(ids, dtype=np.int64))
                        ids = []
                        labels.append(np.asarray(self.m.nset_order.get(f.upper(), sets[f.upper()])
                                                 if key == "NSET" else sets[f.upper()], dtype=np.int64))
                    elif key == "ELSET" and f.upper() in self.m.skipped_elsets:  # (of elements not read)
                        labels.append(self.m.element_set(f))
                    else:
                        raise c.fail(f"{f!r} is neither a label nor a {key} defined above", k)
                labels.append(np.asarray(ids, dtype=np.int64))
        new = np.concatenate(labels) if labels else np.zeros(0, np.int64)
        if key == "NSET":
            self.m.nset_order.setdefault(name, []).extend(int(v) for v in new)
        self._add(sets, name, new)

    def _surface(self, c: Card) -> None:
        name = c.param("NAME", required=True).upper()
        kind = c.param("TYPE", "ELEMENT").upper()
        if kind == "NODE":
            labels = []
            for k, row in enumerate(c.rows()):
                ref = row[0].upper() if row else ""
                if ref.isdigit():
                    labels.append(np.array([int(ref)]))
                elif ref in self.m.nsets:
                    labels.append(self.m.nsets[ref])
                else:
                    raise c.fail(f"{row[0] if row else ''!r} is neither a node label nor a *NSET defined above", k)
            self.m.surfaces[name] = ("NODE", np.unique(np.concatenate(labels)))
            return
        if kind != "ELEMENT":
            self.m.unsupported.append(f"{c.where()}: *SURFACE, TYPE={kind} is not supported")
            return
        refs = []
        for k, row in enumerate(c.rows()):
            if shell_surface_row(self, c, k, row, name):  # (a shell's sides: deck_shells)
                continue
            if len(row) < 2 or not row[1].upper().startswith("S") or not row[1][1:].isdigit():
                raise c.fail("an element surface line is 'element set or label, S1..S6'", k)
            ref = row[0].upper()
            els = np.array([int(ref)]) if ref.isdigit() else self.m.element_set(ref)
            if els is None:
                raise c.fail(f"{row[0]!r} is neither an element label nor an *ELSET defined above", k)
            refs.append((els, int(row[1][1:]), c.where(k)))
        self.m.surfaces[name] = ("ELEMENT", refs)

    def _interaction(self, c: Card) -> None:
        if self.interaction is None:
            raise c.fail("comes before any *SURFACE INTERACTION")
        it = self.m.interactions[self.interaction]
        rows = c.rows()
        if c.name == "FRICTION":
            if not rows:
                raise c.fail("needs 'friction coefficient, stick slope'")
            it.friction = (c.number(0, 0, rows[0], "the friction coefficient"),
                           c.number(0, 1, rows[0], "the stick slope") if len(rows[0]) > 1 else None)
            return
        law = c.param("PRESSURE-OVERCLOSURE", "HARD").upper()
        if law not in ("HARD", "LINEAR", "EXPONENTIAL", "TIED", "TABULAR"):
            raise c.fail(f"PRESSURE-OVERCLOSURE={law} is not a pressure-overclosure law (HARD, LINEAR, EXPONENTIAL, "
                         f"TABULAR, TIED)")
        it.behavior = law.lower()
        it.where = c.where()
        if law == "EXPONENTIAL":
            if not rows:
                raise c.fail("PRESSURE-OVERCLOSURE=EXPONENTIAL needs its data line 'c0, p0'")
            it.values = (c.number(0, 0, rows[0], "c0"), c.number(0, 1, rows[0], "p0"))
            if it.values[0] <= 0.0 or it.values[1] < 0.0:
                raise c.fail("c0 must exceed zero and p0 must not be negative", 0)
        elif law in ("LINEAR", "TIED"):
            # (CalculiX: K, sigma_inf, c0; missing or non-positive values take its defaults, said in the notes)
            row = rows[0] if rows else []
            it.values = tuple(c.number(0, j, row, w, 0.0) if j < len(row) else 0.0
                              for j, w in enumerate(("the slope K", "sigma_inf", "c0")[: 1 if law == "TIED" else 3]))
        elif law == "TABULAR":
            pts = []
            for k, r in enumerate(rows):
                temp = c.number(k, 2, r, "the temperature", 0.0)
                if pts and temp != pts[0][2]:
                    self.m.unsupported.append(f"{c.where(k)}: *SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=TABULAR at "
                                              f"several temperatures is not supported; with --ignore-unsupported the "
                                              f"table at the first temperature is used")
                    break
                pts.append((c.number(k, 1, r, "the overclosure"), c.number(k, 0, r, "the pressure"), temp))
            if not pts:
                raise c.fail("PRESSURE-OVERCLOSURE=TABULAR needs lines 'pressure, overclosure'")
            for k in range(1, len(pts)):  # (as CalculiX: the overclosures made to increase by at least 1e-10)
                if pts[k][0] - pts[k - 1][0] < 1e-10:
                    pts[k] = (pts[k - 1][0] + 1e-10, pts[k][1], pts[k][2])
            it.values = tuple(v for d, pr, _ in pts for v in (d, pr))

    def _equation(self, c: Card) -> None:
        rows = c.rows()
        k = 0
        while k < len(rows):
            n = int(c.number(k, 0, rows[k], "the number of terms"))
            start = k
            k += 1
            terms: list[tuple[int, int, float]] = []
            while len(terms) < n:
                if k >= len(rows):
                    raise c.fail(f"an equation of {n} terms ends after {len(terms)}", start)
                row = rows[k]
                if len(row) % 3:
                    raise c.fail("equation terms are 'node, dof, coefficient' triples", k)
                for j in range(0, len(row), 3):
                    node = int(c.number(k, j, row, "the node"))
                    dof = int(c.number(k, j + 1, row, "the dof"))
                    if not 1 <= dof <= 3:
                        self.m.unsupported.append(f"{c.where(k)}: *EQUATION on dof {dof} (only the displacements 1..3)")
                    terms.append((node, dof, c.number(k, j + 2, row, "the coefficient")))
                k += 1
            if len(terms) != n:
                raise c.fail(f"an equation of {n} terms has {len(terms)}", start)
            if terms[0][2] == 0.0:
                raise c.fail("the first coefficient of an equation (its dependent term) must not be zero", start)
            self.m.equations.append((terms, c.where(start)))

    def _amplitude(self, c: Card) -> None:
        """A tabular amplitude: pairs (time, value), on the step time or (TIME=TOTAL TIME) the total time."""
        name = c.param("NAME", required=True).upper()
        if set(c.params) - {"NAME", "TIME"}:  # (USER, DEFINITION=..., VALUE=ABSOLUTE, SHIFT: listed as unsupported)
            self.m.skipped_amplitudes.add(name)
            return
        time = " ".join(c.param("TIME", "STEP TIME").upper().split())
        if time not in ("STEP TIME", "TOTAL TIME"):
            raise c.fail(f"TIME must be STEP TIME or TOTAL TIME, got {c.params['TIME']!r}")
        v = numbers(c, None, "the amplitude's pairs (time, value)")
        if v.size < 2 or v.size % 2:
            raise c.fail("needs pairs 'time, value' (an even number of fields, at least one pair)")
        t, a = v[0::2], v[1::2]
        if np.any(np.diff(t) <= 0):
            raise c.fail("the times of an amplitude must increase")
        self.m.amplitudes[name] = (t, a, time == "TOTAL TIME")

    def _rigid_body(self, c: Card) -> None:
        """*RIGID BODY, NSET= or ELSET=, REF NODE=, ROT NODE= (model data)."""
        if self.step is not None:
            raise c.fail("*RIGID BODY is model data: it belongs before the first *STEP")
        nset, elset = c.param("NSET"), c.param("ELSET")
        if (nset is None) == (elset is None):
            raise c.fail("*RIGID BODY takes one of NSET= and ELSET=")
        if nset is not None:
            nodes = self.m.nsets.get(nset.upper())
            if nodes is None:
                raise c.fail(f"NSET={nset}: no *NSET of that name above")
        else:
            els = self.m.elsets.get(elset.upper())
            if els is None:
                raise c.fail(f"ELSET={elset}: no *ELSET of that name above")
            want = set(els.tolist())
            nodes = np.unique(np.concatenate([conn[np.isin(labels, list(want))].ravel()
                                              for _, _, labels, conn in self.m.blocks] + [np.zeros(0, np.int64)]))
        refs = []
        for key in ("REF NODE", "ROT NODE"):
            v = c.param(key, c.param(key.replace(" ", "")))  # (CalculiX also reads REFNODE, ROTNODE)
            if v is not None and not v.strip().isdigit():
                raise c.fail(f"{key} must be a node label, got {v!r}")
            refs.append(int(v) if v is not None else None)
        self.m.rigid_bodies.append((np.asarray(nodes, dtype=np.int64), refs[0], refs[1], c.where()))
