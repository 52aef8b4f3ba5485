"""Segment-to-segment contact in the plane (``type = "sts"`` on planar pairs; docs/theory.md section 28): the Gauss
points of the slave edges are the slaves (virtual points), each with its measure w J t or w J 2 pi R. Closed forms:
a pressed interface's overclosure P / K at every point and the forces summing to the load (plane strain and
axisymmetric, linear and quadratic edges), a block sliding under Coulomb friction (the tangential force mu times the
normal one); the tangent against central differences, frictionless and frictional."""

from __future__ import annotations

import math

import numpy as np
import pytest

from covcontact.io.loader import load_problem
from covcontact.tangent_check import check_tangent

from planar_blocks import two_blocks

K = 1e5
Q = 1.0


def blocks(form: str, cell: str, upper: str = "lx = 1.0, ly = 0.5, nx = 4", ox_up: float = 0.0, extra: str = "",
           load: str | None = None, steps: int = 4) -> str:
    contact = f'[[contact]]\nname = "c"\nslave = "up.ymin"\nmaster = "low.ymax"\ntype = "sts"\npenalty = {K}\n' + extra
    return two_blocks(form, contact, cell=cell, upper=upper, ox_up=ox_up, steps=steps, name="sts", hold=load is None,
                      load=f'[[pressure]]\nset = "up.ymax"\nvalue = {Q}\n' if load is None else load)


@pytest.mark.parametrize("form", ["plane_strain", "axisymmetric"])
@pytest.mark.parametrize("cell", ["quad4", "quad8"])
def test_pressed_interface(tmp_path, form, cell):
    """Matching blocks, the upper pressed by Q: every slave point's overclosure is Q / K (1e-9 relative: the points'
    measures integrate a uniform pressure exactly, over the thickness or the circumference), the points are the
    Gauss points of the slave edges (2 per linear edge, 3 per quadratic one), and the contact forces sum to the load
    Q times the area (1e-9)."""
    path = tmp_path / "p.toml"
    path.write_text(blocks(form, cell))
    res = load_problem(path).run(out=tmp_path / "o", quiet=True)
    assert res.exit_code == 0
    p, st = res.model.contact.passes[0], res.state.contact.passes[0]
    assert p.kind == "sts" and len(p.slaves) == 4 * (2 if cell == "quad4" else 3)
    np.testing.assert_allclose(-st.gap, Q / K, rtol=1e-9)
    area = math.pi * (2.0 ** 2 - 1.0 ** 2) if form == "axisymmetric" else 1.0
    assert p.area.sum() == pytest.approx(area, rel=1e-12)
    assert np.abs(st.force[:, 1]).sum() == pytest.approx(Q * area, rel=1e-9)


@pytest.mark.parametrize("cell", ["quad4", "quad8"])
@pytest.mark.parametrize("friction", [0.0, 0.3])
def test_tangent_against_differences(tmp_path, cell, friction):
    """Non-matching blocks (the upper 0.9 wide in 3 cells, shifted by 0.05), pressed and, with friction, pushed
    sideways by a third of the friction limit (sticking): the Newton tangent at the converged first step against
    central differences of the residual, every column, within 1e-6."""
    load = None
    extra = ""
    if friction:
        extra = f"friction = {friction}\n"
        load = (f'[[pressure]]\nset = "up.ymax"\nvalue = {Q}\n'
                f'[[force]]\nset = "up.xmax"\nvalue = [{0.1 * friction * Q * 0.9 / 3:.12g}, 0.0, 0.0]\n'
                f'[[dirichlet]]\nset = "low.xmin"\ncomponents = "x"\nvalue = 0.0\n')
    path = tmp_path / "fd.toml"
    path.write_text(blocks("plane_strain", cell, "lx = 0.9, ly = 0.5, nx = 3", 0.05, extra, load))
    rep = check_tangent(load_problem(path), step=1, columns=None)
    assert rep["converged"] and rep["relative_error"] <= 1e-6, rep["relative_error"]


def test_sliding_block_carries_mu_times_the_normal_force(tmp_path):
    """The upper block pressed by Q and its side moved by 0.02 along x (the lower block held; every slave point stays
    over the master edges): it slides, and at every slave point the contact force's component along the deformed
    master edge is mu times its normal one (Coulomb, closed form) to 1e-6; the normal forces sum to the load (1e-3:
    the deformed master edges tilt a little)."""
    from covcontact.contact.planar_kernels import segment_shapes

    mu = 0.3
    load = (f'[[pressure]]\nset = "up.ymax"\nvalue = {Q}\n'
            '[[dirichlet]]\nset = "up.xmin"\ncomponents = "x"\nvalue = 0.02\n'
            '[[dirichlet]]\nset = "low.xmin"\ncomponents = "x"\nvalue = 0.0\n')
    path = tmp_path / "slide.toml"
    path.write_text(blocks("plane_strain", "quad4", extra=f"friction = {mu}\n", load=load, steps=5))
    res = load_problem(path).run(out=tmp_path / "o", quiet=True)
    assert res.exit_code == 0
    p, st = res.model.contact.passes[0], res.state.contact.passes[0]
    x = res.model.system.X + res.u.reshape(-1, 3)
    N, dN, ddN = np.empty(3), np.empty(3), np.empty(3)
    ratios, normal = [], 0.0
    for f, seg, xi in zip(st.force, st.facet, st.xi[:, 0]):
        segment_shapes(2, float(xi), N, dN, ddN)
        t = dN[:2] @ x[p.curve.segments[seg]]
        t /= np.linalg.norm(t)
        n = np.array([-t[1], t[0], 0.0])
        ratios.append(abs(f @ t) / abs(f @ n))
        normal += abs(f @ n)
    np.testing.assert_allclose(ratios, mu, rtol=1e-6)
    assert normal == pytest.approx(Q * 1.0, rel=1e-3)
