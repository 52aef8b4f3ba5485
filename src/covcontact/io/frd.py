"""CalculiX's ASCII result file (``.frd``) of a deck's run, and a reader of it (docs/input.md, "Abaqus and CalculiX
decks").

:class:`FrdFile` writes ``DECK.frd`` beside the ``.dat`` table: the nodes (the ``2C`` block) and elements (``3C``) of
the deck's solid elements with its node and element labels, then at the end of each deck step (where the ``.dat``
prints) one result set of the blocks ``DISP`` (displacements), ``STRESS`` (the Cauchy stress averaged at the nodes, as
in the VTU files), ``TOSTRAIN`` (the Green-Lagrange strain averaged at the nodes, CalculiX's total strain of a
geometrically nonlinear step), ``FORC`` (the internal and contact forces at each node: the reactions at supported
nodes, the applied load at loaded ones, zero elsewhere; the ``.dat``'s RF) and, where a body is plastic, ``PE`` (the
equivalent plastic strain averaged at the nodes). The records are CalculiX's fixed-width ones (``cgx``, FreeCAD and
PrePoMax read them by column): numbers as ``%12.5E`` of single precision, nodes and elements in increasing label
order, a 20-node brick's mid-edge nodes in CalculiX's frd order (the vertical edges before the top ones).

:func:`read_frd` reads such a file back (CalculiX's own ASCII ``.frd`` files too).
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..observer import Observer
from .deck_dat import output_due

#: covcontact cell type -> (CalculiX's frd element type, the cell's nodes in the order the frd lists them); the
#: deck's node order of C3D8, C3D6, C3D4, C3D10 and C3D20 is covcontact's (VTK's); the frd lists a 20-node brick's
#: vertical mid-edge nodes (deck nodes 17-20) before those of the top face (13-16), and a 15-node wedge's vertical ones
#: (13-15) before the top ones (10-12) after the first ten
#: a hex18 (quad9 bottom 0-8, quad9 top 9-17: corners, mid-sides, centre) as four hex8 over its quarters
_HEX18_SPLIT = tuple(tuple(q) + tuple(i + 9 for i in q) for q in ((0, 4, 8, 7), (4, 1, 5, 8), (8, 5, 2, 6),
                                                                  (7, 8, 6, 3)))
FRD_CELLS = {
    "hex8": (1, tuple(range(8))),
    "wedge6": (2, tuple(range(6))),
    "tet4": (3, tuple(range(4))),
    "hex20": (4, (*range(12), 16, 17, 18, 19, 12, 13, 14, 15)),
    "wedge15": (5, (*range(9), 12, 13, 14, 9, 10, 11)),
    "tet10": (6, tuple(range(10))),
    # planar cells as CalculiX writes 2D elements (OUTPUT=2D): tr3, tr6, qu4, qu8 in the deck's node order
    "tri3": (7, tuple(range(3))),
    "tri6": (8, tuple(range(6))),
    "quad4": (9, tuple(range(4))),
    "quad8": (10, tuple(range(8))),
}

#: the result blocks: name -> (frd component lines (name, type, row, column), with an ALL line)
_BLOCKS = {
    "DISP": ((("D1", 2, 1, 0), ("D2", 2, 2, 0), ("D3", 2, 3, 0)), True),
    "STRESS": ((("SXX", 4, 1, 1), ("SYY", 4, 2, 2), ("SZZ", 4, 3, 3), ("SXY", 4, 1, 2), ("SYZ", 4, 2, 3),
                ("SZX", 4, 3, 1)), False),
    "TOSTRAIN": ((("EXX", 4, 1, 1), ("EYY", 4, 2, 2), ("EZZ", 4, 3, 3), ("EXY", 4, 1, 2), ("EYZ", 4, 2, 3),
                  ("EZX", 4, 3, 1)), False),
    "FORC": ((("F1", 2, 1, 0), ("F2", 2, 2, 0), ("F3", 2, 3, 0)), True),
    "PE": ((("PE", 1, 0, 0),), False),
}

_MONTHS = ("january", "february", "march", "april", "may", "june", "july", "august", "september", "october",
           "november", "december")


def frd_number(x: float) -> str:
    """``x`` as the frd writes a value: %12.5E of its single-precision value (two exponent digits always)."""
    return f"{float(np.float32(x)):12.5E}"


def frd_time(t: float) -> str:
    """The time of a result set's ``100CL`` record, 12 wide: fixed point with ten digits in all from 1 to 1e10,
    else %12.5E."""
    if t > 0.0 and 0.0 <= np.log10(t) < 10.0:
        return f"{t:12.{10 - int(np.floor(np.log10(t) + 1.0))}f}"
    return f"{t:12.5E}"


def _pad(text: str, width: int) -> str:
    return text + " " * max(width - len(text), 0)


def _values(labels: np.ndarray, rows: np.ndarray) -> list[str]:
    """The data records of a block: `` -1``, the label, the values."""
    rows = np.asarray(rows, dtype=np.float32).astype(np.float64)
    return [f" -1{lab:10d}" + "".join(f"{v:12.5E}" for v in row) + "\n"
            for lab, row in zip(labels.tolist(), rows.tolist())]


def header_text(program: str = "covcontact", version: str = "", heading: str = "") -> str:
    """The ``1C`` block: the file's user records (date, time, program)."""
    now = time.localtime()
    lines = ["    1C"]
    if heading:
        lines.append(_pad(f"    1U{heading}", 72))
    for key, value in (("USER", ""), ("DATE", f"{now.tm_mday:02d}.{_MONTHS[now.tm_mon - 1]}.{now.tm_year}"),
                       ("TIME", time.strftime("%H:%M:%S", now)), ("HOST", ""), ("PGM", program),
                       ("VERSION", f"Version {version}" if version else ""), ("DIR", ""), ("DBN", "")):
        lines.append(_pad(f"    1U{key:<18s}{value}", 72))
    return "\n".join(lines) + "\n"


def mesh_text(node_labels: np.ndarray, X: np.ndarray, elements: list[tuple[int, int, int, list[int]]]) -> str:
    """The ``2C`` block of the nodes (``node_labels``, reference coordinates ``X``) and the ``3C`` block of
    ``elements`` [(label, frd type, material number, node labels in frd order)], each in increasing label order."""
    order = np.argsort(node_labels, kind="stable")
    out = [f"    2C{'':18s}{len(order):12d}{1:38d}\n"]
    out += _values(np.asarray(node_labels)[order], np.asarray(X)[order])
    out.append(" -3\n")
    out.append(f"    3C{'':18s}{len(elements):12d}{1:38d}\n")
    for lab, kind, mat, nodes in sorted(elements, key=lambda e: e[0]):
        out.append(f" -1{lab:10d}{kind:5d}{0:5d}{mat:5d}\n")
        for i in range(0, len(nodes), 10):
            out.append(" -2" + "".join(f"{n:10d}" for n in nodes[i: i + 10]) + "\n")
    out.append(" -3\n")
    return "".join(out)


def result_text(name: str, labels: np.ndarray, values: np.ndarray, *, counter: int, kode: int, step: int,
                increment: int, time_value: float, dynamic: bool = False) -> str:
    """One result block: its ``1PSTEP`` and ``100CL`` records, the ``-4`` / ``-5`` header of ``name`` (a key of
    the blocks DISP, STRESS, TOSTRAIN, FORC, PE), a record per node (``labels`` increasing, ``values`` (n, ncomp)),
    `` -3``. ``counter`` numbers the blocks of the file, ``kode`` the result sets (one per time written)."""
    comps, with_all = _BLOCKS[name]
    head = _pad(f"    1PSTEP{'':14s}{counter:12d}{increment:12d}{step:12d}", 70)
    cl = (f"  100CL{100 + kode:5d}{frd_time(time_value)}{len(labels):12d}{'':12s}{'':9s}{'1' if dynamic else '0'}"
          f"{kode:5d}{'':11s}1")
    lines = [head, cl, f" -4  {name:<8s}{len(comps) + with_all:5d}{1:5d}"]
    lines += [f" -5  {c:<8s}{1:5d}{kind:5d}{i:5d}{j:5d}" for c, kind, i, j in comps]
    if with_all:
        lines.append(f" -5  {'ALL':<8s}{1:5d}{2:5d}{0:5d}{0:5d}{1:5d}ALL")
    values = np.asarray(values, dtype=np.float64).reshape(len(labels), len(comps))
    return "\n".join(lines) + "\n" + "".join(_values(np.asarray(labels), values)) + " -3\n"


def _nodal(values: np.ndarray, incidence: tuple[np.ndarray, np.ndarray], n_nodes: int) -> np.ndarray:
    """Element values (nelem, k) averaged at the nodes over the elements that share each (as the Cauchy stress of the
    VTU files, ``elements.base.stress_from_fields``)."""
    els, nodes = incidence
    values = np.asarray(values, dtype=np.float64).reshape(len(values), -1)
    count = np.maximum(np.bincount(nodes, minlength=n_nodes), 1).astype(np.float64)
    out = np.empty((n_nodes, values.shape[1]))
    for k in range(values.shape[1]):
        out[:, k] = np.bincount(nodes, weights=values[els, k], minlength=n_nodes) / count
    return out


class FrdFile(Observer):
    """Writes ``path`` (the .frd) of a deck's run from the labels file of :func:`covcontact.io.deck_import.import_deck`:
    the mesh at the start, a result set at each output increment of the deck (the .dat's: every increment, every
    Nth with FREQUENCY, the time points), `` 9999`` at the end (any status). A resumed
    run goes on with the file it finds (its closing record dropped, its counters read from it)."""

    def __init__(self, labels: Path, path: Path):
        self.info = json.loads(Path(labels).read_text())
        self.path = Path(path)
        steps = self.info.get("deck_step") or list(range(len(self.info["periods"])))
        self.deck_step = steps
        self.counter = 0      # result blocks written
        self.kode = 0         # result sets written
        self.increments = 0   # converged increments of the deck step in hand
        self.in_step = -1     # that deck step
        self.due_count: dict[int, int] = {}  # converged increments per deck step (output_due)

    # -- events ---------------------------------------------------------------------------------------
    def started(self, run) -> None:
        if run.model.is_root:
            from .. import __version__

            self.path.write_text(header_text(version=__version__) + self._mesh(run))

    def resumed(self, run) -> None:
        if not run.model.is_root:
            return
        if not self.path.exists():
            self.started(run)
            return
        lines = self.path.read_text().splitlines(keepends=True)
        while lines and lines[-1].strip() in ("9999", ""):
            lines.pop()
        self.path.write_text("".join(lines))
        # (the increments of a deck step resumed in its middle are counted from the resume on)
        self.counter = sum(1 for ln in lines if ln.startswith("    1PSTEP"))
        self.kode = len({ln[7:12] for ln in lines if ln.startswith("  100CL")})

    def increment_converged(self, run, inc) -> None:
        stage = inc.state.stage
        step = self.deck_step[stage]
        if step != self.in_step:
            self.in_step, self.increments = step, 0
        self.increments += max(1, len(getattr(run.newton, "converged_increments", None) or []))  # (as JOB.sta counts)
        if not output_due(self.info, self.due_count, stage, bool(inc.ends_stage)):  # (the .dat's increments)
            return
        periods = self.info["periods"]
        t = sum(periods[:stage]) + periods[stage] * inc.lam
        text = self._results(run, inc.lam, step + 1, self.increments, t, bool(run.state.dynamics))
        if run.model.is_root:
            with open(self.path, "a") as fh:
                fh.write(text)

    def ended(self, run, status: str) -> None:
        if run.model.is_root and self.path.exists():
            with open(self.path, "a") as fh:
                fh.write(" 9999\n")

    # -- content --------------------------------------------------------------------------------------
    def _bodies(self, run):
        """(block, body, element state, deck node labels, deck element labels) of each deformable body."""
        model = run.model
        for blk, body, est in zip(model.system.blocks, model.problem.bodies, run.state.elements):
            yield (blk, body, est, np.asarray(self.info["bodies"].get(blk.name, []), dtype=np.int64),
                   np.asarray(self.info["elements"].get(blk.name, []), dtype=np.int64))

    def _mesh(self, run) -> str:
        labels, coords, elements = [], [], []
        materials: dict[str, int] = {}  # the distinct materials, numbered from 1 in the order they first appear
        for blk, body, _, nlab, elab in self._bodies(run):
            labels.append(nlab)
            coords.append(body.mesh.points)
            number = np.zeros(body.mesh.n_cells, dtype=np.int64)
            for _, idx, material, _ in body.material_parts():
                number[idx] = materials.setdefault(repr(material), len(materials) + 1)
            for b in body.mesh.blocks:
                if b.cell_type == "hex18":  # (no 18-node brick in the .frd: four C3D8 of its 2 x 2 x 1 corners)
                    for e, cell in enumerate(b.cells.tolist()):
                        for q, sub in enumerate(_HEX18_SPLIT):
                            lab = int(elab[b.first + e]) if q == 0 else self._extra_label(elab)
                            elements.append((lab, 1, int(number[b.first + e]), nlab[[cell[i] for i in sub]].tolist()))
                    continue
                if b.cell_type not in FRD_CELLS:
                    raise ValueError(f"body {blk.name}: {b.cell_type} cells have no CalculiX frd element type")
                kind, order = FRD_CELLS[b.cell_type]
                for e, cell in enumerate(b.cells[:, list(order)].tolist()):
                    elements.append((int(elab[b.first + e]), kind, int(number[b.first + e]), nlab[cell].tolist()))
        return mesh_text(np.concatenate(labels), np.vstack(coords), elements)

    def _extra_label(self, elab) -> int:
        """An element label after every label of the run (the .frd's extra C3D8 of a split hex18)."""
        top = getattr(self, "_next_label", None)
        if top is None:
            top = max([int(v) for labs in self.info["elements"].values() for v in labs] + [0]) + 1
        self._next_label = top + 1
        return top

    def _results(self, run, lam: float, step: int, increment: int, t: float, dynamic: bool) -> str:
        model = run.model
        U = run.u.reshape(-1, 3)
        R, _, _ = model.evaluate(run.u, lam, run.state, want_K=False, raw=True)
        F = (R + model.applied(run.u, lam)).reshape(-1, 3)  # internal and contact forces at each node
        labels, disp, forc, stress, strain, pe = [], [], [], [], [], []
        plastic = False
        for blk, _, est, nlab, _ in self._bodies(run):
            sl = slice(blk.offset, blk.offset + blk.n_nodes)
            st = blk.solid.stress(U[sl], est)
            incidence = blk.solid.incidence()
            labels.append(nlab)
            disp.append(U[sl])
            forc.append(F[sl])
            stress.append(st.cauchy_nodal)
            strain.append(_nodal(st.green_lagrange, incidence, blk.n_nodes))
            fields = blk.solid.plastic_fields(est)
            plastic |= "equivalent_plastic_strain" in fields
            pe.append(_nodal(fields["equivalent_plastic_strain"], incidence, blk.n_nodes)
                      if "equivalent_plastic_strain" in fields else np.zeros((blk.n_nodes, 1)))
        labels = np.concatenate(labels)
        order = np.argsort(labels, kind="stable")
        labels = labels[order]
        self.kode += 1
        out = []
        blocks = [("DISP", disp), ("STRESS", stress), ("TOSTRAIN", strain), ("FORC", forc)]
        if plastic:
            blocks.append(("PE", pe))
        for name, rows in blocks:
            self.counter += 1
            out.append(result_text(name, labels, np.vstack(rows)[order], counter=self.counter, kode=self.kode,
                                   step=step, increment=increment, time_value=t, dynamic=dynamic))
        return "".join(out)


# ---------------------------------------------------------------------------------------------------- reading
@dataclass
class FrdSet:
    """One result block of an frd file: its name, the step, increment and time of its set, the component names and
    the values per node label."""

    name: str
    step: int
    increment: int
    time: float
    kode: int
    components: list[str]
    values: dict[int, np.ndarray] = field(default_factory=dict)


@dataclass
class FrdResults:
    """An frd file read back: nodes (label -> xyz), elements (label -> (frd type, material, node labels)), the result
    blocks in file order, and whether it ends with the closing record (`` 9999``)."""

    nodes: dict[int, np.ndarray] = field(default_factory=dict)
    elements: dict[int, tuple[int, int, list[int]]] = field(default_factory=dict)
    sets: list[FrdSet] = field(default_factory=list)
    closed: bool = False

    def blocks(self, name: str) -> list[FrdSet]:
        return [s for s in self.sets if s.name == name]


#: nodes per element of each frd element type
FRD_NODES = {1: 8, 2: 6, 3: 4, 4: 20, 5: 15, 6: 10}


def _floats(line: str, start: int, n: int) -> np.ndarray:
    return np.array([float(line[start + 12 * k: start + 12 * (k + 1)]) for k in range(n)])


def read_frd(path: str | Path) -> FrdResults:
    """Read an ASCII .frd file by its fixed columns (nodes, elements, nodal result blocks); a ValueError naming the
    line where a record does not parse."""
    out = FrdResults()
    section, current, pending = None, None, None   # pending: [frd type, material, nodes] of the element being read
    step = increment = 0
    lines = Path(path).read_text().splitlines()
    for k, line in enumerate(lines, start=1):
        try:
            key = line[:6]
            if key == "    2C":
                section = "nodes"
            elif key == "    3C":
                section = "elements"
            elif line.startswith("    1PSTEP"):
                increment, step = int(line[36:48]), int(line[48:60])
            elif line.startswith("  100CL"):
                section = "result"
                current = FrdSet("", step, increment, float(line[12:24]), int(line[7:12]) - 100, [])
            elif line.startswith(" -4"):
                current.name = line[5:13].strip()
                out.sets.append(current)
            elif line.startswith(" -5"):
                if line[5:13].strip() != "ALL":
                    current.components.append(line[5:13].strip())
            elif line.startswith(" -3"):
                section = None if section != "result" else section
            elif line.startswith(" 9999"):
                out.closed = True
            elif line.startswith(" -1") and section == "nodes":
                out.nodes[int(line[3:13])] = _floats(line, 13, 3)
            elif line.startswith(" -1") and section == "elements":
                pending = [int(line[13:18]), int(line[23:28]), []]
                out.elements[int(line[3:13])] = pending
            elif line.startswith(" -2") and section == "elements":
                pending[2] += [int(line[i: i + 10]) for i in range(3, len(line.rstrip()), 10)]
            elif line.startswith(" -1") and section == "result":
                out.sets[-1].values[int(line[3:13])] = _floats(line, 13, len(current.components))
        except (ValueError, IndexError, AttributeError, TypeError) as exc:
            raise ValueError(f"{path}, line {k}: cannot read {line!r} ({exc})") from None
    out.elements = {lab: (kind, mat, nodes) for lab, (kind, mat, nodes) in out.elements.items()}
    return out
