"""A deck's *COUPLING with *KINEMATIC or *DISTRIBUTING and the rotational dofs 4-6 of reference nodes
(covcontact.io.deck_coupling; docs/input.md, "Abaqus and CalculiX decks"; docs/theory.md, "Multi-point
constraints"): a bar held at one end and loaded through its other end, against beam theory (nu = 0 and incompatible
modes make it exact for an axial pull and pure bending) and against CalculiX on the same deck; the distribution's
nodal forces against the reference load; the partial attachment's reduced tangent against differences; the one-line
errors and what is refused."""

from __future__ import annotations

import contextlib
import io
import shutil
import subprocess

import numpy as np
import pytest

from covcontact.io.deck_coupling import Coupling, distribution, weights
from covcontact.io.deck_model import DeckModel

from reduced_fd import column_errors

L, B, H, E = 10.0, 1.0, 1.0, 210000.0
EI = E * B * H ** 3 / 12.0
EA = E * B * H


def bar(coupling: str, steps: str, nu: float = 0.0, nx: int = 8, ny: int = 2, nz: int = 2) -> str:
    """A C3D8I bar L x B x H along x centred on the x axis, held at x = 0 (FIX), its end face x = L the surface SEND
    (faces S4 of the elements of END), node 1000 at the end face's centre, then ``coupling`` and ``steps``."""
    nid = {}
    lines = ["*HEADING", "a bar held at x = 0, its end coupled to node 1000", "*NODE, NSET=NALL"]
    for i in range(nx + 1):
        for j in range(ny + 1):
            for k in range(nz + 1):
                nid[i, j, k] = len(nid) + 1
                lines.append(f"{nid[i, j, k]}, {L * i / nx:.6f}, {B * j / ny - B / 2:.6f}, {H * k / nz - H / 2:.6f}")
    lines += [f"1000, {L:.6f}, 0.0, 0.0", "*ELEMENT, TYPE=C3D8I, ELSET=BAR"]
    for i in range(nx):
        for j in range(ny):
            for k in range(nz):
                n = [nid[i, j, k], nid[i + 1, j, k], nid[i + 1, j + 1, k], nid[i, j + 1, k],
                     nid[i, j, k + 1], nid[i + 1, j, k + 1], nid[i + 1, j + 1, k + 1], nid[i, j + 1, k + 1]]
                lines.append(f"{(i * ny + j) * nz + k + 1}, " + ", ".join(map(str, n)))
    end = [((nx - 1) * ny + j) * nz + k + 1 for j in range(ny) for k in range(nz)]
    lines += ["*ELSET, ELSET=END", ", ".join(map(str, end)),
              "*NSET, NSET=FIX", ", ".join(str(nid[0, j, k]) for j in range(ny + 1) for k in range(nz + 1)),
              "*NSET, NSET=REF", "1000", "*SURFACE, NAME=SEND", "END, S4",
              "*MATERIAL, NAME=STEEL", "*ELASTIC", f"{E}, {nu}", "*SOLID SECTION, ELSET=BAR, MATERIAL=STEEL",
              "*BOUNDARY", "FIX, 1, 3", coupling, steps]
    return "\n".join(lines) + "\n"


def step(body: str) -> str:
    return f"*STEP, NLGEOM\n*STATIC\n1., 1.\n{body}\n*NODE PRINT, NSET=NALL\nU\n*NODE PRINT, NSET=FIX\nRF\n*END STEP\n"


def dat_blocks(path) -> dict:
    """(kind, set, time) -> {node: (3,)} of a .dat table."""
    out, key = {}, None
    for ln in path.read_text().splitlines():
        if "for set" in ln and " and time " in ln:
            key = (ln.split()[0], ln.split("for set ")[1].split()[0], float(ln.split("time")[1]))
            out[key] = {}
            continue
        f = ln.split()
        if key is not None and len(f) == 4 and f[0].isdigit():
            out[key][int(f[0])] = np.array([float(v) for v in f[1:]])
    return out


def run_deck(tmp_path, name: str, text: str) -> tuple[dict, dict | None]:
    """The .dat blocks of ``covcontact run`` on the deck, and of CalculiX's run on it (None without ccx)."""
    from covcontact.cli import main

    deck = tmp_path / f"{name}.inp"
    deck.write_text(text)
    assert main(["run", str(deck), "--out", str(tmp_path / f"o_{name}"), "--quiet"]) == 0
    ours = dat_blocks(tmp_path / f"o_{name}" / f"{name}.dat")
    if not shutil.which("ccx"):
        return ours, None
    ccx_dir = tmp_path / f"ccx_{name}"
    ccx_dir.mkdir()
    (ccx_dir / deck.name).write_text(text)
    subprocess.run(["ccx", "-i", name], cwd=ccx_dir, capture_output=True, timeout=120, check=True)
    return ours, dat_blocks(ccx_dir / f"{name}.dat")


def agree(ours: dict, ref: dict | None) -> float:
    """The largest difference of the blocks both print over the largest value of the reference block."""
    if ref is None:
        return 0.0
    worst = 0.0
    for key, block in ref.items():
        common = [n for n in block if n in ours.get(key, {})]
        assert common, key
        scale = max(np.abs(block[n]).max() for n in common)
        worst = max(worst, max(np.abs(ours[key][n] - block[n]).max() for n in common) / scale)
    return worst


def clamp_moment(forces: dict, X: dict) -> np.ndarray:
    """The moment about the origin of the clamp's reactions."""
    return sum(np.cross(X[n], f) for n, f in forces.items())


def _coordinates(text: str) -> dict:
    lines = text.split("*NODE, NSET=NALL\n")[1].split("*")[0].splitlines()
    return {int(r.split(",")[0]): np.array([float(v) for v in r.split(",")[1:]]) for r in lines if r.strip()}


# ------------------------------------------------------------------------------------------ kinematic


def test_kinematic_coupling_pulls_bends_and_turns_the_bar(tmp_path):
    """*KINEMATIC 1-3 (the end face rigid on node 1000; its rotation about z held by *BOUNDARY dof 6), step 1: an
    axial force F at node 1000: the St. Venant-Kirchhoff stretch (nu = 0: exact) and the clamp's reaction -F; step
    2: F off, a moment M about y on dof 5: the end's rotation M L / (E I) and deflection M L^2 / (2 E I) (pure
    bending; the incompatible modes carry it exactly); step 3: M off, dof 6 turned to phi: the clamp's reaction
    moment E I phi / L and the end's sideways travel phi L / 2 (all to 1e-5; measured <= 3e-7, the .dat's seven
    digits). U and RF within 1e-3 of CalculiX's (measured 1.2e-6)."""
    F, M, phi = 10.0, 2.0, 0.002
    text = bar("*COUPLING, REF NODE=1000, SURFACE=SEND, CONSTRAINT NAME=CAP\n*KINEMATIC\n1, 3",
               step(f"*BOUNDARY\n1000, 6, 6, 0.0\n*CLOAD\n1000, 1, {F}")
               + step(f"*CLOAD\n1000, 1, 0.\n1000, 5, {M}")
               + step(f"*BOUNDARY\n1000, 6, 6, {phi}\n*CLOAD\n1000, 5, 0."))
    ours, ref = run_deck(tmp_path, "kin", text)
    toml = (tmp_path / "o_kin" / "deck" / "kin.toml").read_text()
    assert 'name = "CAP"' in toml and 'free = ["x", "y", "z", "rx", "ry"]' in toml and "attach_components" not in toml
    X = _coordinates(text)
    u1, u2, u3 = (ours[("displacements", "NALL", t)] for t in (1.0, 2.0, 3.0))
    stretch = np.roots([EA / 2, 0.0, -EA / 2, -F])  # E/2 (l^3 - l) A = F
    stretch = float(stretch[np.isreal(stretch) & (stretch.real > 0.5)].real[0])
    assert u1[1000][0] == pytest.approx((stretch - 1.0) * L, rel=1e-5)
    assert np.abs(sum(ours[("forces", "FIX", 1.0)].values()) - [-F, 0.0, 0.0]).max() < 1e-4 * F
    assert u2[1000][2] == pytest.approx(-M * L ** 2 / (2 * EI), rel=1e-5)
    top, bottom = (next(n for n in X if X[n][0] == L and X[n][1] == 0.0 and X[n][2] == z) for z in (0.5, -0.5))
    assert (u2[top][0] - u2[bottom][0]) / H == pytest.approx(M * L / EI, rel=1e-5)  # (the end face turned about y)
    moment = clamp_moment(ours[("forces", "FIX", 3.0)], X)
    assert moment[2] == pytest.approx(-EI * phi / L, rel=1e-5)
    assert u3[1000][1] == pytest.approx(phi * L / 2, rel=1e-5)
    assert agree(ours, ref) <= 1e-3


def test_partial_kinematic_coupling_against_beam_theory_and_calculix(tmp_path):
    """*KINEMATIC 1 (only the end face's axial displacements follow node 1000; the others are free), node 1000's
    translations y, z and rotation x held (dofs 2-4), a moment M about z on dof 6: plane sections in x, the
    end's rotation M L / (E I) with its nodes' sideways travel M L^2 / (2 E I) left to the bar, the clamp's reaction
    moment -M (1e-5; measured 1.3e-7); step 2 adds an axial force. U and RF within 1e-3 of CalculiX's (measured
    1e-6)."""
    F, M = 10.0, 2.0
    text = bar("*COUPLING, REF NODE=1000, SURFACE=SEND, CONSTRAINT NAME=CAP\n*KINEMATIC\n1",
               step(f"*BOUNDARY\n1000, 2, 4\n*CLOAD\n1000, 6, {M}") + step(f"*CLOAD\n1000, 1, {F}"))
    ours, ref = run_deck(tmp_path, "part", text)
    toml = (tmp_path / "o_part" / "deck" / "part.toml").read_text()
    assert 'attach_components = ["x"]' in toml
    X = _coordinates(text)
    u = ours[("displacements", "NALL", 1.0)]
    tip = [n for n in X if X[n][0] == L and n != 1000]
    top, bottom = (next(n for n in tip if X[n][1] == y and X[n][2] == 0.0) for y in (0.5, -0.5))
    assert (u[bottom][0] - u[top][0]) / B == pytest.approx(M * L / EI, rel=1e-5)  # the end face's turn
    assert np.mean([u[n][1] for n in tip]) == pytest.approx(M * L ** 2 / (2 * EI), rel=1e-5)
    assert u[1000][1] == 0.0 and u[1000][2] == 0.0
    moment = clamp_moment(ours[("forces", "FIX", 1.0)], X)
    assert moment[2] == pytest.approx(-M, rel=1e-5)
    assert agree(ours, ref) <= 1e-3


# ---------------------------------------------------------------------------------------- distributing


def test_distribution_sums_to_the_reference_force_and_moment():
    """The nodal forces of a force and moment at a point off the surface, over an L-shaped surface of three faces,
    flat and of bilinear or quadratic faces: their sum is the force, their moment about the point the moment (1e-12);
    the weights sum to 1; a flat rectangular quad8 face's are CalculiX's int N dA / A (corners -1/12, mid-sides
    1/3)."""
    rng = np.random.default_rng(7)
    for element, cell, n in (("C3D8", "hex8", 4), ("C3D20R", "hex20", 8)):
        m = DeckModel()
        corners = np.array([[0, 0], [1, 0], [2, 0], [0, 1], [1, 1], [2, 1], [0, 2], [1, 2]], float)
        quads = [(0, 1, 4, 3), (1, 2, 5, 4), (3, 4, 7, 6)]  # (an L: three faces)
        X, faces = [], []
        for q in quads:
            c = corners[list(q)]
            pts = list(c) + ([(c[k] + c[(k + 1) % 4]) / 2 for k in range(4)] if n == 8 else [])
            face = []
            for p in pts:
                hit = [i for i, x in enumerate(X) if np.allclose(x, p)]
                if not hit:
                    X.append(p)
                    hit = [len(X) - 1]
                face.append(hit[0] + 1)
            faces.append((element, np.array(face)))
        m.X = np.column_stack([np.array(X), 0.3 * np.array(X)[:, 0]])  # (a plane tilted about y)
        m.node_labels = np.arange(1, len(X) + 1)
        cp = Coupling("C", 1, "S", "here", kind="distributing", dofs=(4, 5, 6),
                      nodes=np.unique(np.concatenate([f for _, f in faces])), faces=faces)
        labels, w = weights(m, cp)
        assert w.sum() == pytest.approx(1.0, abs=1e-14)
        p = np.array([0.4, 1.7, 2.5])
        load = rng.standard_normal(6)
        Xn = m.X[labels - 1]
        f = distribution(Xn, w, p) @ load
        assert np.abs(f.sum(axis=0) - load[:3]).max() < 1e-12
        assert np.abs(np.cross(Xn - p, f).sum(axis=0) - load[3:]).max() < 1e-12
        if n == 8:  # one flat face alone: the corners' and mid-sides' shares
            single = Coupling("C", 1, "S", "here", kind="distributing", dofs=(), nodes=np.sort(faces[0][1]),
                              faces=[faces[0]])
            lab, w1 = weights(m, single)
            share = {int(a): b for a, b in zip(lab, w1)}
            assert [share[int(k)] for k in faces[0][1]] == pytest.approx([-1 / 12] * 4 + [1 / 3] * 4, abs=1e-14)


def test_distributing_coupling_loads_the_bar_as_calculix_does(tmp_path):
    """*DISTRIBUTING 4-6 with forces along x and y and a moment about z at node 1000: the imported [[force]] entries
    (one per node of the end face) sum to the force and their moment about node 1000 is the moment (1e-9); U and RF
    within 1e-3 of CalculiX's (measured 2e-16: the same nodal loads); the clamp's reaction balances the load (force,
    and moment at the deformed positions). Step 2's *CLOAD on the REF NODE restates the force alone: the distributed
    loads of step 1 are replaced (CalculiX's OP=NEW in effect), the clamp holds -F alone."""
    import tomllib

    F, Fy, M = 10.0, 1.0, 2.0
    text = bar("*COUPLING, REF NODE=1000, SURFACE=SEND, CONSTRAINT NAME=LOAD\n*DISTRIBUTING\n4, 6",
               step(f"*CLOAD\n1000, 1, {F}\n1000, 2, {Fy}\n1000, 6, {M}") + step(f"*CLOAD\n1000, 1, {F}"))
    ours, ref = run_deck(tmp_path, "dist", text)
    problem = tomllib.loads((tmp_path / "o_dist" / "deck" / "dist.toml").read_text())
    forces = [f for f in problem["force"] if f["name"].startswith("dc1n")]
    assert len(forces) == 9 and all(f["distribution"] == "per_node" for f in forces)
    X = _coordinates(text)
    total = np.sum([f["value"] for f in forces], axis=0)
    moment = np.sum([np.cross(X[int(f["name"][4:])] - X[1000], f["value"]) for f in forces], axis=0)
    assert np.abs(total - [F, Fy, 0.0]).max() < 1e-9 and np.abs(moment - [0.0, 0.0, M]).max() < 1e-9
    reaction = ours[("forces", "FIX", 1.0)]
    assert np.abs(sum(reaction.values()) + [F, Fy, 0.0]).max() < 1e-6
    u = ours[("displacements", "NALL", 1.0)]
    applied = np.sum([np.cross(X[int(f["name"][4:])] + u[int(f["name"][4:])], f["value"]) for f in forces], axis=0)
    assert clamp_moment(reaction, X)[2] == pytest.approx(-applied[2], rel=1e-5)  # (about the origin)
    assert np.abs(sum(ours[("forces", "FIX", 2.0)].values()) + [F, 0.0, 0.0]).max() < 1e-6
    assert 1000 not in ours[("displacements", "NALL", 1.0)]  # (its REF NODE has no unknowns; CalculiX prints 0)
    ref = None if ref is None else {k: {n: v for n, v in b.items() if n != 1000} for k, b in ref.items()}
    assert agree(ours, ref) <= 1e-3


# ------------------------------------------------------------------------------------ partial attachment


def test_partial_attachment_tangent_matches_differences(tmp_path):
    """A cap holding only the x and z components of the bar's top nodes (attach_components): P^T K P plus the
    rotation's second-order part against central differences of P^T R in every independent dof, at a deformed state
    with a rotation of 0.8 rad (<= 1e-6 of max |K|; measured 3e-11); only the held components are eliminated."""
    from covcontact.io.loader import load_problem
    from covcontact.solvers.model import Model

    text = """
[problem]
name = "partial"
[[bodies]]
name = "bar"
element = "hex8"
material = { model = "neo-hooke", E = 100.0, nu = 0.3 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 2.0, nx = 2, ny = 2, nz = 3 }
[[dirichlet]]
set = "bar.zmin"
components = "xyz"
[[rigid]]
name = "cap"
attach = ["bar.zmax"]
attach_components = ["z", "x"]
reference = [0.5, 0.5, 2.0]
free = ["x", "z", "rx", "ry", "rz"]
"""
    path = tmp_path / "partial.toml"
    path.write_text(text)
    model = Model(load_problem(path))
    committed = model.initial_state()
    rng = np.random.default_rng(3)
    u = 0.05 * rng.standard_normal(model.n_dofs)
    ref = model.system.reference[0]
    u[3 * ref.B: 3 * ref.B + 3] = [0.3, -0.2, 0.7]
    R, K, _ = model.evaluate(u, 0.5, committed)
    K = K.toarray()
    dep = model.constraints.mask
    assert ref.attached_components == (0, 2)
    assert dep.sum() == 2 * ref.attached.size and not dep[3 * ref.attached + 1].any()
    worst = max(column_errors(model, u, 0.5, committed, K, np.flatnonzero(~dep)).values())
    assert worst <= 1e-6 * np.abs(K).max()
    assert np.all(R[dep] == 0.0) and np.allclose(K[np.ix_(dep, ~dep)], 0.0)
    bad = {'attach_components = ["z", "x"]': 'attach_components = ["z", "w"]',
           'attach = ["bar.zmax"]\nattach_components = ["z", "x"]\n': 'attach_components = ["z"]\n'}
    from covcontact.io.validate import InputError

    for old, new in bad.items():
        path.write_text(text.replace(old, new))
        with pytest.raises(InputError) as err:
            load_problem(path)
        assert "attach_components" in str(err.value) and "\n" not in str(err.value)


# ---------------------------------------------------------------------------------- errors and refusals


def _run(tmp_path, name: str, text: str) -> tuple[int, str]:
    from covcontact.cli import main

    deck = tmp_path / f"{name}.inp"
    deck.write_text(text)
    buf = io.StringIO()
    with contextlib.redirect_stderr(buf):
        code = main(["import", str(deck), "--out", str(tmp_path / f"{name}.toml")])
    return code, buf.getvalue()


def test_coupling_errors_and_refusals(tmp_path):
    """One line each (exit 2): a coupling on an undefined surface, a dof outside 1..6, *DISTRIBUTING on a node
    surface, *KINEMATIC of rotations alone, *KINEMATIC not after *COUPLING; refused (listed with the line, exit 2):
    ORIENTATION, a *BOUNDARY on a *DISTRIBUTING REF NODE, dofs 4-6 on a node that is no reference node, a moment on a
    dof the *DISTRIBUTING does not name, a *DISTRIBUTING in the Abaqus dialect (a constraint there)."""
    s1 = step("*CLOAD\n1000, 1, 1.0")
    kin = "*COUPLING, REF NODE=1000, SURFACE=SEND, CONSTRAINT NAME=C\n*KINEMATIC\n{dofs}"
    dist = "*COUPLING, REF NODE=1000, SURFACE=SEND, CONSTRAINT NAME=C\n*DISTRIBUTING\n{dofs}"
    errors = {
        bar(kin.replace("SEND", "NOPE").format(dofs="1, 3"), s1): "SURFACE=NOPE: no *SURFACE of that name above",
        bar(kin.format(dofs="1, 7"), s1): "dofs are 'first dof[, last dof]' within 1..6",
        bar(kin.format(dofs="0"), s1): "within 1..6",
        bar("*SURFACE, NAME=NS, TYPE=NODE\nFIX\n" + dist.replace("SEND", "NS").format(dofs="4, 6"), s1):
            "*DISTRIBUTING needs an element (face) surface",
        bar(kin.format(dofs="4, 6"), s1): "dofs 4-6 alone couple nothing on solid nodes",
        bar("*KINEMATIC\n1, 3", s1): "belongs right after a *COUPLING card",
        bar(kin.replace("REF NODE=1000", "REF NODE=FIX").format(dofs="1, 3"), s1): "the reference node is one",
        bar(kin.replace("*KINEMATIC", "*NSET, NSET=X\n1").format(dofs="1, 3"), s1):
            "must be followed by *KINEMATIC or *DISTRIBUTING",
    }
    for k, (text, words) in enumerate(errors.items()):
        code, err = _run(tmp_path, f"bad{k}", text)
        assert code == 2 and words in err and len(err.strip().splitlines()) == 1, (words, err)
    refused = {
        bar(kin.replace("C\n", "C, ORIENTATION=OR1\n").format(dofs="1, 3"), s1): "*COUPLING, ORIENTATION=OR1 is not",
        bar(dist.format(dofs="6"), step("*BOUNDARY\n1000, 1, 1, 0.1")): "*BOUNDARY on the REF NODE 1000 of a "
                                                                          "*DISTRIBUTING coupling",
        bar(kin.format(dofs="1, 3"), step("*BOUNDARY\n1000, 6, 6, 0.1\n*CLOAD\n5, 4, 1.0")):
            "*CLOAD on dof 4 of node 5, which is no reference node",
        bar(dist.format(dofs="6"), step("*CLOAD\n1000, 4, 1.0")): "its *DISTRIBUTING",
    }
    for k, (text, words) in enumerate(refused.items()):
        code, err = _run(tmp_path, f"ref{k}", text)
        assert code == 2 and words in err, (words, err)
    # an Abaqus deck's *DISTRIBUTING (a constraint there): listed, not read as CalculiX's load distribution
    deck = tmp_path / "abq.inp"
    deck.write_text(bar(dist.format(dofs="4, 6"), s1))
    buf = io.StringIO()
    with contextlib.redirect_stderr(buf):
        from covcontact.cli import main

        code = main(["import", str(deck), "--out", str(tmp_path / "abq.toml"), "--dialect", "abaqus"])
    assert code == 2 and "*DISTRIBUTING in an Abaqus deck: Abaqus' distributing coupling is a constraint" in \
        buf.getvalue(), buf.getvalue()


def test_reference_node_rotations_of_a_rigid_body(tmp_path):
    """A *RIGID BODY's REF NODE dofs 4-6 are its rotation (as Abaqus reads them; CalculiX's dialect says so in a
    note): dof 6 turned to phi gives the clamp's reaction moment E I phi / L (1e-3), as the ROT NODE's dof 3 does."""
    from covcontact.cli import main

    phi = 0.002
    for k, (card, bc) in enumerate((("*RIGID BODY, NSET=TIPN, REF NODE=1000", "1000, 6, 6"),
                                    ("*RIGID BODY, NSET=TIPN, REF NODE=1000, ROT NODE=1001", "1001, 3, 3"))):
        text = bar("*NSET, NSET=TIPN\n" + ", ".join(str(n) for n in range(73, 82)) + f"\n{card}",
                   step(f"*BOUNDARY\n{bc}, {phi}")).replace("1000, 10.000000, 0.0, 0.0",
                                                            "1000, 10.000000, 0.0, 0.0\n1001, 0.0, 0.0, 0.0")
        deck = tmp_path / f"rb{k}.inp"
        deck.write_text(text)
        buf = io.StringIO()
        with contextlib.redirect_stderr(buf):
            assert main(["run", str(deck), "--out", str(tmp_path / f"rb{k}"), "--quiet"]) == 0
        assert ("REF NODE's dofs 4-6" in buf.getvalue() or "does not use the REF NODE" in buf.getvalue()) == (k == 0)
        forces = dat_blocks(tmp_path / f"rb{k}" / f"rb{k}.dat")[("forces", "FIX", 1.0)]
        assert clamp_moment(forces, _coordinates(text))[2] == pytest.approx(-EI * phi / L, rel=1e-3)


def test_deck_model_reads_the_coupling(tmp_path):
    """The model: a kinematic coupling is a rigid body of the surface's nodes on its REF NODE (a node set of one
    node names it too); two on one REF NODE make one body."""
    from covcontact.io.deck_model import read_model

    two = ("*COUPLING, REF NODE=REF, SURFACE=SEND, CONSTRAINT NAME=A\n*KINEMATIC\n1, 3\n"
           "*SURFACE, NAME=SIDE\nEND, S6\n*COUPLING, REF NODE=1000, SURFACE=SIDE, CONSTRAINT NAME=B\n*KINEMATIC\n")
    deck = tmp_path / "m.inp"
    deck.write_text(bar(two, step("*CLOAD\n1000, 1, 1.0")))
    m = read_model(deck)
    assert [c.kind for c in m.couplings] == ["kinematic", "kinematic"] and len(m.rigid_bodies) == 1
    nodes, ref, rot, _ = m.rigid_bodies[0]
    assert ref == 1000 and rot is None  # (the end face's nodes, and those of the end elements' faces S6)
    X = _coordinates(deck.read_text())
    assert set(nodes.tolist()) == {n for n in X if X[n][0] in (L, L - L / 8) and n != 1000}
    assert any("without dof lines" in n for n in m.notes)


# ------------------------------------------------------------------------------------ total rotations

#: the rotation vectors of Test/Supports/trans (CalculiX-Examples), one per step: about z, then its axis turned twice
TURNS = ((0.0, 0.0, 1.57), (1.209, 1.209, 1.209), (-1.209, 1.209, 1.209))


def turned_bar(kind: str) -> str:
    """An unloaded C3D8 bar 4 x 1 x 1 along x, held only through its end face x = 0: a *KINEMATIC coupling on REF
    NODE 1000 at the face's centre, turned by its dofs 4-6 (``coupling``), or a *RIGID BODY of the face's nodes with
    ROT NODE 1001 (``rigid``); one step per rotation vector of ``TURNS``."""
    nid, nx = {}, 4
    lines = ["*HEADING", "a bar turned through its support", "*NODE, NSET=NALL"]
    for i in range(nx + 1):
        for j in range(2):
            for k in range(2):
                nid[i, j, k] = len(nid) + 1
                lines.append(f"{nid[i, j, k]}, {i:.1f}, {j - 0.5:.1f}, {k - 0.5:.1f}")
    lines += ["1000, 0.0, 0.0, 0.0", "1001, 0.0, 0.0, 0.0", "*ELEMENT, TYPE=C3D8, ELSET=BAR"]
    for i in range(nx):
        n = [nid[i, 0, 0], nid[i + 1, 0, 0], nid[i + 1, 1, 0], nid[i, 1, 0],
             nid[i, 0, 1], nid[i + 1, 0, 1], nid[i + 1, 1, 1], nid[i, 1, 1]]
        lines.append(f"{i + 1}, " + ", ".join(map(str, n)))
    lines += ["*NSET, NSET=FIX", ", ".join(str(nid[0, j, k]) for j in range(2) for k in range(2)),
              "*ELSET, ELSET=FIRST", "1", "*SURFACE, NAME=SFIX", "FIRST, S6",
              "*MATERIAL, NAME=STEEL", "*ELASTIC", "210000., 0.3", "*SOLID SECTION, ELSET=BAR, MATERIAL=STEEL"]
    if kind == "coupling":
        lines += ["*COUPLING, REF NODE=1000, SURFACE=SFIX, CONSTRAINT NAME=FIXC", "*KINEMATIC", "1, 3"]
        node, dofs = 1000, (4, 5, 6)
    else:
        lines += ["*RIGID BODY, NSET=FIX, REF NODE=1000, ROT NODE=1001"]
        node, dofs = 1001, (1, 2, 3)
    for theta in TURNS:
        lines += ["*STEP, NLGEOM", "*STATIC", "0.25, 1.0", "*BOUNDARY", "1000, 1, 3, 0.0"]
        lines += [f"{node}, {d}, {d}, {v!r}" for d, v in zip(dofs, theta)]
        lines += ["*NODE PRINT, NSET=NALL", "U", "*END STEP"]
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("kind", ["coupling", "rigid"])
def test_prescribed_rotation_vector_is_the_total_rotation(tmp_path, kind):
    """A *BOUNDARY on a reference node's rotation (the *KINEMATIC REF NODE's dofs 4-6, a *RIGID BODY's ROT NODE) is
    the body's total rotation vector, as CalculiX reads it (its nonlinear rigid-body MPC rotates by R(w) of the
    rotational node's displacement w, w going linearly over a step from the value before): the bar turned
    through its support to 1.57 e_z, then 1.209 (1, 1, 1), then 1.209 (-1, 1, 1) ends each step at
    x = X_ref + R(theta)(X - X_ref), R of the step's rotation vector by Rodrigues' formula (closed form): the
    coupled nodes to 1e-8 (they are there to round-off), the free ones to 1e-7 (an unloaded bar moves rigidly; found
    to Newton's tolerance, 1e-8), and the body's rotation vector is the deck's. (Composing the step's change of the vector onto the rotation reached, R(delta theta) R(theta_before),
    is the same only while the axis stays: the far end 3.5 off, the coupled nodes 0.60, in the second step.) CalculiX 2.20 on the same deck: every node's
    U within 5e-7 of the closed form in all three steps (its .dat's six digits)."""
    from covcontact.io.deck_import import import_deck
    from covcontact.io.loader import load_problem
    from covcontact.motion import rotation_matrix
    from covcontact.observer import Observer
    from covcontact.solvers.run import solve_problem

    class StageEnds(Observer):
        def __init__(self):
            self.u = {}

        def increment_converged(self, run, inc):
            if inc.ends_stage:
                self.u[inc.state.stage] = run.u.copy()

    deck = tmp_path / f"{kind}.inp"
    deck.write_text(turned_bar(kind))
    imp = import_deck(deck, tmp_path / kind / f"{kind}.toml")
    assert not imp.unsupported
    problem = load_problem(imp.problem)
    ends = StageEnds()
    res = solve_problem(problem, out=tmp_path / kind / "out", quiet=True, observers=[ends])
    assert res.exit_code == 0 and sorted(ends.u) == [0, 1, 2]
    X = problem.bodies[0].mesh.points          # the bar's nodes (labels 1..20 in order)
    fixed = np.abs(X[:, 0]) < 1e-12            # the coupled face x = 0 (X_ref = 0)
    assert fixed.sum() == 4
    last = {}
    for s in res.summary["steps"]:
        last[s["stage"]] = s
    for k, theta in enumerate(TURNS):
        want = X @ rotation_matrix(theta).T    # X_ref + R(theta)(X - X_ref), X_ref = 0
        x = X + ends.u[k].reshape(-1, 3)[: len(X)]
        np.testing.assert_allclose(x[fixed], want[fixed], rtol=0.0, atol=1e-8)   # (exact: 1e-16)
        np.testing.assert_allclose(x, want, rtol=0.0, atol=1e-7)                 # (Newton's tolerance: 1e-8)
        body = next(iter(last[list(last)[k]]["rigid_bodies"].values()))
        np.testing.assert_allclose(body["rotation"], theta, rtol=0.0, atol=1e-12)


def test_kinematic_coupling_on_planar_edges(tmp_path):
    """*COUPLING with *KINEMATIC 1-3 on the right edge (S2) of a CPS4 strip 4 x 1 (thickness 0.5, nu = 0), its REF NODE
    pulled by *CLOAD F along x: the coupling moves in the plane (z is the planar body's; the rotations about x and
    y are held), the strip stretches homogeneously, so the REF NODE moves by 4 (l - 1) with E/2 (l^3 - l) A = F,
    A = 0.5 (St. Venant-Kirchhoff, closed form; the .dat's seven digits); *SECTION PRINT on the planar edge is said
    in a note, *DISTRIBUTING on planar edges refused with one line."""
    from scipy.optimize import brentq

    from covcontact.cli import main

    nodes = "\n".join(f"{j * 5 + i + 1}, {float(i)}, {float(j)}, 0." for j in range(2) for i in range(5))
    els = "\n".join(f"{i + 1}, {i + 1}, {i + 2}, {i + 7}, {i + 6}" for i in range(4))
    F = 10.0
    deck = (f"*NODE\n{nodes}\n1000, 4., 0.5, 0.\n*ELEMENT, TYPE=CPS4, ELSET=EALL\n{els}\n"
            "*ELSET, ELSET=ERIGHT\n4\n*SURFACE, NAME=SR\nERIGHT, S2\n"
            "*MATERIAL, NAME=M\n*ELASTIC\n100., 0.\n*SOLID SECTION, ELSET=EALL, MATERIAL=M\n0.5\n"
            "*COUPLING, REF NODE=1000, SURFACE=SR, CONSTRAINT NAME=PULL\n*KINEMATIC\n1, 3\n"
            "*BOUNDARY\n1, 1, 2\n6, 1\n*NSET, NSET=REF\n1000\n"
            f"*STEP, NLGEOM\n*STATIC\n0.5, 1.\n*CLOAD\n1000, 1, {F}\n*NODE PRINT, NSET=REF\nU\n"
            "*SECTION PRINT, SURFACE=SR, NAME=S1\nSOF\n*END STEP\n")
    path = tmp_path / "strip.inp"
    path.write_text(deck)
    buf = io.StringIO()
    with contextlib.redirect_stderr(buf):
        assert main(["run", str(path), "--out", str(tmp_path / "o")]) == 0
    assert "*SECTION PRINT, SURFACE=SR: edges of planar elements (CPS4): not printed" in buf.getvalue()
    lam = brentq(lambda x: 50.0 * (x ** 3 - x) * 0.5 - F, 1.0, 2.0, xtol=1e-15)
    u = dat_blocks(tmp_path / "o" / "strip.dat")
    ref = u[[k for k in u if k[0] == "displacements"][-1]][1000]
    assert ref[0] == pytest.approx(4.0 * (lam - 1.0), rel=1e-6) and abs(ref[1]) < 1e-9
    path.write_text(deck.replace("*KINEMATIC\n1, 3", "*DISTRIBUTING\n1, 3"))
    code, err = _run(tmp_path, "dist", path.read_text())
    assert code == 2 and "*DISTRIBUTING on the edges of planar elements (CPS4) is not supported" in err
