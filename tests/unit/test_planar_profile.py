"""Profile tools as rigid masters in the plane (``shape = "profile"``: extruded along z in plane strain and plane
stress, revolved about the y axis in an axisymmetric model; docs/input.md, "Contact pairs on planar bodies"): a flat
profile is the rigid line, a fillet the rigid circle of its radius (to round-off, the same problem two ways); the
tangent against central differences on the fillet; refusals of profiles out of the plane."""

from __future__ import annotations

import math

import numpy as np
import pytest

from covcontact.io.loader import load_problem
from covcontact.io.validate import InputError
from covcontact.tangent_check import check_tangent


def block(form: str, master: str, origin=(-0.2, 0.0), drop: float = 0.02) -> str:
    """A small block (0.4 x 0.2, 4 x 2 quad8) of ``form`` whose bottom edge is the slave of ``master``, pushed down by
    ``drop`` through its top edge (held along x in the plane cases)."""
    hold = '' if form == "axisymmetric" else 'components = "xy"\nvalue = [0.0, %r]\n' % -drop
    top = ('[[dirichlet]]\nset = "b.ymax"\n' + (hold or f'components = "y"\nvalue = {-drop!r}\n'))
    return f"""
[problem]
name = "profile"
[[bodies]]
name = "b"
formulation = "{form}"
element = "quad8"
mesh = {{ generator = "rectangle", lx = 0.4, ly = 0.2, nx = 4, ny = 2, origin = [{origin[0]}, {origin[1]}] }}
material = {{ model = "neo-hooke", E = 100.0, nu = 0.3 }}
{top}
[[contact]]
name = "c"
slave = "b.ymin"
master = "tool"
penalty = 1e4
weighting = "area"
{master}
[steps]
count = 3
"""


def _run(tmp_path, name: str, text: str):
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    res = load_problem(path).run(out=tmp_path / name, quiet=True)
    assert res.exit_code == 0, name
    return res


@pytest.mark.parametrize("form", ["plane_strain", "axisymmetric"])
def test_flat_profile_is_the_rigid_line(tmp_path, form):
    """A flat profile under the block (plane strain: extruded along z; axisymmetric: revolved about the y axis, a
    flat disc) gives the displacements of a rigid line there to 1e-12 of the largest and the same contact force."""
    origin = (1.0, 0.0) if form == "axisymmetric" else (-0.2, 0.0)
    line = ('[[rigid]]\nname = "tool"\nshape = "plane"\npoint = [0.0, -0.001, 0.0]\nnormal = [0.0, 1.0, 0.0]\n')
    where = ('revolve = { axis = [0.0, 1.0, 0.0], center = [0.0, -0.001, 0.0] }' if form == "axisymmetric" else
             'extrude = { axis = [0.0, 0.0, 1.0], origin = [0.0, -0.001, 0.0] }')
    pts = "[[0.0, 0.0], [3.0, 0.0]]" if form == "axisymmetric" else "[[-2.0, 0.0], [2.0, 0.0]]"
    prof = f'[[rigid]]\nname = "tool"\nshape = "profile"\npoints = {pts}\n{where}\n'
    a = _run(tmp_path, "line", block(form, line, origin))
    b = _run(tmp_path, "profile", block(form, prof, origin))
    ua, ub = np.asarray(a.u), np.asarray(b.u)
    assert np.abs(ua).max() > 0.01
    assert np.abs(ua - ub).max() <= 1e-12 * np.abs(ua).max()
    fa = a.summary["steps"][-1]["contact_force_on"]["tool"][1]
    fb = b.summary["steps"][-1]["contact_force_on"]["tool"][1]
    assert fa < 0.0 and fb == pytest.approx(fa, rel=1e-10)   # (the block pushes the tool down)


FILLET = """[[rigid]]
name = "tool"
shape = "profile"
points = [[-10.0, -10.0], [0.0, 0.0], [10.0, -10.0]]
fillets = [2.0]
extrude = { axis = [0.0, 0.0, 1.0], origin = [0.0, 0.0, 0.0] }
"""
CIRCLE = f"""[[rigid]]
name = "tool"
shape = "cylinder"
center = [0.0, {-2.0 * math.sqrt(2.0)!r}, 0.0]
axis = [0.0, 0.0, 1.0]
radius = 2.0
"""


def test_fillet_is_the_rigid_circle(tmp_path):
    """A roof-shaped profile (legs at 45 degrees) with a fillet of radius 2 at its apex under the block: the block's
    bottom stays on the arc (its top at y = 2 sqrt(2) - 2 below the corner), so it meets the rigid circle of radius 2
    about the fillet's centre: the same displacements to 1e-10 of the largest, the same force."""
    origin = (-0.2, 2.0 - 2.0 * math.sqrt(2.0) + 0.001)
    a = _run(tmp_path, "circle", block("plane_strain", CIRCLE, origin))
    b = _run(tmp_path, "fillet", block("plane_strain", FILLET, origin))
    ua, ub = np.asarray(a.u), np.asarray(b.u)
    assert np.abs(ua - ub).max() <= 1e-10 * np.abs(ua).max()
    st = b.state.contact.passes[0]
    assert np.sum(np.isfinite(st.gap) & (st.gap < 0.0)) >= 3


def test_tangent_against_differences(tmp_path):
    """The fillet case at the converged first step: the Newton tangent against central differences of the
    residual, every column, within 1e-6."""
    origin = (-0.2, 2.0 - 2.0 * math.sqrt(2.0) + 0.001)
    path = tmp_path / "fd.toml"
    path.write_text(block("plane_strain", FILLET, origin))
    rep = check_tangent(load_problem(path), step=1, columns=None)
    assert rep["converged"] and rep["relative_error"] <= 1e-6, rep["relative_error"]


def test_profiles_out_of_the_plane_refused(tmp_path):
    """One line naming the pair: a profile extruded along x in plane strain, one extruded in an axisymmetric model,
    a profile that moves along z."""
    path = tmp_path / "bad.toml"
    cases = [("plane_strain", FILLET.replace("axis = [0.0, 0.0, 1.0]", "axis = [1.0, 0.0, 0.0]"),
              "must be extruded along z from the x-y plane"),
             ("axisymmetric", FILLET, "must be revolved about the model's axis"),
             ("plane_strain", FILLET + "motion = { translation = [0.0, 0.0, 0.1] }\n", "moves out of its plane")]
    for form, master, words in cases:
        path.write_text(block(form, master, (1.0, 0.0) if form == "axisymmetric" else (-0.2, 0.0)))
        with pytest.raises(InputError) as err:
            load_problem(path)
        assert words in str(err.value) and "\n" not in str(err.value), str(err.value)


@pytest.mark.parametrize("form", ["plane_strain", "axisymmetric"])
def test_meshed_rigid_die_is_the_rigid_line(tmp_path, form):
    """A rigid die meshed with quad4 cells in the plane (``shape = "mesh"``, a rectangle), its top edge set the master:
    the block pressed onto it takes the displacements of the rigid line there to 1e-12 of the largest; a die of
    hexahedra, or one that moves out of the plane, is refused with one line."""
    origin = (1.0, 0.0) if form == "axisymmetric" else (-0.2, 0.0)
    line = '[[rigid]]\nname = "tool"\nshape = "plane"\npoint = [0.0, -0.001, 0.0]\nnormal = [0.0, 1.0, 0.0]\n'
    x0 = 0.5 if form == "axisymmetric" else -1.0
    die = (f'[[rigid]]\nname = "tool"\nshape = "mesh"\n'
           f'mesh = {{ generator = "rectangle", lx = 3.0, ly = 0.5, nx = 6, ny = 1, origin = [{x0}, -0.501] }}\n')
    a = _run(tmp_path, "line", block(form, line, origin))
    b = _run(tmp_path, "die", block(form, die, origin).replace('master = "tool"', 'master = "tool.ymax"'))
    ua, ub = np.asarray(a.u), np.asarray(b.u)
    n = np.abs(ua).size
    assert np.abs(ua).max() > 0.01
    assert np.abs(ua - ub[:n]).max() <= 1e-12 * np.abs(ua).max()
    path = tmp_path / "bad.toml"
    for master, words in ((die.replace('generator = "rectangle", lx = 3.0, ly = 0.5, nx = 6, ny = 1, origin = '
                                       f'[{x0}, -0.501]', 'generator = "block", lx = 3.0, ly = 0.5, lz = 1.0, nx = 6, '
                                       'ny = 1, nz = 1'), "must be a mesh of planar cells"),
                          (die + "motion = { rotation = [0.1, 0.0, 0.0] }\n", "moves out of its plane")):
        path.write_text(block(form, master, origin).replace('master = "tool"', 'master = "tool.ymax"'))
        with pytest.raises(InputError) as err:
            load_problem(path)
        assert words in str(err.value) and "\n" not in str(err.value), str(err.value)
