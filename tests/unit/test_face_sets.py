"""Face sets of your own (docs/input.md, "Face sets of your own"): boundary faces chosen by a box, by the
direction of their outward normal, by an element set, or as a union; usable as master, slave and load
surfaces like the mesh's own."""

from __future__ import annotations

import numpy as np
import pytest

from covcontact.io.loader import problem_from_dict
from covcontact.io.validate import InputError


def _raw(faces: dict | None = None, slave: str = "block.zmax", pressure: str | None = None) -> dict:
    body = {"name": "block", "material": {"model": "neo-hooke", "E": 1000.0, "nu": 0.3},
            "mesh": {"generator": "block", "lx": 2.0, "ly": 1.0, "lz": 1.0, "nx": 4, "ny": 2, "nz": 2}}
    if faces is not None:
        body["faces"] = faces
    raw = {"problem": {"name": "faces"}, "bodies": [body],
           "rigid": [{"name": "plate", "shape": "plane", "point": [0.0, 0.0, 1.0], "normal": [0.0, 0.0, -1.0],
                      "motion": {"translation": [0.0, 0.0, -0.02]}}],
           "contact": [{"name": "touch", "slave": slave, "master": "plate", "penalty": 1e5, "weighting": "area"}],
           "dirichlet": [{"set": "block.zmin"}], "steps": {"count": 2}, "output": {"vtu": False}}
    if pressure:
        raw["pressure"] = [{"set": pressure, "value": 5.0}]
    return raw


def _faces(tmp_path, faces: dict) -> dict:
    prob = problem_from_dict(_raw(faces), tmp_path / "p.toml")
    return prob.bodies[0].mesh


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    return {tuple(sorted(f)) for f in a.tolist()} == {tuple(sorted(f)) for f in b.tolist()}


def test_normal_box_union(tmp_path):
    mesh = _faces(tmp_path, {"up": {"normal": [0.0, 0.0, 1.0]},
                             "up_left": {"normal": [0.0, 0.0, 1.0], "box": [[-1.0, -1.0, -1.0], [1.0, 2.0, 2.0]]},
                             "slanted": {"normal": [1.0, 0.0, 1.0], "angle": 50.0},
                             "ends": {"union": ["xmin", "xmax"]}})
    assert _same(mesh.face_sets["up"], mesh.face_sets["zmax"])
    assert len(mesh.face_sets["up_left"]) == 4 and np.all(mesh.points[mesh.face_sets["up_left"], 0] <= 1.0)
    assert _same(mesh.face_sets["slanted"], np.vstack([mesh.face_sets["zmax"], mesh.face_sets["xmax"]]))
    assert _same(mesh.face_sets["ends"], np.vstack([mesh.face_sets["xmin"], mesh.face_sets["xmax"]]))
    # each face set is also a node set of its nodes, and its faces point out of the body like the mesh's own
    np.testing.assert_array_equal(mesh.node_sets["up"], mesh.node_sets["zmax"])
    from covcontact.mesh.faces import face_normals

    assert np.all(face_normals(mesh.points, mesh.face_sets["up"])[:, 2] > 0)


def test_a_face_set_of_your_own_as_slave_and_load_surface(tmp_path):
    """The block pressed by a plate, its slave surface and a pressure given by a normal-direction face set:
    the same answer as with the generator's zmax."""
    ref = problem_from_dict(_raw(pressure="block.zmax"), tmp_path / "a.toml").run(out=tmp_path / "a")
    own = problem_from_dict(_raw({"top": {"normal": [0.0, 0.0, 1.0], "angle": 1.0}}, slave="block.top",
                                 pressure="block.top"), tmp_path / "b.toml").run(out=tmp_path / "b")
    assert ref.exit_code == 0 and own.exit_code == 0
    np.testing.assert_allclose(own.u, ref.u, atol=1e-12)


@pytest.mark.parametrize("faces, message", [
    ({"none": {"box": [[5.0, 5.0, 5.0], [6.0, 6.0, 6.0]]}}, "bodies[0].faces.none: no boundary face passes"),
    ({"a": {"angle": 20.0}}, "bodies[0].faces.a.angle: needs 'normal'"),
    ({"a": {"normal": [0.0, 0.0, 1.0], "angle": 200.0}}, "bodies[0].faces.a.angle: must lie in (0, 180]"),
    ({"a": {"normal": [0.0, 0.0, 0.0]}}, "bodies[0].faces.a.normal: must not be zero"),
    ({"a": {"union": ["xmin", "top"]}}, "bodies[0].faces.a.union: no face set 'top'"),
    ({"a": {"cells": "core"}}, "bodies[0].faces.a.cells: no element set 'core'"),
    ({"a": {"normals": [0.0, 0.0, 1.0]}}, "bodies[0].faces.a"),
    ({"zmax": {"normal": [0.0, 0.0, 1.0]}}, "bodies[0].faces.zmax: a face set 'zmax' exists already"),
])
def test_bad_face_sets(tmp_path, faces, message):
    with pytest.raises(InputError) as err:
        _faces(tmp_path, faces)
    assert message in str(err.value) and "\n" not in str(err.value), str(err.value)
