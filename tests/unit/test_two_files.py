"""One two-body model read from a Gmsh file (physical volumes and surfaces) and from an Abaqus deck (element sets,
*SURFACE by face identifier): the same bodies, sets and results to round-off. The files are committed in tests/data
(made by tests/data/make_two_blocks.py)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from covcontact.io.loader import problem_from_dict

DATA = Path(__file__).resolve().parents[1] / "data"


def _raw(path: Path, cell_faces: str = "nts") -> dict:
    body = {"material": {"model": "neo-hooke", "E": 1000.0, "nu": 0.3}}
    return {
        "problem": {"name": "two-files"},
        "bodies": [dict(body, name="base", mesh={"file": str(path), "volume": "base"}),
                   dict(body, name="punch", mesh={"file": str(path), "volume": "punch"})],
        "contact": [{"name": "c", "slave": "punch.punch_bottom", "master": "base.base_top", "penalty": 1e5,
                     "type": cell_faces, "friction": 0.2}],
        "dirichlet": [{"set": "base.base_bottom"},
                      {"set": "punch.punch_top", "value": [0.01, 0.005, -0.01]}],
        "steps": {"count": 2}, "output": {"vtu": False},
    }


@pytest.mark.parametrize("kind", ["nts", "sts"])
def test_gmsh_and_abaqus_give_the_same_model(tmp_path, kind):
    res, meshes = {}, {}
    for suffix in ("msh", "inp"):
        prob = problem_from_dict(_raw(DATA / f"two_blocks.{suffix}", kind), tmp_path / f"{suffix}.toml")
        meshes[suffix] = {b.name: b.mesh for b in prob.bodies}
        res[suffix] = prob.run(out=tmp_path / suffix)
        assert res[suffix].exit_code == 0
    order = {}
    for suffix, bodies in meshes.items():
        for name, mesh in bodies.items():
            assert mesh.cell_type == "hex8" and mesh.n_cells == 4
            for fset in ("base_top", "base_bottom") if name == "base" else ("punch_top", "punch_bottom"):
                assert len(mesh.face_sets[fset]) == 4
                assert np.allclose(mesh.points[mesh.face_sets[fset]][:, :, 2].std(axis=1), 0.0)
            order[suffix, name] = np.lexsort(mesh.points.T[::-1])
    for name in ("base", "punch"):
        a, b = meshes["msh"][name], meshes["inp"][name]
        np.testing.assert_array_equal(a.points[order["msh", name]], b.points[order["inp", name]])
        # each face set: the same faces (as sets of node positions), facing the same way
        for fset in a.face_sets:
            key = [sorted(map(tuple, np.round(m.points[m.face_sets[fset]].mean(axis=1), 12))) for m in (a, b)]
            assert key[0] == key[1], fset
    steps = [[s["iterations"] for s in r.summary["steps"]] for r in res.values()]
    assert steps[0] == steps[1]
    u = {}
    for suffix, r in res.items():
        off = 0
        for name in ("base", "punch"):
            n = meshes[suffix][name].n_nodes
            u[suffix, name] = r.u.reshape(-1, 3)[off: off + n][order[suffix, name]]
            off += n
    scale = np.abs(res["msh"].u).max()
    assert scale > 1e-3
    for name in ("base", "punch"):
        np.testing.assert_allclose(u["msh", name], u["inp", name], rtol=0, atol=1e-10 * scale)
    fa = res["msh"].summary["steps"][-1]["contact_force"]
    fb = res["inp"].summary["steps"][-1]["contact_force"]
    np.testing.assert_allclose(fa, fb, rtol=1e-9)
    assert fa[2] > 0.0
