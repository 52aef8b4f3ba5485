"""Pictures of a result folder: the initial and the final state, like the figures of a paper.

``render_pictures(out)`` reads ``step_0000.vtu`` and the last ``step_NNNN.vtu`` of a result folder and writes
``initial.png`` and ``final.png`` (and, for a staged run, ``<stage>.png`` at the end of every stage but the
last): the deformable bodies coloured by the displacement magnitude, the rigid
bodies in translucent grey, drawn at the current position (points + displacement) with equal axis scaling
and a colour bar. Only matplotlib (off-screen, Agg) and meshio are needed.

Rigid bodies are recognised by their cells: the result files give them no stress (NaN), and they carry the
largest ``body_id`` values.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

# the six faces of a linear hexahedron (VTK order), each ordered outward
_HEX_FACES = np.array([
    [0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7],
])
_LIGHT = np.array([0.35, -0.45, 0.82]) / np.linalg.norm([0.35, -0.45, 0.82])
_STRESS_KEYS = ("von_mises", "cauchy", "pk2", "green_lagrange")


#: the cell field a plastic problem's pictures are coloured by
PLASTIC = "equivalent_plastic_strain"


def _step_files(out: Path) -> list[Path]:
    files = [p for p in out.glob("step_*.vtu") if re.fullmatch(r"step_\d+\.vtu", p.name)]
    return sorted(files, key=lambda p: int(p.stem.split("_")[1]))


def _load_factor(out: Path, name: str) -> float | None:
    """Load factor of a step file from result.pvd (None if unknown)."""
    try:
        text = (out / "result.pvd").read_text()
    except OSError:
        return None
    m = re.search(r'timestep="([^"]+)"[^>]*file="' + re.escape(name) + '"', text)
    return float(m.group(1)) if m else None


def _rigid_mask(mesh, block: int, n: int) -> np.ndarray:
    """True for the cells of cell block ``block`` that belong to rigid bodies."""
    for key in _STRESS_KEYS:
        if key in mesh.cell_data:
            arr = np.asarray(mesh.cell_data[key][block], dtype=float).reshape(n, -1)
            return np.all(np.isnan(arr), axis=1)
    if "body_id" in mesh.cell_data:
        ids = np.concatenate([np.asarray(b, dtype=float).ravel() for b in mesh.cell_data["body_id"]])
        bid = np.asarray(mesh.cell_data["body_id"][block], dtype=float).ravel()
        return bid == ids.max() if len(np.unique(ids)) > 1 else np.zeros(n, dtype=bool)
    return np.zeros(n, dtype=bool)


def _contact_facets(mesh, block: int) -> bool:
    """True for a block of slave facets written for their contact pressure, or of a solid-shell body's mid-surface
    written for its resultants (not a body to draw)."""
    for key in ("contact_facet_pressure", "shell_thickness"):
        arr = mesh.cell_data.get(key)
        if arr is not None and not np.all(np.isnan(np.asarray(arr[block], dtype=float))):
            return True
    return False


#: the faces of a tetrahedron and of a wedge by their corners, triangles as quadrilaterals with a repeated corner
_TET_FACES = np.array([[0, 2, 1, 1], [0, 1, 3, 3], [1, 2, 3, 3], [0, 3, 2, 2]])
_WEDGE_FACES = np.array([[0, 2, 1, 1], [3, 4, 5, 5], [0, 1, 4, 3], [1, 2, 5, 4], [0, 3, 5, 2]])


def _boundary_quads(hexes: np.ndarray, faces_of=None) -> tuple[np.ndarray, np.ndarray]:
    """Faces of linear hexahedra (or of the cells whose faces ``faces_of`` lists) that belong to one cell only,
    and the index of that cell."""
    table = _HEX_FACES if faces_of is None else faces_of
    if len(hexes) == 0:
        return np.zeros((0, 4), dtype=np.int64), np.zeros(0, dtype=np.int64)
    faces = hexes[:, table].reshape(-1, 4)
    key = np.sort(faces, axis=1)
    key[:, 1:][key[:, 1:] == key[:, :-1]] = -1  # a triangle's repeated corner, wherever it was
    key = np.sort(key, axis=1)
    _, inv, count = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    outer = count[inv.ravel()] == 1
    return faces[outer], np.flatnonzero(outer) // len(table)


def surface_quads(mesh, field: str | None = None):
    """(quads (m, 4), rigid (m,) bool) of the drawable surface of a meshio mesh of covcontact results; with
    ``field`` also the values (m,) of that cell field on the cell behind each quad (nan where absent)."""
    quads, rigid, values = [], [], []
    for b, block in enumerate(mesh.cells):
        conn = np.asarray(block.data, dtype=np.int64)
        mask = _rigid_mask(mesh, b, len(conn))
        data = (np.asarray(mesh.cell_data[field][b], dtype=float).reshape(len(conn), -1)[:, 0]
                if field is not None and field in mesh.cell_data else np.full(len(conn), np.nan))
        solid = {"tetra": (_TET_FACES, 4), "wedge": (_WEDGE_FACES, 6)}.get(block.type.rstrip("0123456789"))
        if block.type.startswith("hexahedron") or solid is not None:
            table, corners = solid if solid is not None else (None, 8)
            for flag in (False, True):
                cells = np.flatnonzero(mask == flag)
                q, owner = _boundary_quads(conn[cells, :corners], table)
                quads.append(q)
                rigid.append(np.full(len(q), flag))
                values.append(data[cells[owner]])
        elif block.type.startswith("quad") and not _contact_facets(mesh, b):
            quads.append(conn[:, :4])
            rigid.append(mask)
            values.append(data)
    if not quads:
        empty = (np.zeros((0, 4), dtype=np.int64), np.zeros(0, dtype=bool))
        return empty if field is None else (*empty, np.zeros(0))
    out = (np.vstack(quads), np.concatenate(rigid))
    return out if field is None else (*out, np.concatenate(values))


def _state(path: Path):
    import meshio

    mesh = meshio.read(path)
    x = np.asarray(mesh.points, dtype=float)
    disp = np.asarray(mesh.point_data.get("displacement", np.zeros_like(x)), dtype=float)
    disp = np.nan_to_num(disp)
    quads, rigid, eps_p = surface_quads(mesh, PLASTIC)
    return x + disp, np.linalg.norm(disp, axis=1), quads, rigid, eps_p


def _shade(polys: np.ndarray) -> np.ndarray:
    n = np.cross(polys[:, 2] - polys[:, 0], polys[:, 3] - polys[:, 1])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    return 0.55 + 0.45 * np.abs(n @ _LIGHT)


def _draw(path: Path, state, lo: np.ndarray, hi: np.ndarray, vmax: float, title: str,
          view: tuple[float, float], length: str = "", plastic: bool = False) -> None:
    import matplotlib
    from matplotlib.figure import Figure
    from matplotlib.ticker import MaxNLocator
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    x, mag, quads, rigid, eps_p = state
    tol = 1e-3 * float((hi - lo).max())
    inside = np.all((x[quads] >= lo - tol) & (x[quads] <= hi + tol), axis=(1, 2))
    keep = ~rigid | inside  # rigid faces leaving the frame are left out (matplotlib does not clip in 3D)
    quads, rigid, eps_p = quads[keep], rigid[keep], eps_p[keep]
    polys = x[quads]
    cmap = matplotlib.colormaps["viridis"]
    norm = matplotlib.colors.Normalize(0.0, vmax)
    colors = np.empty((len(quads), 4))
    values = np.nan_to_num(eps_p[~rigid]) if plastic else mag[quads[~rigid]].mean(axis=1)
    colors[~rigid] = cmap(norm(values))
    colors[rigid] = (0.72, 0.72, 0.75, 0.55)
    colors[:, :3] *= _shade(polys)[:, None]
    edge = np.where(rigid[:, None], (0.35, 0.35, 0.4, 0.35), (0.1, 0.1, 0.1, 0.5))

    fig = Figure(figsize=(8.0, 5.6), dpi=130)
    ax = fig.add_subplot(projection="3d", computed_zorder=False)
    coll = Poly3DCollection(polys, facecolors=colors, edgecolors=edge, linewidths=0.25)
    ax.add_collection3d(coll)
    span = hi - lo
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(tuple(np.maximum(span, 1e-3 * span.max())))
    ax.view_init(elev=view[0], azim=view[1])
    unit = f" [{length}]" if length else ""
    ax.set_xlabel("x" + unit)
    ax.set_ylabel("y" + unit)
    ax.set_zlabel("z" + unit)
    ax.tick_params(labelsize=7, pad=0)
    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.set_major_locator(MaxNLocator(5))
    sm = matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap)
    fig.colorbar(sm, ax=ax, shrink=0.55, pad=0.12,
                 label="equivalent plastic strain" if plastic else "displacement magnitude" + unit)
    ax.set_title(title)
    tmp = path.with_name("." + path.name + ".tmp.png")
    fig.savefig(tmp, bbox_inches="tight", pad_inches=0.15)
    tmp.replace(path)


def render_pictures(out_dir: Path, view: tuple[float, float] = (18.0, -65.0)) -> list[Path]:
    """Write ``initial.png`` and ``final.png`` of the result folder ``out_dir``; return their paths.

    ``view`` is the camera (elevation, azimuth) in degrees. Nothing is written (empty list) when the
    folder holds no step files.
    """
    out_dir = Path(out_dir)
    files = _step_files(out_dir)
    if not files:
        return []
    first, last = files[0], files[-1]
    s0, s1 = _state(first), _state(last)
    # one frame for both pictures: the deformable bodies in both states, plus the rigid parts near them
    pts = [s[0][np.unique(s[2][~s[3]])] for s in (s0, s1) if (~s[3]).any()]
    allp = np.vstack(pts) if pts else np.vstack([s0[0], s1[0]])
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    pad = 0.15 * (hi - lo).max()
    lo, hi = lo - pad, hi + pad
    for s in (s0, s1):
        rp = s[0][np.unique(s[2][s[3]])] if s[3].any() else np.zeros((0, 3))
        if len(rp):
            near = np.all((rp > lo - pad) & (rp < hi + pad), axis=1)
            if near.any():
                lo = np.minimum(lo, rp[near].min(axis=0))
                hi = np.maximum(hi, rp[near].max(axis=0))
    deform = ~s1[3]
    # a plastic problem is coloured by the equivalent plastic strain, an elastic one by the displacement
    peak = float(np.nanmax(s1[4][deform], initial=0.0)) if deform.any() and np.isfinite(s1[4][deform]).any() \
        else 0.0
    plastic = peak > 0.0
    vmax = peak if plastic else (float(s1[1][np.unique(s1[2][deform])].max()) if deform.any() else 1.0)
    vmax = vmax if vmax > 0 else 1.0
    written = []
    lam = _load_factor(out_dir, last.name)
    step = int(last.stem.split("_")[1])
    summary = _summary(out_dir)
    ends = _stage_ends(summary)
    length = _length_unit(summary)
    if _dynamic(summary):  # the pvd time of a dynamic step is the time
        final = f"final state: step {step}" + (f", time {lam:.4g}" if lam is not None else "")
    elif ends:  # a staged run: the pvd time is not a load factor
        final = f"final state: step {step}, end of stage {ends[-1][0]!r}"
    else:
        final = f"final state: step {step}" + (f", load factor {lam:.3g}" if lam is not None else "")
    for state, name, label in ((s0, "initial.png", "initial state"), (s1, "final.png", final)):
        path = out_dir / name
        _draw(path, state, lo, hi, vmax, label, view, length, plastic)
        written.append(path)
    for name, k in ends[:-1]:  # a staged run: the end of every stage but the last
        f = out_dir / f"step_{k:04d}.vtu"
        if f.exists():
            path = out_dir / f"{re.sub(r'[^A-Za-z0-9_.-]+', '_', name)}.png"
            _draw(path, _state(f), lo, hi, vmax, f"end of stage {name!r}: step {k}", view, length, plastic)
            written.append(path)
    energy = energy_plot(out_dir, summary)
    return written + ([energy] if energy is not None else [])


def energy_plot(out_dir: Path, summary: dict | None = None) -> Path | None:
    """``energy.png``: the energies of a run with dynamic steps (summary.json ``energy`` against ``time``): kinetic,
    strain, contact, their sum, the applied forces' work and the dissipation; None without dynamic steps."""
    summary = _summary(out_dir) if summary is None else summary
    steps = [s for s in summary.get("steps", []) if s.get("converged") and "energy" in s]
    if not steps:
        return None
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    t = np.array([s["time"] for s in steps])
    e = {k: np.array([s["energy"][k] for s in steps]) for k in steps[0]["energy"]}
    fig, ax = plt.subplots(figsize=(6.4, 3.6), dpi=110)
    for key, style in (("kinetic", "-"), ("strain", "-"), ("contact", "-"), ("external_work", "--"),
                       ("dissipation", ":")):
        if np.any(e[key]):
            ax.plot(t, e[key], style, label=key.replace("_", " "))
    ax.plot(t, e["kinetic"] + e["strain"] + e["contact"], "k-", lw=1.5, label="kinetic + strain + contact")
    ax.set_xlabel("time")
    ax.set_ylabel("energy")
    worst = float(np.max(np.abs(e["balance_error"])))
    ax.set_title(f"energies (largest balance error {worst:.2g})", fontsize=10)
    ax.legend(fontsize=8, loc="best")
    ax.grid(alpha=0.3)
    path = out_dir / "energy.png"
    tmp = path.with_name(".energy.tmp.png")
    fig.savefig(tmp, bbox_inches="tight")
    plt.close(fig)
    tmp.replace(path)
    return path


def _summary(out_dir: Path) -> dict:
    """The run's summary.json ({} when there is none that reads)."""
    import json

    try:
        return json.loads((out_dir / "summary.json").read_text())
    except (OSError, ValueError):
        return {}


def _dynamic(summary: dict) -> bool:
    """Whether the run's last step was a dynamic one (its summary record has energies)."""
    steps = summary.get("steps", [])
    return bool(steps) and "energy" in steps[-1]


def _length_unit(summary: dict) -> str:
    """The length unit of the problem's ``units`` (its first entry); "" if not stated."""
    units = summary.get("units", "")
    return units.replace(";", ",").split(",")[0].strip() if units else ""


def _stage_ends(summary: dict) -> list[tuple[str, int]]:
    """(stage name, its last converged step) of a staged run; [] for a single stage."""
    ends: dict[str, int] = {}
    for entry in summary.get("steps", []):
        if entry.get("converged") and "stage" in entry:
            ends[entry["stage"]] = int(entry["step"])
    return list(ends.items())
