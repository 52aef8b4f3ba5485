"""Several bodies in one mesh file (docs/input.md, ``mesh = { file, volume }``): each body takes the cells of
its volume (Gmsh physical volume or element set), its own copies of the nodes it shares with the others, and
the groups that lie on it; a face group between two volumes becomes a boundary face set of each."""

from __future__ import annotations

import meshio
import numpy as np
import pytest

from covcontact.io.loader import problem_from_dict
from covcontact.io.validate import InputError
from covcontact.mesh.generators import block


def _assembly(path):
    """Two 2 x 2 x 1 stacks of unit hex8 cells, "base" below z = 1 and "punch" above it, sharing the nodes of the
    plane z = 1; physical surfaces "interface" (z = 1) and "bottom" (z = 0)."""
    lower = block(2.0, 2.0, 1.0, 2, 2, 1, cell="hex8")
    pts = np.vstack([lower.points, lower.points[lower.points[:, 2] > 0.5] + [0.0, 0.0, 1.0]])
    # the upper cells: the lower cells' nodes shifted up (top nodes of the lower = bottom of the upper)
    top_of = {tuple(np.round(p, 9)): i for i, p in enumerate(pts)}
    upper = np.array([[top_of[tuple(np.round(pts[n] + [0.0, 0.0, 1.0], 9))] for n in c] for c in lower.cells])
    hexes = np.vstack([lower.cells, upper])
    z = pts[:, 2]

    def quads_at(level):
        out = []
        for c in hexes:
            face = [n for n in c if abs(z[n] - level) < 1e-9]
            if len(face) == 4:
                q = pts[face][:, :2]
                order = np.argsort(np.arctan2(q[:, 1] - q[:, 1].mean(), q[:, 0] - q[:, 0].mean()))
                out.append(np.array(face)[order])
        return np.array(out)

    inter = quads_at(1.0)[: 4]
    bottom = quads_at(0.0)
    cells = [("hexahedron", hexes), ("quad", inter), ("quad", bottom)]
    phys = [np.array([1] * 4 + [2] * 4), np.full(len(inter), 3), np.full(len(bottom), 4)]
    mesh = meshio.Mesh(pts, cells, cell_data={"gmsh:physical": phys, "gmsh:geometrical": phys},
                       field_data={"base": np.array([1, 3]), "punch": np.array([2, 3]),
                                   "interface": np.array([3, 2]), "bottom": np.array([4, 2])})
    meshio.write(path, mesh, file_format="gmsh22", binary=False)


def _raw(path, penalty=1e4):
    return {
        "problem": {"name": "assembly"},
        "bodies": [{"name": "base", "material": {"model": "neo-hooke", "E": 1000.0, "nu": 0.3},
                    "mesh": {"file": str(path), "volume": "base"}},
                   {"name": "punch", "material": {"model": "neo-hooke", "E": 1000.0, "nu": 0.3},
                    "mesh": {"file": str(path), "volume": "punch"}}],
        "contact": [{"name": "c", "slave": "punch.interface", "master": "base.interface", "penalty": penalty,
                     "weighting": "area"}],
        "dirichlet": [{"set": "base.bottom"}, {"set": "punch.interface", "components": "xy"}],
        "pressure": [{"set": "punch.interface", "value": 0.0}],
        "steps": {"count": 1}, "output": {"vtu": False},
    }


def test_two_volumes_of_one_file(tmp_path):
    path = tmp_path / "assembly.msh"
    _assembly(path)
    prob = problem_from_dict(_raw(path), tmp_path / "p.toml")
    base, punch = (b.mesh for b in prob.bodies)
    assert base.n_cells == 4 and punch.n_cells == 4 and base.n_nodes == 18 and punch.n_nodes == 18
    # the interface: the top of the base and the bottom of the punch, each facing out of its own body
    from covcontact.mesh.faces import face_normals

    assert len(base.face_sets["interface"]) == 4 and len(punch.face_sets["interface"]) == 4
    assert np.all(face_normals(base.points, base.face_sets["interface"])[:, 2] > 0)
    assert np.all(face_normals(punch.points, punch.face_sets["interface"])[:, 2] < 0)
    assert "bottom" in base.face_sets and "bottom" not in punch.face_sets
    # the shared nodes are each body's own copies, at the same places
    np.testing.assert_allclose(np.sort(base.points[base.node_sets["interface"]], axis=0),
                               np.sort(punch.points[punch.node_sets["interface"]], axis=0))
    res = prob.run(out=tmp_path / "out")
    assert res.exit_code == 0


def test_unknown_volume(tmp_path):
    path = tmp_path / "assembly.msh"
    _assembly(path)
    raw = _raw(path)
    raw["bodies"][1]["mesh"]["volume"] = "punsh"
    with pytest.raises(InputError) as err:
        problem_from_dict(raw, tmp_path / "p.toml")
    msg = str(err.value)
    assert "bodies[1].mesh.volume" in msg and "no volume (element set) 'punsh'" in msg and "'punch'" in msg
