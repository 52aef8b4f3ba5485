"""Self-contact against symmetry: a thin elastic tube crushed between rigid plates until its inner walls meet and
flatten, modelled whole with self-contact (examples/contact/tube_crush.toml) and as its upper half with the
inner surface against a rigid symmetry plane (examples/contact/tube_crush_half.toml).

No closed form: the reference is the half model, whose inner wall meets a plane. The two must give the same
plate force at the same plate travel, before the inner walls meet (where only the meshes and the plate contact
enter) and after (where the whole model's self-contact, each node a slave against the other wall, stands in for
the plane). Numbers: docs/verification.md, section "Self-contact: the crushed tube".
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from covcontact.io.loader import load_problem

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "contact"
T = 0.1  # wall thickness


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    out = {}
    for name in ("tube_crush", "tube_crush_half"):
        prob = load_problem(EXAMPLES / f"{name}.toml")
        prob.output.vtu = False
        prob.output.pictures = False
        res = prob.run(out=tmp_path_factory.mktemp(name))
        assert res.exit_code == 0, name
        assert "warnings" not in res.summary, res.summary["warnings"]  # (as tests/test_examples.py asks of examples)
        out[name] = res
    return out


def _curve(res) -> dict[float, float]:
    """Plate force (on the upper plate, y) per load factor of the converged steps."""
    return {round(s["load_factor"], 9): s["contact_force_on"]["upper"][1] for s in res.summary["steps"]
            if s.get("converged") and "contact_force_on" in s}


def test_whole_with_self_contact_equals_half_with_symmetry_plane(runs):
    """The plate force of the whole tube equals the half model's at each of the 40 output load factors the two
    share (automatic increments end there), within 0.5 %. Measured: within 1e-6 relative at every one, from
    0.00234 at 2.5 % of the travel to 92.5 at the end, the inner walls in contact from a travel of 0.93 on (the
    force rising from 1.8 to 92.5 while they flatten)."""
    whole, half = _curve(runs["tube_crush"]), _curve(runs["tube_crush_half"])
    common = sorted(set(whole) & set(half))
    assert len(common) >= 40
    rel = [abs(whole[k] / half[k] - 1.0) for k in common]
    assert max(rel) < 5e-3, max(rel)
    last = runs["tube_crush"].summary["steps"][-1]
    assert last["load_factor"] == pytest.approx(1.0)
    assert last["pairs"]["inner"]["active_contacts"] > 100  # the inner walls touch over most of their length
    assert whole[common[-1]] > 20 * whole[min(k for k in common if k >= 0.9)]  # and carry the crush


def test_walls_do_not_pass_through_each_other(runs):
    """The inner walls overlap by at most what the penalty allows: less than 5 % of the wall thickness at the
    end (the largest force). The walls keep their thickness: no node of the upper wall's inner surface lies below
    the lower wall's inner surface at the same x (to that overlap)."""
    res = runs["tube_crush"]
    last = res.summary["steps"][-1]
    assert last["pairs"]["inner"]["min_gap"] > -0.05 * T
    model = res.model
    x = model.positions(res.u)
    p = next(q for q in model.contact.passes if q.pair == "inner")
    xs = x[p.slaves]
    s = res.state.contact.passes[model.contact.passes.index(p)]
    act = model.contact.active_mask(model.contact.passes.index(p), res.state.contact)
    top = act & (xs[:, 1] > 0)
    assert top.sum() > 20
    assert xs[top, 1].min() > -0.05 * T
    assert np.all(np.isfinite(s.gap[act]))


def test_strip_folded_onto_itself(tmp_path):
    """examples/contact/strip_fold.toml: a strip folded by 180 degrees onto itself, then squeezed by a pressure
    on the outside of the fold. Self-contact keeps the halves apart: at the end they touch over a stretch
    (active slaves) and every node of the folded half's top face lies above the other half's top face at the same
    x, to 5 % of the thickness. Measured: 12 active, the largest overlap 7e-4 (0.7 % of t), 67 increments; with
    the pair switched off the halves pass through each other by 0.096 (96 % of t)."""
    prob = load_problem(EXAMPLES / "strip_fold.toml")
    prob.output.vtu = False
    prob.output.pictures = False
    res = prob.run(out=tmp_path)
    assert res.exit_code == 0
    last = res.summary["steps"][-1]
    assert last["load_factor"] == pytest.approx(1.0) and last["stage"] == "squeeze"
    assert last["pairs"]["fold"]["active_contacts"] >= 6
    t = 0.1
    assert last["pairs"]["fold"]["min_gap"] > -0.05 * t
    model = res.model
    x = model.positions(res.u)
    X = prob.bodies[0].mesh.points
    top = prob.bodies[0].mesh.node_sets["ymax"]
    lower = top[X[top, 0] < 1.5]
    upper = top[X[top, 0] > 2.5]
    order = np.argsort(x[lower, 0])
    y_lower = np.interp(x[upper, 0], x[lower, 0][order], x[lower, 1][order])
    over = x[upper, 0] < x[lower, 0].max()
    assert over.sum() > 10  # the folded half lies over the other
    assert np.all(x[upper, 1][over] >= y_lower[over] - 0.05 * t)


def test_segment_to_surface_on_nodal_gaps_crushes_as_node_to_surface(runs, tmp_path):
    """The half tube with both pairs segment-to-surface on nodal gaps (gap = "nodal", docs/theory.md section 16):
    against the flat plate and symmetry plane the nodes' weighted gaps are their own gaps, so the plate force equals
    node-to-surface's at every output (measured: to 1e-9 relative), and the increments stay within 1.5x of
    node-to-surface's (measured: 108 against 107; segment-to-surface on the points' gaps takes 364, its active set
    cycling where the flattened wall hovers over the plate, docs/performance.md)."""
    prob = load_problem(EXAMPLES / "tube_crush_half.toml")
    for pair in prob.contacts:
        pair.type, pair.gap = "sts", "nodal"
    prob.output.vtu = False
    prob.output.pictures = False
    res = prob.run(out=tmp_path)
    assert res.exit_code == 0
    nodal, half = _curve(res), _curve(runs["tube_crush_half"])
    common = sorted(set(nodal) & set(half))
    assert len(common) >= 40
    assert max(abs(nodal[k] / half[k] - 1.0) for k in common) < 1e-6
    assert len(res.summary["steps"]) <= 1.5 * len(runs["tube_crush_half"].summary["steps"])
