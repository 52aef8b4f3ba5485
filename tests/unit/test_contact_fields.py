"""The VTU contact fields of a slave surface in several pairs (contact/report.py ``node_fields``, ``point_data``):
each pair's own gap, pressure and status, and the combined fields (smallest gap, summed pressure, highest
status); before, the last pair's fields overwrote the others'."""

from __future__ import annotations

import meshio
import numpy as np

from covcontact.io.loader import load_problem

TWO_BASES = """
[problem]
name = "two-bases"
[[bodies]]
name = "left"
element = "hex8"
material = { model = "svk", E = 1000.0, nu = 0.3 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 0.5, nx = 2, ny = 2, nz = 1, origin = [-1.0, -0.5, -0.5] }
[[bodies]]
name = "right"
element = "hex8"
material = { model = "svk", E = 1000.0, nu = 0.3 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 0.5, nx = 2, ny = 2, nz = 1, origin = [0.0, -0.5, -0.5] }
[[bodies]]
name = "punch"
element = "hex8"
material = { model = "svk", E = 1000.0, nu = 0.3 }
mesh = { generator = "block", lx = 1.2, ly = 0.6, lz = 0.3, nx = 4, ny = 2, nz = 1, origin = [-0.6, -0.3, 0.0] }
[[contact]]
name = "on_left"
slave = "punch.zmin"
master = "left.zmax"
penalty = 1.0e4
weighting = "area"
[[contact]]
name = "on_right"
slave = "punch.zmin"
master = "right.zmax"
penalty = 1.0e4
weighting = "area"
[[dirichlet]]
set = "left.zmin"
components = "xyz"
[[dirichlet]]
set = "right.zmin"
components = "xyz"
[[dirichlet]]
set = "punch.zmax"
components = "xyz"
value = [0.0, 0.0, -0.01]
[steps]
count = 1
"""


def test_each_pair_of_a_shared_slave_surface_is_written(tmp_path):
    path = tmp_path / "p.toml"
    path.write_text(TWO_BASES)
    res = load_problem(path).run(out=tmp_path / "out", quiet=True)
    assert res.exit_code == 0
    m = meshio.read(sorted((tmp_path / "out").glob("step_*.vtu"))[-1])
    pd = m.point_data
    left, right = pd["contact_pressure[on_left]"], pd["contact_pressure[on_right]"]
    x = m.points[:, 0]
    slave = pd["contact_status"] >= 0
    on_l = slave & (x < -0.01)
    on_r = slave & (x > 0.01)
    assert (left[on_l] > 0).all() and (right[on_l] == 0).all()  # each pair presses on its own side only
    assert (right[on_r] > 0).all() and (left[on_r] == 0).all()
    assert np.allclose(pd["contact_pressure"], left + right)
    assert np.array_equal(pd["contact_status"], np.maximum(pd["contact_status[on_left]"],
                                                           pd["contact_status[on_right]"]))
    g = np.fmin(pd["gap[on_left]"], pd["gap[on_right]"])
    assert np.allclose(pd["gap"], g, equal_nan=True)
    # the pressure of a pressed node is the same on either side of the joint (symmetric set-up)
    assert np.isclose(left[on_l].max(), right[on_r].max(), rtol=1e-6)
