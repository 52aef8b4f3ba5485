"""Node sets defined in the input file (``sets`` of a body): box, closest point, node numbers."""

from __future__ import annotations

import numpy as np
import pytest

from covcontact.cli import main
from covcontact.io.loader import load_problem
from covcontact.io.validate import InputError

BASE = """
[problem]
name = "sets"
[[bodies]]
name = "plate"
element = "hex8"
material = {{ model = "svk", E = 1000.0, nu = 0.3 }}
mesh = {{ generator = "plate", lx = 4.0, ly = 2.0, t = 0.1, nx = 4, ny = 2 }}
{sets}
[[dirichlet]]
set = "plate.xmin"
components = "xyz"
[[force]]
set = "plate.{load}"
value = [0.0, 0.0, -1.0]
distribution = "total"
"""


def write(tmp_path, sets, load="corner"):
    f = tmp_path / "p.toml"
    f.write_text(BASE.format(sets=sets, load=load))
    return f


def test_box_closest_and_nodes(tmp_path):
    f = write(tmp_path, '[bodies.sets]\n'
                        'corner = { box = [[3.9, 1.9, -1.0], [4.1, 2.1, 1.0]] }\n'
                        'tip = { closest = [[4.0, 0.0, 0.2], [4.0, 2.0, 0.2]] }\n'
                        'two = { nodes = [0, 1] }')
    p = load_problem(f)
    mesh = p.bodies[0].mesh
    X = mesh.points
    corner = mesh.node_sets["corner"]
    assert len(corner) == 2  # the corner's bottom and top node (one hex8 through the thickness)
    assert np.allclose(X[corner][:, :2], [4.0, 2.0])
    tip = mesh.node_sets["tip"]
    assert len(tip) == 2 and np.allclose(X[tip][:, 0], 4.0) and np.allclose(X[tip][:, 2], X[:, 2].max())
    assert list(mesh.node_sets["two"]) == [0, 1]
    assert p.forces[0].set == "corner"
    assert main(["run", str(f), "--out", str(tmp_path / "out"), "--quiet"]) == 0


@pytest.mark.parametrize("sets, words", [
    ('sets = { corner = { box = [[9.0, 9.0, 9.0], [10.0, 10.0, 10.0]] } }', "no node lies in the box"),
    ('sets = { corner = { box = [[0.0, 0.0, 0.0]] } }', "must be two points"),
    ('sets = { corner = { nodes = [0, 99999] } }', "node numbers must lie in"),
    ('sets = { corner = { nodes = [0], closest = [0.0, 0.0, 0.0] } }', "exactly one of"),
    ('sets = { corner = { boxx = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]] } }', "exactly one of"),
    ('sets = { xmin = { nodes = [0] } }', "exists already"),
])
def test_bad_sets_are_one_line_errors(tmp_path, capsys, sets, words):
    f = write(tmp_path, sets, load="xmax")
    with pytest.raises(InputError, match=words):
        load_problem(f)
    assert main(["run", str(f), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(f) in err[0] and "sets" in err[0]


# ------------------------------------------------------------------ rigid motion along a path

RIGID = """
[problem]
name = "path"
[[bodies]]
name = "b"
element = "hex8"
material = {{ model = "svk", E = 1000.0, nu = 0.3 }}
mesh = {{ generator = "block", lx = 1.0, ly = 1.0, lz = 1.0, nx = 1, ny = 1, nz = 1 }}
[[rigid]]
name = "floor"
shape = "plane"
point = [0.0, 0.0, -0.1]
normal = [0.0, 0.0, 1.0]
motion = {{ {motion} }}
[[contact]]
slave = "b.zmin"
master = "floor"
penalty = 1.0e3
[[dirichlet]]
set = "b.zmax"
components = "xyz"
"""


def test_motion_path_is_piecewise_linear(tmp_path):
    f = tmp_path / "p.toml"
    f.write_text(RIGID.format(motion="path = [[0.0, 0.0, 0.0, 0.0], [0.25, 0.0, 0.0, 0.1], [1.0, 3.0, 0.0, 0.1]]"))
    m = load_problem(f).rigid[0].motion
    X = np.array([[1.0, 2.0, 3.0]])
    assert np.allclose(m.apply(X, 0.125) - X, [0.0, 0.0, 0.05])   # half of the press
    assert np.allclose(m.apply(X, 0.25) - X, [0.0, 0.0, 0.1])
    assert np.allclose(m.apply(X, 0.625) - X, [1.5, 0.0, 0.1])    # half of the slide
    assert np.allclose(m.apply(X, 2.0) - X, [3.0, 0.0, 0.1])      # constant beyond the last row
    assert np.allclose(m.rotate(np.eye(3), 0.6), np.eye(3))


@pytest.mark.parametrize("motion, words", [
    ("path = [[0.0, 0.0, 0.0]]", "rows"),
    ("path = [[0.1, 0.0, 0.0, 0.0], [1.0, 1.0, 0.0, 0.0]]", "start at 0"),
    ("path = [[0.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]]", "increase strictly"),
    ("path = [[0.0, 0.0, 0.0, 0.0], [1.0, 1.0, 0.0, 0.0]], translation = [1.0, 0.0, 0.0]", "not both"),
])
def test_bad_motion_path(tmp_path, capsys, motion, words):
    f = tmp_path / "p.toml"
    f.write_text(RIGID.format(motion=motion))
    with pytest.raises(InputError, match=words):
        load_problem(f)
    assert main(["run", str(f), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "motion" in err[0]
