"""Writes the decks of tests/verification/test_ccx_finish.py: three small CalculiX decks of kinds that CalculiX 2.20
finishes, as users reported them against covcontact (run again, ``python tests/data/decks/make_decks.py``, to remake
them; the decks are plain text and need nothing but this script):

- ``neck_c3d20r.inp``: one eighth of a rectangular tensile bar of C3D20R with a slightly reduced middle section,
  *PLASTIC with a 7-point table, NLGEOM, pulled by a prescribed end displacement to well past the force maximum
  (automatic increments);
- ``sheet_tools_c3d10.inp``: a plate of C3D10 tetrahedra pressed by four stiff tools at once, each tool its own
  *CONTACT PAIR, TYPE=SURFACE TO SURFACE;
- ``wire_pin.inp``: an elastic-plastic wire of C3D8I bricks bent round a pin by a *RIGID BODY arm turned about
  the pin's axis.
"""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent

#: the hex20 corner and mid-edge nodes in a 3 x 3 x 3 lattice of (i, j, k) in {0, 1, 2}: C3D20 order
HEX20 = [(0, 0, 0), (2, 0, 0), (2, 2, 0), (0, 2, 0), (0, 0, 2), (2, 0, 2), (2, 2, 2), (0, 2, 2),
         (1, 0, 0), (2, 1, 0), (1, 2, 0), (0, 1, 0), (1, 0, 2), (2, 1, 2), (1, 2, 2), (0, 1, 2),
         (0, 0, 1), (2, 0, 1), (2, 2, 1), (0, 2, 1)]
HEX8 = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]


def _lines(values, per_line: int = 8) -> list[str]:
    """Labels written ``per_line`` to a line (as *NSET and *ELSET data)."""
    v = [str(int(x)) for x in values]
    return [", ".join(v[i:i + per_line]) + ("," if i + per_line < len(v) else "") for i in range(0, len(v), per_line)]


def _grid(coords, cells_of):
    """A structured mesh: ``coords`` (ni, nj, nk, 3) lattice points, ``cells_of`` the list of cells, each a list of
    (i, j, k) lattice indices. Returns the nodes used (labels from 1, in lattice order), their coordinates and the
    cells as labels, and the lattice -> label map."""
    used = sorted({p for c in cells_of for p in c})
    label = {p: n + 1 for n, p in enumerate(used)}
    X = np.array([coords[p] for p in used])
    cells = np.array([[label[p] for p in c] for c in cells_of])
    return X, cells, label


# ----------------------------------------------------------------------------------------------------------------
# 1. necking of a C3D20R bar
# ----------------------------------------------------------------------------------------------------------------

#: the bar: width 10 (x), thickness 5 (y), length 60 (z); the eighth x, y, z >= 0 is modelled
NECK_HALF = (5.0, 2.5, 30.0)
#: elements over the half width, half thickness, half length
NECK_CELLS = (3, 2, 12)
#: the middle section is this much narrower (width and thickness), blending to the nominal one at z = 8
NECK_IMPERFECTION = 0.02
NECK_BLEND = 8.0
#: the pulled end's displacement (the eighth's half length grows by it)
NECK_PULL = 9.0
#: true stress against equivalent plastic strain (7 points)
NECK_TABLE = [(200.0, 0.0), (240.0, 0.02), (275.0, 0.06), (300.0, 0.12), (320.0, 0.22), (335.0, 0.40),
              (345.0, 0.80)]


def neck_deck(cells=NECK_CELLS, half=NECK_HALF, pull=NECK_PULL, etype="C3D20R", table=NECK_TABLE,
              static="0.02, 1., 1e-5, 0.05") -> str:
    nx, ny, nz = cells
    a, b, h = half
    i = np.linspace(0.0, 1.0, 2 * nx + 1)
    j = np.linspace(0.0, 1.0, 2 * ny + 1)
    # along the bar: elements twice as fine at the middle as at the end (geometric grading)
    r = 2.0 ** (1.0 / (nz - 1))
    sizes = r ** np.arange(nz)
    edges = np.concatenate([[0.0], np.cumsum(sizes)]) / sizes.sum() * h
    k = np.empty(2 * nz + 1)
    k[0::2] = edges
    k[1::2] = 0.5 * (edges[:-1] + edges[1:])
    coords = {}
    for p, q, s in itertools.product(range(len(i)), range(len(j)), range(len(k))):
        z = k[s]
        shrink = 1.0 - NECK_IMPERFECTION * (0.5 + 0.5 * np.cos(np.pi * z / NECK_BLEND) if z < NECK_BLEND else 0.0)
        coords[(p, q, s)] = np.array([a * i[p] * shrink, b * j[q] * shrink, z])
    cells = [[(2 * ex + di, 2 * ey + dj, 2 * ez + dk) for di, dj, dk in HEX20]
             for ez in range(nz) for ey in range(ny) for ex in range(nx)]
    X, conn, label = _grid(coords, cells)
    out = ["**", "** Necking of a rectangular bar (one eighth), C3D20R, *PLASTIC table, NLGEOM,",
           "** prescribed end displacement to well past the force maximum; written by make_decks.py",
           "*HEADING", "C3D20R tensile bar with a reduced middle section", "*NODE"]
    out += [f"{n + 1}, {x:.10g}, {y:.10g}, {z:.10g}" for n, (x, y, z) in enumerate(X)]
    out.append(f"*ELEMENT, TYPE={etype}, ELSET=BAR")
    for e, c in enumerate(conn):  # (CalculiX reads 16 nodes on the first line, the rest on the next)
        out.append(f"{e + 1}, " + ", ".join(str(v) for v in c[:15]) + ",")
        out.append(", ".join(str(v) for v in c[15:]))
    tol = 1e-9
    for name, test in (("XSYM", lambda p: abs(p[0]) < tol), ("YSYM", lambda p: abs(p[1]) < tol),
                       ("ZSYM", lambda p: abs(p[2]) < tol), ("END", lambda p: abs(p[2] - h) < tol)):
        out.append(f"*NSET, NSET={name}")
        out += _lines([n + 1 for n, p in enumerate(X) if test(p)])
    mid = [n + 1 for n, p in enumerate(X) if abs(p[2]) < tol and abs(p[1]) < tol and abs(p[0] - X[:, 0].max()) < 1e-6]
    out += ["*NSET, NSET=NECK", *_lines(mid)]
    out += ["*MATERIAL, NAME=STEEL", "*ELASTIC", "210000., 0.3", "*PLASTIC"]
    out += [f"{s:.6g}, {e:.6g}" for s, e in table]
    out += ["*SOLID SECTION, ELSET=BAR, MATERIAL=STEEL",
            "*BOUNDARY", "XSYM, 1, 1", "YSYM, 2, 2", "ZSYM, 3, 3",
            "*STEP, NLGEOM, INC=1000", "*STATIC", static,
            "*BOUNDARY", f"END, 3, 3, {pull:g}",
            "*NODE PRINT, NSET=END, TOTALS=ONLY", "RF",
            "*NODE PRINT, NSET=NECK", "U",
            "*END STEP"]
    return "\n".join(out) + "\n"


# ----------------------------------------------------------------------------------------------------------------
# 2. a C3D10 sheet pressed by four tools, each its own surface-to-surface pair
# ----------------------------------------------------------------------------------------------------------------

#: the sheet: length (x), width (y), thickness (z); bricks over them, each split into six C3D10
SHEET = (60.0, 10.0, 2.0)
SHEET_CELLS = (24, 3, 1)
#: the tools: (name, x of the centre, below or above the sheet); each a stiff C3D8 block 4 x 10 x 3 of 2 x 1 x 1
SHEET_TOOLS = (("T1", 8.0, "below"), ("T2", 52.0, "below"), ("T3", 22.0, "above"), ("T4", 38.0, "above"))
TOOL_SIZE = (4.0, 10.0, 3.0)
#: the upper tools' stroke (down)
SHEET_STROKE = 2.0
#: C3D10 faces (S1..S4) by their corner nodes, 0-based
TET_FACES = ((0, 1, 2), (0, 3, 1), (1, 3, 2), (2, 3, 0))
#: Kuhn's six tetrahedra of the unit cube: (0,0,0), then one axis after the other, to (1,1,1)
KUHN = [(0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)]


def _tet10_block(size, cells, origin):
    """A brick (``size``, ``cells`` bricks, ``origin``) split into C3D10 (Kuhn: conforming): lattice coordinates
    (doubled, so that every mid-edge node is a lattice point) -> position, and the cells as lists of lattice
    points in C3D10 order (positive volume)."""
    n = np.array(cells)
    h = np.array(size) / n
    coords = {p: np.asarray(origin) + np.array(p) * h / 2.0
              for p in itertools.product(*(range(2 * c + 1) for c in cells))}
    out = []
    for c in itertools.product(*(range(k) for k in cells)):
        base = 2 * np.array(c)
        for perm in KUHN:
            v = [base.copy()]
            for ax in perm:
                w = v[-1].copy()
                w[ax] += 2
                v.append(w)
            a, b, cc, d = v
            if np.dot(np.cross(b - a, cc - a), d - a) < 0:
                b, cc = cc, b
            corners = [a, b, cc, d]
            mids = [(corners[i] + corners[j]) // 2 for i, j in ((0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3))]
            out.append([tuple(int(x) for x in p) for p in corners + mids])
    return coords, out


def _hex8_block(size, cells, origin):
    n = np.array(cells)
    h = np.array(size) / n
    coords = {p: np.asarray(origin) + np.array(p) * h for p in itertools.product(*(range(c + 1) for c in cells))}
    out = [[(c[0] + di, c[1] + dj, c[2] + dk) for di, dj, dk in HEX8]
           for c in itertools.product(*(range(k) for k in cells))]
    return coords, out


def sheet_deck(tools=SHEET_TOOLS, cells=SHEET_CELLS, stroke=SHEET_STROKE, static="0.1, 1., 1e-5, 0.25", gap=0.0,
               rigid=False, tool_size=TOOL_SIZE, tool_cells=(2, 1, 1), friction=None) -> str:
    L, W, T = SHEET
    out = ["**", "** A C3D10 sheet pressed by several stiff tools at once, each tool its own", "** *CONTACT PAIR, "
           "TYPE=SURFACE TO SURFACE (the sheet's bottom or top the slave); written by make_decks.py",
           "*HEADING", "C3D10 sheet between four tools", "*NODE"]
    nodes, elements, nsets, surfaces = [], [], {}, {}

    def add(coords, cells, first_element):
        X, conn, label = _grid(coords, cells)
        start = len(nodes)
        nodes.extend(X)
        return conn + start, {p: lab + start for p, lab in label.items()}, X

    coords, cells = _tet10_block(SHEET, cells, (0.0, 0.0, 0.0))
    conn, label, X = add(coords, cells, 1)
    elements.append(("C3D10", "SHEET", conn))
    first = 1
    pts = np.array(nodes)
    # the sheet's bottom and top faces: (element, face) of the tetrahedra faces lying on z = 0 and z = T
    for name, z in (("SBOT", 0.0), ("STOP", T)):
        faces = []
        for e, c in enumerate(conn):
            for f, (i, j, k) in enumerate(TET_FACES):
                if all(abs(pts[c[m] - 1, 2] - z) < 1e-9 for m in (i, j, k)):
                    faces.append((first + e, f + 1))
        surfaces[name] = faces
    nsets["SYMX"] = [n + 1 for n, p in enumerate(pts) if abs(p[0] - L / 2) < 1e-9]
    nsets["SYMY"] = [n + 1 for n, p in enumerate(pts) if abs(p[1]) < 1e-9]
    first += len(conn)
    a, b, c = tool_size
    for name, xc, side in tools:
        z0 = -c - gap if side == "below" else T + gap
        coords, cells = _hex8_block(tool_size, tool_cells, (xc - a / 2, 0.0, z0))
        tconn, tlabel, tX = add(coords, cells, first)
        elements.append(("C3D8", name, tconn))
        # the face toward the sheet: S2 (top, 5-8-7-6) of a lower tool, S1 (bottom, 1-2-3-4) of an upper one
        surfaces[name + "F"] = [(first + e, 2 if side == "below" else 1) for e in range(len(tconn))]
        far = 0 if side == "below" else tool_cells[2]
        nsets[name + "N"] = sorted({int(tlabel[p]) for p in coords if p[2] == far})
        first += len(tconn)
    refs = {}
    if rigid:  # a REF NODE and a ROT NODE per tool, at the middle of its face toward the sheet
        for name, xc, side in tools:
            z = -gap if side == "below" else T + gap
            nodes.extend([np.array([xc, b / 2, z])] * 2)
            refs[name] = (len(nodes) - 1, len(nodes))
    for n, (x, y, z) in enumerate(nodes):
        out.append(f"{n + 1}, {x:.10g}, {y:.10g}, {z:.10g}")
    first = 1
    for etype, elset, conn in elements:
        out.append(f"*ELEMENT, TYPE={etype}, ELSET={elset}")
        out += [f"{first + e}, " + ", ".join(str(v) for v in c) for e, c in enumerate(conn)]
        first += len(conn)
    out += ["*ELSET, ELSET=TOOLS", ", ".join(t[0] for t in tools)]
    for name, labels in nsets.items():
        out.append(f"*NSET, NSET={name}")
        out += _lines(labels)
    for name, faces in surfaces.items():
        out.append(f"*SURFACE, NAME={name}, TYPE=ELEMENT")
        out += [f"{e}, S{f}" for e, f in faces]
    out += ["*MATERIAL, NAME=ALU", "*ELASTIC", "70000., 0.33", "*PLASTIC", "150., 0.", "250., 0.2",
            "*MATERIAL, NAME=STEEL", "*ELASTIC", "210000., 0.3",
            "*SOLID SECTION, ELSET=SHEET, MATERIAL=ALU", "*SOLID SECTION, ELSET=TOOLS, MATERIAL=STEEL",
            "*SURFACE INTERACTION, NAME=SI", "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR", "1e6"]
    if friction is not None:
        out += ["*FRICTION", f"{friction[0]:g}, {friction[1]:g}"]
    for name, (ref, rot) in refs.items():
        out.append(f"*RIGID BODY, ELSET={name}, REF NODE={ref}, ROT NODE={rot}")
    for name, xc, side in tools:
        out += ["*CONTACT PAIR, INTERACTION=SI, TYPE=SURFACE TO SURFACE",
                f"{'SBOT' if side == 'below' else 'STOP'}, {name}F"]
    out += ["*BOUNDARY", "SYMX, 1, 1", "SYMY, 2, 2"]
    held = {name: (f"{refs[name][0]}", f"{refs[name][1]}") if rigid else (f"{name}N", None) for name, _, _ in tools}
    for name, xc, side in tools:
        out.append(f"{held[name][0]}, 1, 3")
        if rigid:
            out.append(f"{held[name][1]}, 1, 3")
    out += ["*STEP, NLGEOM, INC=1000", "*STATIC", static, "*BOUNDARY"]
    for name, xc, side in tools:
        if side == "above":
            out.append(f"{held[name][0]}, 3, 3, {-stroke:g}")
    first_below = next(t[0] for t in tools if t[2] == "below")
    if rigid:
        out += ["*NSET, NSET=REF1", held[first_below][0]]
    out += [f"*NODE PRINT, NSET={'REF1' if rigid else first_below + 'N'}, TOTALS=ONLY", "RF", "*END STEP"]
    return "\n".join(out) + "\n"


def main() -> None:
    (HERE / "neck_c3d20r.inp").write_text(neck_deck())
    (HERE / "sheet_tools_c3d10.inp").write_text(sheet_deck())


if __name__ == "__main__":
    main()
