"""Stress resultants of solid-shells and their mid-surface in the VTU output (SolidShellBody.shell_resultants,
io.observers.shell_mid_surfaces; docs/input.md, "Output"): a cantilever strip under a tip force and under a tip
tension, against beam statics (closed forms: M(x) = -P (L - x) / b, Q = P / b, N = F / b, the faces' stresses
-+ 6 M / t^2 and N / t)."""

from __future__ import annotations

import numpy as np
import pytest

from covcontact.io.loader import load_problem

L, B, T, E = 10.0, 1.0, 0.1, 1.0e5

STRIP = """
[problem]
name = "strip"
[[bodies]]
name = "p"
mesh = {{ generator = "plate", lx = 10.0, ly = 1.0, t = 0.1, nx = 20, ny = 2, origin = [0.0, 0.0, -0.05] }}
element = "{cell}"
formulation = "solid-shell"
material = {{ model = "svk", E = 1.0e5, nu = 0.0 }}
[[dirichlet]]
set = "p.xmin"
components = "xyz"
value = 0.0
[[force]]
set = "p.xmax"
value = {load}
distribution = "total"
[steps]
count = 1
[output]
vtu = true
pictures = false
"""


def _mid_surface(tmp_path, cell: str, load: str):
    """The converged strip's mid-surface block of the last VTU: (centres (ne, 3), cell data)."""
    import meshio

    path = tmp_path / f"{cell}.toml"
    path.write_text(STRIP.format(cell=cell, load=load))
    res = load_problem(path).run(out=tmp_path / cell, quiet=True)
    assert res.exit_code == 0
    mesh = meshio.read(tmp_path / cell / "step_0001.vtu")
    (k,) = [k for k, blk in enumerate(mesh.cells) if blk.type.startswith("quad")]
    x = mesh.points + mesh.point_data["displacement"]
    centres = x[mesh.cells[k].data].mean(axis=1)
    return centres, {key: np.asarray(v[k]) for key, v in mesh.cell_data.items()}


@pytest.mark.parametrize("cell", ["hex8", "hex18"])
def test_bending_resultants_of_a_cantilever(tmp_path, cell):
    """Tip force P = 1e-3 along z on a strip clamped at x = 0 (deflection 0.4 % of the length): at every element
    the moment M11 = -P (L - x) / b (x the deformed centre; the top is compressed) to 1e-4 of the root moment,
    Q1 = P / b to 1e-4, N11 below 2 % of P / b (the rotated tip force's share), the face stresses -+ 6 M11 / t^2
    to 1e-3 of the root's; the thickness t, e1 along x. Measured: M11 to 1e-5 (hex8)."""
    P = 1e-3
    c, d = _mid_surface(tmp_path, cell, f"[0.0, 0.0, {P}]")
    root = P * L / B
    M, Q, N = d["bending_moment"], d["transverse_shear_force"], d["membrane_force"]
    np.testing.assert_allclose(M[:, 0], -P * (L - c[:, 0]) / B, atol=1e-4 * root)
    np.testing.assert_allclose(Q[:, 0], P / B, rtol=1e-4)
    assert np.abs(N[:, 0]).max() < 0.02 * P / B
    np.testing.assert_allclose(d["stress_top"][:, 0], 6.0 * M[:, 0] / T**2, atol=1e-3 * 6.0 * root / T**2)
    np.testing.assert_allclose(d["stress_bottom"][:, 0], -6.0 * M[:, 0] / T**2, atol=1e-3 * 6.0 * root / T**2)
    np.testing.assert_allclose(d["shell_thickness"], T, rtol=1e-3)
    assert np.all(d["shell_frame_e1"][:, 0] > 0.999)


def test_membrane_resultants_of_a_strip_in_tension(tmp_path):
    """Tip tension F = 50 along x (strain 5e-3): N11 = F / b to 1e-3 (the Cauchy stress per deformed width:
    Poisson's ratio 0, so the width stays), no moment (below 1e-6 F t / b), both faces at N / t."""
    F = 50.0
    c, d = _mid_surface(tmp_path, "hex8", f"[{F}, 0.0, 0.0]")
    far = np.abs(c[:, 0] - L / 2) < L / 4                 # (away from the clamp's and the tip's ends)
    N, M = d["membrane_force"][far], d["bending_moment"][far]
    np.testing.assert_allclose(N[:, 0], F / B, rtol=1e-3)
    assert np.abs(M).max() < 1e-6 * F * T / B
    np.testing.assert_allclose(d["stress_top"][far, 0], F / (B * T), rtol=1e-3)
    np.testing.assert_allclose(d["stress_bottom"][far, 0], F / (B * T), rtol=1e-3)
