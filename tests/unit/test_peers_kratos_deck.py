"""The Kratos case writer of benchmarks/peers (no Kratos needed): penalty conversion, mesh and parameters."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "benchmarks" / "peers"))

from kratos_deck import nodal_penalties, two_blocks_case, write_case

from covcontact.io.loader import load_problem


@pytest.fixture(scope="module")
def problem():
    return load_problem(ROOT / "benchmarks" / "problems" / "two_blocks_5k.toml")


def test_nodal_penalty_is_four_k_over_the_face_area_on_a_uniform_mesh(problem):
    punch = next(b.mesh for b in problem.bodies if b.name == "punch")
    eps = nodal_penalties(punch, "zmin", 1e6)
    area = (1.0 / 11) ** 2                     # the punch's 11 x 11 faces on a unit square
    assert len(eps) == 12 * 12
    np.testing.assert_allclose(list(eps.values()), 4e6 / area, rtol=1e-12)
    # graded: a node between a small and a large face gets the area-weighted mean of 4 k / A
    assert nodal_penalties(punch, "zmin", 2.5e5)[0] == pytest.approx(4 * 2.5e5 / area)


def test_case_files(problem, tmp_path):
    case = two_blocks_case(problem, penalty=2.5e5)
    info = write_case(case, tmp_path)
    nodes = sum(b.mesh.n_nodes for b in problem.bodies)
    cells = sum(b.mesh.n_cells for b in problem.bodies)
    assert (info.nodes, info.elements) == (nodes, cells)
    text = (tmp_path / "mesh.mdpa").read_text()
    assert text.count("TotalLagrangianElement3D8N") >= 1
    params = json.loads((tmp_path / "ProjectParameters.json").read_text())
    assert params["solver_settings"]["time_stepping"]["time_step"] == pytest.approx(0.1)
    assert params["solver_settings"]["contact_settings"]["mortar_type"] == "PenaltyContactFrictionless"
    nodal = params["race"]["nodal_penalty"]
    assert len(nodal) == 144 and all(v == pytest.approx(4 * 2.5e5 * 121) for v in nodal.values())
    # the punch's pressed face moves by the problem's value: -0.05 in z, ramped
    supports = {s["Parameters"]["model_part_name"]: s["Parameters"] for s in
                params["processes"]["constraints_process_list"]}
    assert supports["Structure.punch_zmax"]["value"] == [0.0, 0.0, "-0.05*t"]
    assert supports["Structure.base_zmin"]["value"] == [0.0, 0.0, 0.0]
    assert supports["Structure.base_zmin"]["constrained"] == [True, True, True]
    mats = json.loads((tmp_path / "materials.json").read_text())
    assert "KirchhoffSaintVenant3DLaw" in json.dumps(mats)
