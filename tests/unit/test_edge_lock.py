"""Slaves held on master edges and corners in a valley (covcontact.contact.edgelock, docs/theory.md section 4).

A punch whose slave nodes lie on the base's facet edges pushes those edges down; each slave then sits in a
valley where the normal of one facet pushes it onto the other one and back, and Newton cycles between two
iterates with the same residual. With the lock it converges, the tangent of a held slave is exact, and the
converged state is also a solution of the free contact problem (every lock agrees with the free projection).
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import covcontact.contact.manager as manager_module
from covcontact.contact.driver import project_slaves
from covcontact.contact.edgelock import RELEASED, edge_point, inconsistent
from covcontact.contact.search import candidates
from covcontact.contact.state import PassState
from covcontact.contact.surface import facet_sizes
from covcontact.io.loader import load_problem

ROOT = Path(__file__).resolve().parents[2]


def _valley_problem(tmp: Path):
    """benchmarks/problems/two_blocks_5k.toml with a 20 x 20 base and a 22 x 22 punch: punch nodes on the base's
    edges and corners (x, y in {-0.5, 0, 0.5}); the first tenth of its load as one step."""
    text = (ROOT / "benchmarks" / "problems" / "two_blocks_5k.toml").read_text()
    for old, new in (("nx = 10, ny = 10, nz = 5", "nx = 20, ny = 20, nz = 2"),
                     ("nx = 11, ny = 11, nz = 5", "nx = 22, ny = 22, nz = 2"),
                     ("count = 10", "count = 1"), ("value = [0.0, 0.0, -0.05]", "value = [0.0, 0.0, -0.005]")):
        assert old in text
        text = text.replace(old, new)
    path = tmp / "valley.toml"
    path.write_text(text)
    return load_problem(path)


@pytest.fixture(scope="module")
def converged(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("valley")
    res = _valley_problem(tmp).run(out=tmp / "out", quiet=True)
    return res


def test_slaves_on_master_edges_converge(converged):
    assert converged.exit_code == 0
    (step,) = converged.summary["steps"]
    assert step["cutbacks"] == 0 and step["iterations"] <= 5
    assert step["residual_norms"][-1] <= 1e-8 * step["residual_norms"][0]
    lock = converged.state.contact.passes[0].edge_lock
    assert np.count_nonzero(lock >= 0) > 0  # the slaves on the base's edges are held


def test_locks_agree_with_the_free_projection(converged):
    """The converged answer solves the free problem: at the final positions the free projection (no tolerance
    on the facet bounds) of every held slave is its edge or corner point, with the same gap vector."""
    model, state = converged.model, converged.state
    p = model.contact.passes[0]
    t = state.contact.passes[0]
    xe = state.contact.x
    held = np.flatnonzero(t.edge_lock >= 0)
    xs = xe[p.slaves[held]]
    ptr, fac = candidates(xe, p.surface, xs, float(facet_sizes(xe, p.surface.faces).max()))
    free = project_slaves(xe, p.surface, xs, ptr, fac, t.facet[held], t.xi[held], tol_inside=0.0)
    pts = [edge_point(p.surface, xe, t.edge_lock[s], xe[p.slaves[s]]) for s in held]
    gap = np.array([q[2] for q in pts])
    normal = np.array([q[3] for q in pts])
    assert inconsistent(t.edge_lock[held], gap, normal, free.kind, free.g, free.normal).size == 0
    np.testing.assert_allclose(t.gap[held], gap, rtol=1e-12)
    assert np.all(gap < 0.0)


def test_without_locks_newton_cycles(tmp_path, monkeypatch):
    """The failure the lock removes: the same problem without it repeats one residual norm."""
    monkeypatch.setattr(manager_module, "new_locks",
                        lambda *a, **k: (np.zeros(0, np.int64), np.zeros(0, np.int64)))
    problem = _valley_problem(tmp_path)
    problem.solver = dataclasses.replace(problem.solver, max_iterations=10, max_cutbacks=0)
    res = problem.run(out=tmp_path / "out", quiet=True)
    assert res.exit_code == 1
    rows = np.loadtxt(tmp_path / "out" / "convergence.csv", delimiter=",", skiprows=1, usecols=(0, 1, 2))
    r = rows[rows[:, 0] == 1, 2]
    assert r.size == 11  # the predictor's residual and ten iterations
    assert r[-1] > 1e-6 * r[0]
    assert abs(r[-1] - r[-3]) <= 1e-4 * r[-1]  # a two-cycle


def test_held_slave_tangent_matches_finite_differences(converged):
    """Columns of the held slaves' dofs: the exact tangent of the edge or vertex element against central
    differences of the residual (the locks come from the guess, so they hold for every perturbation)."""
    model, state, u = converged.model, converged.state, converged.u.copy()
    lam = 1.0
    p = model.contact.passes[0]
    held = np.flatnonzero(state.contact.passes[0].edge_lock >= 0)[:4]
    cols = (3 * p.slaves[held][:, None] + np.arange(3)).ravel()
    _, K, _ = model.evaluate(u, lam, state, state)
    K = K.tocsc()
    h = 1e-9
    for c in cols:
        up, um = u.copy(), u.copy()
        up[c] += h
        um[c] -= h
        Rp, _, _ = model.evaluate(up, lam, state, state, want_K=False)
        Rm, _, _ = model.evaluate(um, lam, state, state, want_K=False)
        fd = (Rp - Rm) / (2 * h)
        col = K[:, c].toarray().ravel()
        assert np.linalg.norm(col - fd) <= 1e-6 * np.linalg.norm(col)


def test_a_lock_off_the_edge_is_released(converged):
    """A lock that does not agree with the free projection (a slave in the middle of a facet held on one of its
    edges) is released; the converged locks are kept."""
    model, state = converged.model, converged.state
    mgr = model.contact
    assert mgr.augment(state.contact) is None
    trial = state.contact.copy()
    t = trial.passes[0]
    inner = np.flatnonzero((t.edge_lock < 0) & (np.abs(t.xi).max(axis=1) < 0.5) & (t.gap < 0.0))[0]
    t.edge_lock[inner] = 8 * t.facet[inner] + 1
    new = mgr.augment(trial)
    assert new is not None
    assert new.passes[0].edge_lock[inner] == RELEASED
    kept = np.flatnonzero(state.contact.passes[0].edge_lock >= 0)
    np.testing.assert_array_equal(new.passes[0].edge_lock[kept], state.contact.passes[0].edge_lock[kept])
    assert t.edge_lock[inner] == 8 * t.facet[inner] + 1  # the trial given is not changed
    # the next step starts with released marks cleared
    assert mgr.start_step(new).passes[0].edge_lock[inner] == -1


def test_checkpoint_without_locks_loads():
    """Checkpoints written before edge locks existed load with every slave free."""
    s = PassState.empty(5)
    arrays = {k: v for k, v in s.arrays("contact.0").items() if not k.endswith("edge_lock")}
    back = PassState.from_arrays(arrays, "contact.0")
    np.testing.assert_array_equal(back.edge_lock, np.full(5, -1))
