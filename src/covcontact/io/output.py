"""Result files: one VTU per converged step, result.pvd, summary.json, convergence.csv, all atomic."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from .atomic import replacing

# hex18 has no VTK type: each element is written as four linear hexahedra over its 3x3 node grid
_HEX18_SPLIT = np.array([
    [0, 4, 8, 7, 9, 13, 17, 16],
    [4, 1, 5, 8, 13, 10, 14, 17],
    [8, 5, 2, 6, 17, 14, 11, 15],
    [7, 8, 6, 3, 16, 17, 15, 12],
])
_VTK_NAME = {"hex8": "hexahedron", "hex27": "hexahedron27", "quad4": "quad", "quad9": "quad9", "tet4": "tetra",
             "tet10": "tetra10", "wedge6": "wedge", "hex20": "hexahedron20", "tri3": "triangle", "tri6": "triangle6",
             "quad8": "quad8", "line": "line", "line3": "line3"}


def atomic_write_text(path: Path, text: str) -> None:
    """Write text to ``path`` through a temporary file in the same folder and a rename."""
    with replacing(path) as tmp, open(tmp, "w") as fh:
        fh.write(text)


def vtk_cells(cell_type: str, cells: np.ndarray) -> tuple[str, np.ndarray, np.ndarray]:
    """VTK cell name, connectivity and parent-element index for a covcontact cell block."""
    if cell_type == "hex18":
        sub = cells[:, _HEX18_SPLIT].reshape(-1, 8)
        return "hexahedron", sub, np.repeat(np.arange(len(cells)), 4)
    return _VTK_NAME[cell_type], cells, np.arange(len(cells))


def body_blocks(mesh, offset: int, cell_data: dict[str, np.ndarray]) -> list[tuple[str, np.ndarray, dict]]:
    """The VTU blocks of a body's ``mesh`` whose nodes start at ``offset``: (cell type, connectivity, its rows of
    the mesh-order ``cell_data``) per cell block."""
    return [(b.cell_type, b.cells + offset, {k: np.asarray(v)[b.first: b.first + len(b.cells)]
                                             for k, v in cell_data.items()}) for b in mesh.blocks]


class ResultWriter:
    """Writes the output folder of one run, one converged step at a time."""

    def __init__(self, out: Path):
        self.out = Path(out)
        self.out.mkdir(parents=True, exist_ok=True)
        self.pvd_entries: list[tuple[float, str]] = []
        self.csv_rows: list[str] = ["step,iteration,residual_norm,energy_norm,active_contacts,linear,krylov_iterations,"
                                    "status_changes"]

    def write_vtu(self, step: int, time_value: float, points: np.ndarray,
                  blocks: list[tuple[str, np.ndarray, dict[str, np.ndarray]]],
                  point_data: dict[str, np.ndarray]) -> None:
        """Write ``step_NNNN.vtu``; blocks are (covcontact cell type, global connectivity, cell data)."""
        cells = []
        cdata: dict[str, list[np.ndarray]] = {}
        names = set()
        for _, _, cd in blocks:
            names.update(cd)
        for ctype, conn, cd in blocks:
            vname, vconn, parent = vtk_cells(ctype, conn)
            cells.append((vname, vconn))
            for key in names:
                if key in cd:
                    arr = np.asarray(cd[key])[parent]
                else:
                    width = next(np.asarray(c[key]).shape[1:] for _, _, c in blocks if key in c)
                    arr = np.full((len(parent),) + width, np.nan)
                cdata.setdefault(key, []).append(arr)
        import meshio  # imported by the first VTU written: runs without VTU output do not pay for it

        mesh = meshio.Mesh(points, cells, point_data=point_data, cell_data=cdata)
        name = f"step_{step:04d}.vtu"
        with replacing(self.out / name) as tmp:
            meshio.write(tmp, mesh, file_format="vtu", binary=True)
        self.pvd_entries.append((time_value, name))
        self._write_pvd()

    def restore_series(self, pvd_entries: list) -> None:
        """Continue the VTU series of an earlier run (resume from a checkpoint): the checkpoint's
        ``pvd_entries``; VTU files written after it are removed."""
        self.pvd_entries = [(float(t), str(f)) for t, f in pvd_entries]
        kept = {f for _, f in self.pvd_entries}
        for path in self.out.glob("step_*.vtu"):
            if path.name not in kept:
                path.unlink()
        self._write_pvd()

    def restore_iterations(self, step: int) -> None:
        """Continue convergence.csv of an earlier run at the end of ``step``: the iterations of steps up to it."""
        csv = self.out / "convergence.csv"
        if csv.is_file():
            rows = csv.read_text().splitlines()[1:]
            self.csv_rows += [r for r in rows if r and int(r.split(",", 1)[0]) <= step]
        atomic_write_text(csv, "\n".join(self.csv_rows) + "\n")

    def _write_pvd(self) -> None:
        lines = ['<?xml version="1.0"?>',
                 '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
                 "  <Collection>"]
        for t, f in self.pvd_entries:
            lines.append(f'    <DataSet timestep="{t:.10g}" group="" part="0" file="{f}"/>')
        lines += ["  </Collection>", "</VTKFile>", ""]
        atomic_write_text(self.out / "result.pvd", "\n".join(lines))

    def add_iterations(self, step: int, records) -> None:
        for r in records:
            self.csv_rows.append(f"{step},{r.iteration},{r.residual:.6e},{r.energy:.6e},{r.active},{r.linear},"
                                 f"{r.krylov},{r.changes}")
        atomic_write_text(self.out / "convergence.csv", "\n".join(self.csv_rows) + "\n")

    def write_summary(self, summary: dict, text: str | None = None) -> None:
        """summary.json of ``summary`` (``text``: its summary_text, where the caller has it)."""
        atomic_write_text(self.out / "summary.json", text if text is not None else summary_text(summary))


def summary_text(summary: dict, steps: list[str] | None = None) -> str:
    """summary.json's text: a key per line, and a list of records (the steps) a record per line. Written after every
    increment, so the compact dumps of json's compiled encoder: an indented dump runs its pure-Python one, whose cost
    over a long run's rewrites grows with the square of the steps (1.4 s of a 70-step 6 s run). ``steps``: the
    encoded records of the first steps, where the caller keeps them (only the others are encoded)."""
    lines = []
    for key, value in summary.items():
        head = f"  {json.dumps(key)}: "
        if isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
            done = steps if key == "steps" and steps is not None else []
            body = ",\n".join([*("    " + s for s in done),
                                *("    " + json.dumps(v, default=_jsonable) for v in value[len(done):])])
            lines.append(f"{head}[\n{body}\n  ]")
        else:
            lines.append(head + json.dumps(value, default=_jsonable))
    return "{\n" + ",\n".join(lines) + "\n}\n"


def _jsonable(obj):
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")
