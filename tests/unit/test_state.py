"""The state rule: ``Model.evaluate(u, lam, committed, guess)`` is a function of its arguments.

Property tests over random displacements and random states: evaluating twice gives identical residual,
tangent and trial (bit for bit) and leaves the committed state and the guess untouched; for contact with
friction (mesh facets and an analytic master) under augmented-Lagrangian multipliers, and for solid-shells
(EAS parameters) in contact. Also: a cutback drops the trial (the committed state of a failed step is the
one before it), and the contact pattern is reused while the coupling does not change.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from covcontact.io.loader import load_problem
from covcontact.solvers.model import Model
from covcontact.solvers.newton import Newton
from covcontact.solvers.state import State

ROOT = Path(__file__).resolve().parents[2]


def _problem(tmp: Path, name: str, text: str):
    path = tmp / f"{name}.toml"
    path.write_text(text)
    return load_problem(path)


def _friction_facets(tmp: Path):
    """Two blocks, the punch pressed and dragged over the base: Coulomb friction on mesh facets, Uzawa."""
    text = (ROOT / "examples/contact/two_blocks.toml").read_text()
    text = text.replace('weighting = "area"\n', 'weighting = "area"\nfriction = 0.3\nmethod = "augmented"\n', 1)
    text = text.replace("value = [0.0, 0.0, -0.02]", "value = [0.02, 0.01, -0.02]")
    return _problem(tmp, "facets", text)


def _friction_analytic(tmp: Path):
    text = (ROOT / "examples/friction/block_sliding.toml").read_text()
    text = text.replace("friction = 0.3\n", "friction = 0.3\nmethod = \"augmented\"\n", 1)
    return _problem(tmp, "analytic", text)


def _shells(tmp: Path):
    text = (ROOT / "examples/paper/sphere_q4.toml").read_text()
    i = text.index("[steps]")
    j = text.index("[", i + 1)
    return _problem(tmp, "shells", text[:i] + "[steps]\ncount = 100\n\n" + text[j:])


def _converged(problem, steps: int = 1):
    """A model with the committed state and displacement after ``steps`` load steps."""
    model = Model(problem)
    newton = Newton(model, problem.solver)
    u = model.prescribed(0.0)
    state = model.initial_state()
    lam = 0.0
    for lam_b in problem.steps.factors[:steps]:
        ok, _, _, _, state = newton.advance(u, lam, lam_b, state)
        assert ok
        lam = lam_b
    return model, u, state, lam


def _arrays(state: State) -> dict:
    return {k: np.array(v, copy=True) for k, v in state.arrays().items()}


def _same(a: dict, b: dict) -> bool:
    return a.keys() == b.keys() and all(np.array_equal(a[k], b[k], equal_nan=True) for k in a)


@pytest.fixture(scope="module", params=["facets", "analytic", "shells"])
def converged(request, tmp_path_factory):
    make = {"facets": _friction_facets, "analytic": _friction_analytic, "shells": _shells}[request.param]
    model, u, state, lam = _converged(make(tmp_path_factory.mktemp(request.param)))
    return request.param, model, u, state, lam


@settings(max_examples=8)
@given(seed=st.integers(0, 2**31 - 1), size=st.floats(0.0, 1.0))
def test_evaluate_is_pure(converged, seed, size):
    name, model, u0, committed, lam = converged
    rng = np.random.default_rng(seed)
    # a random state: the committed one with random Uzawa multipliers and random contact-point guesses
    guess = model.start_step(committed)
    for p in guess.contact.passes:
        p.multiplier = -size * rng.uniform(0.0, 1e-3, p.multiplier.shape) * (p.multiplier.size > 0)
        p.xi = np.clip(p.xi + 0.1 * size * rng.standard_normal(p.xi.shape), -1.0, 1.0)
    for e in guess.elements:
        for k in e:
            e[k] = e[k] + 1e-6 * size * rng.standard_normal(e[k].shape)
    scale = 1e-3 if name != "shells" else 1e-4
    u = u0 + scale * size * rng.standard_normal(u0.shape) * model.free
    before_c, before_g = _arrays(committed), _arrays(guess)
    model.begin_step()
    R1, K1, T1 = model.evaluate(u, lam, committed, guess)
    R2, K2, T2 = model.evaluate(u, lam, committed, guess)
    assert np.array_equal(R1, R2)
    assert np.array_equal(K1.indptr, K2.indptr) and np.array_equal(K1.indices, K2.indices)
    assert np.array_equal(K1.data, K2.data)
    assert _same(_arrays(T1), _arrays(T2))
    assert _same(_arrays(committed), before_c), "evaluate changed the committed state"
    assert _same(_arrays(guess), before_g), "evaluate changed the state it started from"
    # the residual-only path gives the same residual
    R3, K3, _ = model.evaluate(u, lam, committed, guess, want_K=False)
    assert K3 is None and np.array_equal(R1, R3)


def test_cutback_drops_the_trial(tmp_path):
    """A step that cannot converge (one Newton iteration allowed) keeps the committed state of the step
    before, bit for bit."""
    problem = _friction_facets(tmp_path)
    model, u, state, lam = _converged(problem, steps=1)
    problem.solver.max_iterations = 1
    problem.solver.max_cutbacks = 1
    newton = Newton(model, problem.solver)
    before = _arrays(state)
    u_before = u.copy()
    ok, _, cutbacks, _, after = newton.advance(u, lam, problem.steps.factors[1], state)
    assert not ok and cutbacks == 2
    assert after is state and _same(_arrays(after), before)
    assert np.array_equal(u, u_before)


def test_contact_pattern_is_reused(tmp_path):
    """Within a step and across steps the tangent keeps its pattern while the contact coupling does not
    change (the solver keeps its analysis); a new coupling grows it once."""
    problem = _friction_facets(tmp_path)
    model, u, state, lam = _converged(problem, steps=1)
    rebuilds = model.coupling.rebuilds
    assert rebuilds >= 1  # the first contact coupled the blocks
    pattern = model.coupling.pattern
    model.begin_step()
    _, K, _ = model.evaluate(u, lam, state)
    assert model.coupling.pattern is pattern and model.coupling.rebuilds == rebuilds
    assert K.nnz == pattern.nnz
    # lift the punch off: no contact, the grown pattern stays (zeros where the contact was)
    far = u.copy()
    off, n = model.system.offset("punch"), problem.body("punch").mesh.n_nodes
    far.reshape(-1, 3)[off: off + n, 2] += 0.5
    _, K2, _ = model.evaluate(far, lam, state)
    assert model.coupling.pattern is pattern and K2.nnz == K.nnz
