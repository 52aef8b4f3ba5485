"""F-bar hex8 (covcontact.elements.fbar): exact tangent against central differences, patch test on a
distorted mesh, rigid rotations, volumetric locking against plain hex8 and hex27, material history
(committed read, trial written), chunking, inverted elements and argument checks.

Everything goes through the element API (``assemble`` with a Pattern), not through the Problem API.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
import scipy.sparse.linalg as sla

import covcontact.materials as materials
from covcontact.assembly import Pattern
from covcontact.elements.fbar import FbarBody
from covcontact.elements.solid import SolidBody
from covcontact.fem.quadrature import gauss_quad
from covcontact.fem.shapes import NODES, shape_functions
from covcontact.materials import NeoHooke, SaintVenantKirchhoff, stress_tangent
from covcontact.mesh.generators import block

MATERIALS = {"neo-hooke": NeoHooke, "svk": SaintVenantKirchhoff}
FORMS = ("spatial", "variational")


# ----------------------------------------------------------------------------- helpers


def two_elements(seed: int = 0, cell: str = "hex8") -> tuple[np.ndarray, np.ndarray]:
    """Two distorted hexahedra (hex8 or hex27, curved edges) sharing the face x = 1 (nodes merged)."""
    rng = np.random.default_rng(seed)
    ref = NODES[cell]
    X, inv = np.unique(np.round(np.vstack([ref, ref + [2.0, 0.0, 0.0]]), 12), axis=0, return_inverse=True)
    cells = inv.reshape(2, -1).astype(np.int64)
    X = 0.5 * X * [1.0, 0.8, 1.3] + 0.08 * rng.uniform(-1.0, 1.0, X.shape)
    return np.ascontiguousarray(X), cells


def distorted_block(seed: int = 0, amp: float = 0.25):
    """A 3 x 3 x 3 hex8 block of unit cells with its 8 interior nodes moved by up to ``amp`` in every
    direction (general, non-parallelepiped elements). Returns X, cells, interior node ids."""
    m = block(3.0, 3.0, 3.0, 3, 3, 3, "hex8")
    X = m.points.copy()
    interior = np.flatnonzero(np.all((X > 1e-9) & (X < 3.0 - 1e-9), axis=1))
    X[interior] += amp * np.random.default_rng(seed).uniform(-1.0, 1.0, (interior.size, 3))
    return X, m.cells, interior


def residual(body, u, state=None) -> np.ndarray:
    r = np.zeros(3 * body.n_nodes)
    assert body.assemble(u, np.zeros(0), r, None, want_K=False, state=state) == -1
    return r


def tangent(body, u, state=None) -> tuple[np.ndarray, np.ndarray]:
    P = Pattern(body.n_nodes, [body.cells])
    data = P.zeros()
    r = np.zeros(3 * body.n_nodes)
    assert body.assemble(u, data, r, P, state=state) == -1
    return P.csr(data).toarray(), r


def fd_tangent(body, u, h: float, state_of=lambda: None) -> np.ndarray:
    """Central differences of the residual, column by column; ``state_of()`` gives each evaluation its
    material state (a fresh trial from the same committed history)."""
    Kfd = np.empty((u.size, u.size))
    for j in range(u.size):
        up = u.ravel().copy()
        um = u.ravel().copy()
        up[j] += h
        um[j] -= h
        Kfd[:, j] = (residual(body, up, state_of()) - residual(body, um, state_of())) / (2.0 * h)
    return Kfd


def rotation(axis, angle: float) -> np.ndarray:
    a = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    W = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    return np.eye(3) + np.sin(angle) * W + (1.0 - np.cos(angle)) * W @ W


def face_loads(X: np.ndarray, faces: np.ndarray, face_type: str, traction) -> np.ndarray:
    """Consistent nodal forces (nnode, 3) of a uniform traction on reference faces (quad4 or quad9)."""
    pts, w = gauss_quad(3)
    N, dN, _ = shape_functions(face_type, pts)
    f = np.zeros((X.shape[0], 3))
    for face in faces:
        x = X[face]
        for g in range(w.size):
            dA = np.linalg.norm(np.cross(dN[g, :, 0] @ x, dN[g, :, 1] @ x)) * w[g]
            f[face] += np.outer(N[g], traction) * dA
    return f


def newton(body, u, free, f, atol: float, maxit: int = 20) -> np.ndarray:
    """Solve r(u) = f on the free dofs (u given on the others) to |r - f| <= atol; returns u (nnode, 3)."""
    u = np.array(u, dtype=float).ravel()
    P = Pattern(body.n_nodes, [body.cells])
    for _ in range(maxit):
        data = P.zeros()
        r = np.zeros(u.size)
        assert body.assemble(u, data, r, P) == -1
        R = (r - f)[free]
        if np.linalg.norm(R) <= atol:
            return u.reshape(-1, 3)
        K = P.csr(data)[free][:, free].tocsc()
        u[free] -= sla.spsolve(K, R)
    raise AssertionError(f"Newton did not converge: |R| = {np.linalg.norm(R):.3e} > {atol:.3e}")


# ----------------------------------------------------------------------------- tangent


@pytest.mark.parametrize("nu", [0.3, 0.4999])
@pytest.mark.parametrize("mat", list(MATERIALS))
@pytest.mark.parametrize("form", FORMS)
def test_tangent_matches_central_differences(form, mat, nu):
    X, cells = two_elements(seed=1)
    body = FbarBody("hex8", X, cells, MATERIALS[mat](E=200.0, nu=nu), form=form)
    assert body.check_reference() == []
    u = 0.12 * np.random.default_rng(2).uniform(-1.0, 1.0, X.shape)  # ~25% of the element size
    K, r = tangent(body, u)
    assert np.allclose(r, residual(body, u), rtol=0.0, atol=1e-14 * np.abs(r).max())
    h = 1e-6
    Kfd = np.empty_like(K)
    gfd = np.empty(K.shape[0])
    for j in range(K.shape[0]):
        up = u.ravel().copy()
        um = u.ravel().copy()
        up[j] += h
        um[j] -= h
        Kfd[:, j] = (residual(body, up) - residual(body, um)) / (2.0 * h)
        gfd[j] = (body.energy(up) - body.energy(um)) / (2.0 * h)
    scale = np.abs(K).max()
    assert np.abs(K - Kfd).max() <= 1e-6 * scale  # measured 2e-10 .. 7e-10
    asym = np.abs(K - K.T).max() / scale
    if form == "variational":
        # the residual is the gradient of int W(F_bar) dV and the tangent its (symmetric) Hessian
        assert asym <= 1e-12
        assert np.abs(r - gfd).max() <= 1e-6 * np.abs(r).max()
    else:
        assert asym > 1e-3  # the paper's weak form: no potential, non-symmetric tangent


# ----------------------------------------------------------------------------- patch test


F_HOM = np.array([[1.10, 0.20, -0.10], [0.05, 0.95, 0.15], [-0.10, 0.10, 1.05]])


@pytest.mark.parametrize("mat,nu", [("neo-hooke", 0.4999), ("neo-hooke", 0.3), ("svk", 0.3)])
def test_patch_homogeneous_deformation(mat, nu):
    X, cells, interior = distorted_block(seed=3)
    material = MATERIALS[mat](E=200.0, nu=nu)
    body = FbarBody("hex8", X, cells, material)
    u_exact = X @ F_HOM.T - X
    # F_bar = F for a homogeneous deformation: the exact stress in every element
    S, _, status = stress_tangent(material, F_HOM)
    assert status == 0
    J = np.linalg.det(F_HOM)
    sig = F_HOM @ S[materials.VOIGT] @ F_HOM.T / J
    C = F_HOM.T @ F_HOM
    pairs = [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (0, 2)]
    st = body.stress(u_exact)
    scale = np.abs(S).max()
    assert np.abs(st.pk2 - S).max() <= 1e-12 * scale
    assert np.abs(st.cauchy - [sig[i, j] for i, j in pairs]).max() <= 1e-12 * scale
    assert np.abs(st.green_lagrange - [0.5 * (C[i, j] - (i == j)) for i, j in pairs]).max() <= 1e-14
    # equilibrium: no out-of-balance force at the interior nodes
    r = residual(body, u_exact).reshape(-1, 3)
    fscale = np.abs(r).max()
    assert np.abs(r[interior]).max() <= 1e-12 * fscale
    # the patch test proper: boundary nodes prescribed, interior nodes solved for (Newton from a
    # perturbed start) give the homogeneous field
    free = (np.arange(3 * body.n_nodes).reshape(-1, 3)[interior]).ravel()
    u0 = u_exact.copy()
    u0[interior] += 0.02 * np.random.default_rng(4).uniform(-1.0, 1.0, (interior.size, 3))
    u = newton(body, u0, free, np.zeros(3 * body.n_nodes), atol=1e-12 * fscale)
    assert np.abs(u - u_exact).max() <= 1e-10


def test_variational_form_patch_test_needs_parallelepipeds():
    """The variational form balances a homogeneous state only where int G_a dV = V G_a(centre), e.g. on
    parallelepipeds; on general hexahedra the centre-point volume leaves interior forces (docs/theory.md)."""
    material = NeoHooke(E=200.0, nu=0.4999)
    m = block(3.0, 3.0, 3.0, 3, 3, 3, "hex8")
    interior = np.flatnonzero(np.all((m.points > 1e-9) & (m.points < 3.0 - 1e-9), axis=1))
    A = np.array([[1.0, 0.3, -0.2], [0.1, 0.9, 0.25], [-0.15, 0.2, 1.1]])  # sheared parallelepipeds
    X = m.points @ A.T
    body = FbarBody("hex8", X, m.cells, material, form="variational")
    r = residual(body, X @ F_HOM.T - X).reshape(-1, 3)
    assert np.abs(r[interior]).max() <= 1e-12 * np.abs(r).max()
    X, cells, interior = distorted_block(seed=3)
    r = residual(FbarBody("hex8", X, cells, material, form="variational"), X @ F_HOM.T - X).reshape(-1, 3)
    assert np.abs(r[interior]).max() > 1e-4 * np.abs(r).max()  # measured 1e-2


# ----------------------------------------------------------------------------- rigid motion


@pytest.mark.parametrize("form", FORMS)
def test_rigid_rotation_is_stress_free(form):
    X, cells = two_elements(seed=5)
    mat = NeoHooke(E=200.0, nu=0.4999)
    body = FbarBody("hex8", X, cells, mat, form=form)
    scale = (mat.lam + 2.0 * mat.mu) * 0.5**2  # stiffest modulus times a face area (round-off ~ eps lambda)
    R = rotation([1.0, 2.0, -0.5], 1.1)  # 63 degrees
    t = np.array([0.3, -1.2, 2.0])
    u = X @ R.T - X + t
    assert np.abs(residual(body, u)).max() <= 1e-12 * scale
    assert abs(body.energy(u)) <= 1e-13 * scale  # Neo-Hooke: mu (I_C - 3) / 2 - mu ln J, round-off eps mu
    st = body.stress(u)
    assert np.abs(st.cauchy).max() <= 1e-12 * scale and np.abs(st.pk2).max() <= 1e-12 * scale
    # objectivity of the tangent: rotated body, rotated initial stiffness
    K0 = tangent(body, np.zeros_like(X))[0]
    Rb = np.kron(np.eye(body.n_nodes), R)
    assert np.abs(tangent(body, u)[0] - Rb @ K0 @ Rb.T).max() <= 1e-10 * np.abs(K0).max()


# ----------------------------------------------------------------------------- locking

BEAM = dict(L=10.0, H=2.0, W=2.0, E=1000.0, nu=0.4999, load=2.0)
BEAM_MESH = (20, 4, 4)


@cache
def beam_tip(kind: str, form: str = "spatial") -> float:
    """Vertical tip deflection of a clamped Neo-Hooke cantilever (10 x 2 x 2, nu = 0.4999) under a total
    end shear of 2 (about 5% of the length: moderately nonlinear), one load step solved by Newton."""
    cell = "hex27" if kind == "hex27" else "hex8"
    m = block(BEAM["L"], BEAM["H"], BEAM["W"], *BEAM_MESH, cell)
    mat = NeoHooke(E=BEAM["E"], nu=BEAM["nu"])
    body = (FbarBody("hex8", m.points, m.cells, mat, form=form) if kind == "fbar"
            else SolidBody(cell, m.points, m.cells, mat))
    traction = [0.0, BEAM["load"] / (BEAM["H"] * BEAM["W"]), 0.0]
    f = face_loads(m.points, m.face_set("xmax"), m.face_type, traction)
    assert abs(f[:, 1].sum() - BEAM["load"]) <= 1e-12
    fixed = np.zeros((body.n_nodes, 3), dtype=bool)
    fixed[m.node_set("xmin")] = True
    u = newton(body, np.zeros_like(m.points), np.flatnonzero(~fixed.ravel()), f.ravel(),
               atol=1e-7 * np.linalg.norm(f))
    return float(u[m.node_set("xmax"), 1].mean())


@pytest.mark.parametrize("form", FORMS)
def test_fbar_removes_volumetric_locking(form):
    ref = beam_tip("hex27")  # 20 x 4 x 4 hex27, measured 0.4836
    plain = beam_tip("hex8")  # measured 0.1132 (23% of the reference)
    fbar = beam_tip("fbar", form)  # measured 0.4865 (+0.6%), both forms
    assert plain < 0.3 * ref
    assert abs(fbar / ref - 1.0) < 0.03


# ----------------------------------------------------------------------------- history


def _j2():
    J2 = getattr(materials, "J2Plasticity", None)
    hard = getattr(materials, "LinearHardening", None)
    if J2 is None or hard is None:
        pytest.skip("no J2 plasticity material")
    return J2(E=200.0, nu=0.3, yield_stress=0.5, hardening=hard(modulus=20.0))


@pytest.mark.parametrize("form", FORMS)
def test_history_committed_read_and_trial_written(form):
    mat = _j2()
    X, cells = two_elements(seed=1)
    body = FbarBody("hex8", X, cells, mat, form=form)
    st0 = body.new_state()
    assert set(st0) == {"hist"} and st0["hist"].shape == (2, 8, mat.n_hist)
    rng = np.random.default_rng(2)
    u1 = 0.04 * rng.uniform(-1.0, 1.0, X.shape)
    u2 = u1 + 0.03 * rng.uniform(-1.0, 1.0, X.shape)
    # step 1, committed: plastic flow changed the history
    ks = body.kernel_state(st0, st0)
    residual(body, u1, ks)
    assert np.array_equal(ks["hist_n"], st0["hist"])
    committed = body.trial_of(ks)
    assert not np.array_equal(committed["hist"], st0["hist"])
    # a trial from the committed state: hist_n read only, the same result every time, and the same as
    # with ``hist`` alone (a fresh copy of the committed history as both start and trial)
    h0 = committed["hist"].copy()
    ks2 = body.kernel_state(committed, committed)
    K, r = tangent(body, u2, ks2)
    assert np.array_equal(ks2["hist_n"], h0) and np.array_equal(committed["hist"], h0)
    ks3 = body.kernel_state(committed, committed)
    assert np.array_equal(tangent(body, u2, ks3)[1], r) and np.array_equal(ks3["hist"], ks2["hist"])
    only = {"hist": h0.copy()}
    assert np.array_equal(residual(body, u2, only), r) and np.array_equal(only["hist"], ks2["hist"])
    # the tangent is the exact derivative of the residual at fixed committed history (plastic points)
    Kfd = fd_tangent(body, u2, 1e-7, lambda: body.kernel_state(committed, committed))
    assert np.abs(K - Kfd).max() <= 1e-6 * np.abs(K).max()  # measured 4e-9


def test_hyperelastic_state_is_empty_history():
    X, cells = two_elements()
    st = FbarBody("hex8", X, cells, NeoHooke(E=1.0, nu=0.3)).new_state()
    assert set(st) == {"hist"} and st["hist"].shape == (2, 8, 0)


# ----------------------------------------------------------------------------- plumbing


def test_chunks_give_identical_results():
    X, cells, _ = distorted_block(seed=6)
    u = 0.05 * np.random.default_rng(7).uniform(-1.0, 1.0, X.shape)
    mat = NeoHooke(E=200.0, nu=0.45)
    one = FbarBody("hex8", X, cells, mat)
    many = FbarBody("hex8", X, cells, mat, chunk_bytes=5 * 8 * 24 * 24)  # chunks of 5 elements
    assert one.chunk == 27 and many.chunk == 5
    K1, r1 = tangent(one, u)
    K2, r2 = tangent(many, u)
    assert np.array_equal(K1, K2) and np.array_equal(r1, r2)


@pytest.mark.parametrize("mat", list(MATERIALS))
def test_inverted_element_is_reported_and_outputs_stay_finite(mat):
    X, cells = two_elements(seed=4)
    body = FbarBody("hex8", X, cells, MATERIALS[mat](E=200.0, nu=0.3))
    u = np.zeros_like(X)
    u[np.setdiff1d(cells[1], cells[0]), 0] = -1.5  # far face of element 1 pushed through: det F < 0
    P = Pattern(body.n_nodes, [cells])
    data = P.zeros()
    r = np.zeros(3 * body.n_nodes)
    assert body.assemble(u, data, r, P) == 1
    assert np.isfinite(data).all() and np.isfinite(r).all()
    assert np.isfinite(body.stress(u).cauchy).all()


def test_reference_checks_and_arguments():
    X, cells = two_elements(seed=5)
    mat = SaintVenantKirchhoff(E=200.0, nu=0.3)
    bad = cells.copy()
    bad[1] = bad[1][[4, 5, 6, 7, 0, 1, 2, 3]]  # top and bottom swapped: det J0 < 0
    assert FbarBody("hex8", X, bad, mat).check_reference() == [1]
    body = FbarBody("hex8", X, cells, mat)
    assert body.form == "spatial" and not body.symmetric_tangent
    assert FbarBody("hex8", X, cells, mat, form="variational").symmetric_tangent
    with pytest.raises(ValueError, match="F-bar elements are hex8, hex27, hex20, tet10"):
        FbarBody("hex18", X, cells, mat)
    X27, cells27 = two_elements(seed=5, cell="hex27")
    with pytest.raises(ValueError, match="spatial form only"):
        FbarBody("hex27", X27, cells27, mat, form="variational")
    with pytest.raises(ValueError, match="form"):
        FbarBody("hex8", X, cells, mat, form="mixed")
    with pytest.raises(ValueError, match="cells"):
        FbarBody("hex8", X, cells[:, :4], mat)


# ----------------------------------------------------------------------------- hex27


@pytest.mark.parametrize("mat", ["neo-hooke", "j2"])
def test_hex27_tangent_matches_central_differences(mat):
    """F-bar hex27 (3 x 3 x 3 Gauss points, J projected onto the element's linear functions), exact tangent;
    J2 loaded into the plastic range."""
    X, cells = two_elements(seed=1, cell="hex27")
    material = NeoHooke(E=200.0, nu=0.4999) if mat == "neo-hooke" else _j2()
    body = FbarBody("hex27", X, cells, material)
    assert body.check_reference() == [] and body.weights.size == 27
    u = 0.08 * np.random.default_rng(2).uniform(-1.0, 1.0, X.shape)
    state = body.new_state()
    trial = {"hist_n": state["hist"], "hist": state["hist"].copy()}
    K, r = tangent(body, u, state=trial)
    if mat == "j2":
        assert trial["hist"].any()  # yielded
    Kfd = fd_tangent(body, u, 1e-6, lambda: {"hist_n": state["hist"], "hist": state["hist"].copy()})
    assert np.abs(K - Kfd).max() <= 1e-6 * np.abs(K).max()
    assert not state["hist"].any()  # evaluating never changes the committed history


def test_hex27_patch_homogeneous_deformation():
    """A homogeneous deformation of a block of distorted hex27 (moved interior and mid-side nodes) is
    reproduced exactly: exact stresses and no out-of-balance force at interior nodes."""
    m = block(2.0, 2.0, 2.0, 2, 2, 2, "hex27")
    X = m.points.copy()
    interior = np.flatnonzero(np.all((X > 1e-9) & (X < 2.0 - 1e-9), axis=1))
    X[interior] += 0.1 * np.random.default_rng(3).uniform(-1.0, 1.0, (interior.size, 3))
    material = NeoHooke(E=200.0, nu=0.4999)
    body = FbarBody("hex27", X, m.cells, material)
    u = X @ F_HOM.T - X
    S, _, _ = stress_tangent(material, F_HOM)
    assert np.abs(body.stress(u).pk2 - S).max() <= 1e-11 * np.abs(S).max()
    r = residual(body, u).reshape(-1, 3)
    assert np.abs(r[interior]).max() <= 1e-11 * np.abs(r).max()


@cache
def hex27_beam_tip(kind: str, n: int) -> float:
    """Tip deflection of the cantilever of beam_tip on an n x n/4 x n/4 hex27 mesh, plain or F-bar, in five
    load increments."""
    m = block(BEAM["L"], BEAM["H"], BEAM["W"], n, max(1, n // 4), max(1, n // 4), "hex27")
    mat = NeoHooke(E=BEAM["E"], nu=BEAM["nu"])
    body = FbarBody("hex27", m.points, m.cells, mat) if kind == "fbar" else SolidBody("hex27", m.points, m.cells,
                                                                                         mat)
    traction = [0.0, BEAM["load"] / (BEAM["H"] * BEAM["W"]), 0.0]
    f = face_loads(m.points, m.face_set("xmax"), m.face_type, traction).ravel()
    fixed = np.zeros((body.n_nodes, 3), dtype=bool)
    fixed[m.node_set("xmin")] = True
    free = np.flatnonzero(~fixed.ravel())
    u = np.zeros_like(m.points)
    for lam in (0.2, 0.4, 0.6, 0.8, 1.0):
        u = newton(body, u, free, lam * f, atol=1e-6 * np.linalg.norm(f))
    return float(u[m.node_set("xmax"), 1].mean())


def test_hex27_fbar_removes_volumetric_locking():
    """nu = 0.4999: plain hex27 locks on coarse meshes (0.82 of the reference on 4 x 1 x 1, 0.94 on 8 x 2 x 2);
    F-bar hex27 does not lock (it is slightly too flexible on the coarsest mesh, as mixed elements are) and
    converges to the reference of the fine plain hex27 and F-bar hex8 meshes (0.4836, 0.4865)."""
    ref = beam_tip("hex27")
    out = {n: (hex27_beam_tip("plain", n), hex27_beam_tip("fbar", n)) for n in (4, 8)}
    print({n: (round(p / ref, 4), round(f / ref, 4)) for n, (p, f) in out.items()})
    for n, (plain, fbar) in out.items():
        assert abs(fbar / ref - 1.0) < abs(plain / ref - 1.0)
    assert abs(out[8][1] / ref - 1.0) < 0.03
