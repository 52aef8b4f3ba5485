"""Self-contact in the plane (``self = [...]`` edge sets of planar bodies; docs/theory.md sections 13 and 28): a
surface made of two bodies' edge sets is the two-pass pair between them (node-to-segment and segment-to-segment,
plane strain and axisymmetric); the tangent against central differences; a ring crushed flat between rigid lines
until its inner walls meet and flatten against each other, whole with self-contact and as its upper half against a
rigid symmetry line (no closed form: the reference is symmetry); one-line refusals."""

from __future__ import annotations

import numpy as np
import pytest

from covcontact.io.loader import load_problem
from covcontact.io.validate import InputError
from covcontact.tangent_check import check_tangent

from planar_blocks import two_blocks


def blocks(form: str, contact: str, upper: str = "lx = 1.0, ly = 0.5, nx = 3", ox_up: float = 0.0) -> str:
    return two_blocks(form, contact, cell="quad8", material='model = "neo-hooke", E = 1000.0, nu = 0.3', upper=upper,
                      ox_up=ox_up, load='[[pressure]]\nset = "up.ymax"\nvalue = 2.0\n', steps=3, name="self")


SELF = '[[contact]]\nname = "c"\nself = ["low.ymax", "up.ymin"]\npenalty = 1e5\nweighting = "area"\n'
PAIR = ('[[contact]]\nname = "c"\nslave = "up.ymin"\nmaster = "low.ymax"\ntwo_pass = true\npenalty = 1e5\n'
        'weighting = "area"\n')


@pytest.mark.parametrize("form", ["plane_strain", "axisymmetric"])
@pytest.mark.parametrize("kind", ["nts", "sts"])
def test_merged_surface_is_the_two_pass_pair(tmp_path, form, kind):
    """Two blocks of quad8 with non-matching edges (3 and 4 cells) pressed together: one self-contact surface made of
    both facing edge sets gives the displacements of the two-pass pair between them to 1e-10 of the largest, in the
    same Newton iterations (every slave of the merged surface faces only the other block's edges: its own are
    excluded or face the same way)."""
    extra = 'type = "sts"\n' if kind == "sts" else ""
    runs = []
    for name, contact in (("self", SELF), ("pair", PAIR)):
        path = tmp_path / f"{name}.toml"
        path.write_text(blocks(form, contact + extra))
        res = load_problem(path).run(out=tmp_path / name, quiet=True)
        assert res.exit_code == 0
        runs.append(res)
    u_self, u_pair = (np.asarray(r.u) for r in runs)
    n = len(u_pair)
    assert np.abs(u_self[:n] - u_pair).max() <= 1e-10 * np.abs(u_pair).max()
    assert [s["iterations"] for s in runs[0].summary["steps"]] == [s["iterations"] for s in runs[1].summary["steps"]]


@pytest.mark.parametrize("kind", ["nts", "sts"])
def test_tangent_against_differences(tmp_path, kind):
    """The merged surface of shifted blocks (the upper 0.9 wide, moved by 0.05: no slave on a vertex), at the
    converged first step: the Newton tangent against central differences of the residual, every column, within
    1e-6."""
    path = tmp_path / "fd.toml"
    path.write_text(blocks("plane_strain", SELF + ('type = "sts"\n' if kind == "sts" else ""),
                           "lx = 0.9, ly = 0.5, nx = 3", 0.05))
    rep = check_tangent(load_problem(path), step=1, columns=None)
    assert rep["converged"] and rep["relative_error"] <= 1e-6, rep["relative_error"]


RING = """
[problem]
name = "ring"
[[bodies]]
name = "tube"
formulation = "plane_strain"
element = "quad8"
material = { model = "neo-hooke", E = 1000.0, nu = 0.3 }
mesh = { generator = "annulus", r_inner = 0.95, r_outer = 1.05, nr = 1, nt = NT, angle = ANGLE }
SETS
[[rigid]]
name = "upper"
shape = "plane"
point = [0.0, 1.05, 0.0]
normal = [0.0, -1.0, 0.0]
motion = { translation = [0.0, -0.975, 0.0] }
[[contact]]
name = "top"
slave = "tube.outer"
master = "upper"
penalty = 1.0e5
weighting = "area"
[[dirichlet]]
set = "tube.top"
components = "x"
INNER
[steps]
initial = 0.02
min = 1e-4
max = 0.02
output_at = [0.5, 0.9, 0.95, 0.96, 0.97, 0.98, 0.99, 1.0]
[output]
vtu = false
pictures = false
"""
WHOLE = """
[[rigid]]
name = "lower"
shape = "plane"
point = [0.0, -1.05, 0.0]
normal = [0.0, 1.0, 0.0]
motion = { translation = [0.0, 0.975, 0.0] }
[[contact]]
name = "bottom"
slave = "tube.outer"
master = "lower"
penalty = 1.0e5
weighting = "area"
[[contact]]
name = "inner"
self = "tube.inner"
penalty = 1.0e5
weighting = "area"
smoothing = 1.0e-3
[[dirichlet]]
set = "tube.bottom"
components = "x"
"""
HALF = """
[[rigid]]
name = "mid"
shape = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]
[[contact]]
name = "inner"
slave = "tube.inner"
master = "mid"
penalty = 4.0e5
weighting = "area"
smoothing = 0.5e-3
[[dirichlet]]
set = "tube.angle0"
components = "y"
[[dirichlet]]
set = "tube.angle1"
components = "y"
"""


def test_crushed_ring_whole_against_half(tmp_path):
    """A ring (radius 1, wall 0.1, Neo-Hooke, plane strain, 32 quad8 round) crushed by two rigid lines moving 0.975
    each until its inner walls meet and flatten: whole with its inner edge set in self-contact (penalty 1e5 per area,
    smoothing 1e-3), and as its upper half with the inner edges against a rigid line on the symmetry axis (4 times
    the penalty, half the band: the whole model's walls press on each other from both sides, each node slave and
    master). The plate force agrees at every output load factor to 1e-5 relative (measured 1e-8); the walls
    touch near 0.97 (the force rises tenfold from 0.95 to the end, self-contact slaves active) and overlap by less than 5 % of the wall."""
    forces, active = {}, {}
    top = "top = { box = [[-1e-6, 0.0, -1.0], [1e-6, 2.0, 1.0]] }"
    bottom = "bottom = { box = [[-1e-6, -2.0, -1.0], [1e-6, 0.0, 1.0]] }"
    for name, text in (("whole", RING.replace("NT", "32").replace("ANGLE", "360.0").replace("INNER", WHOLE)
                        .replace("SETS", f"sets = {{ {top}, {bottom} }}")),
                       ("half", RING.replace("NT", "16").replace("ANGLE", "180.0").replace("INNER", HALF)
                        .replace("SETS", f"sets = {{ {top} }}"))):
        path = tmp_path / f"{name}.toml"
        path.write_text(text)
        res = load_problem(path).run(out=tmp_path / name, quiet=True)
        assert res.exit_code == 0, name
        forces[name] = {round(s["load_factor"], 9): s["contact_force_on"]["upper"][1] for s in res.summary["steps"]}
        k = [p.name for p in res.model.contact.passes].index("inner")
        st = res.state.contact.passes[k]
        active[name] = int(np.sum(np.isfinite(st.gap) & (np.linalg.norm(st.force, axis=1) > 0.0)))
        overlap = -np.min(st.gap[np.isfinite(st.gap)]) * (1.0 if name == "whole" else 2.0)
        assert 0.0 < overlap < 0.05 * 0.1
    shared = sorted(set(forces["whole"]) & set(forces["half"]))
    assert {0.5, 0.9, 0.95, 0.97, 0.99, 1.0} <= set(shared)
    for lam in shared:
        assert forces["whole"][lam] == pytest.approx(forces["half"][lam], rel=1e-5), lam
    assert forces["whole"][1.0] > 10.0 * forces["whole"][0.95]
    assert active["whole"] >= 2 * 10 and active["half"] >= 10


def test_refusals(tmp_path):
    """One line naming the pair: a self-contact surface of planar bodies of two formulations."""
    text = blocks("plane_strain", SELF).replace('formulation = "plane_strain"', 'formulation = "plane_stress"', 1)
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(InputError) as err:
        load_problem(path)
    assert "planar bodies of one formulation (found plane_strain, plane_stress)" in str(err.value)
    assert "\n" not in str(err.value)
