"""Tool profiles of lines and arcs (docs/theory.md section 5): construction, geometry against the plane and
cylinder they are made of, continuity across joints, sharp corners, the pole of a revolved profile, the
orientation rules and bad input."""

import numpy as np
import pytest

from covcontact.contact import Cylinder, Plane, Profile
from covcontact.contact.profile import ARC, LINE, SHARP, build_profile

EPS = 50.0


def punch(fillet=5.0):
    """The U-channel punch drawn in (x, z), extruded along y: wall, corner, bottom to the symmetry plane."""
    return Profile([(35.0, 60.0), (35.0, 0.0), (0.0, 0.0)], [fillet], extrude={"axis": (0, 1, 0),
                                                                             "origin": (0.0, 0.0, 0.782)})


def fd_tangent(surf, x, h=1e-6):
    K = np.zeros((3, 3))
    for j in range(3):
        xp, xm = x.copy(), x.copy()
        xp[j] += h
        xm[j] -= h
        K[:, j] = (surf.contact(xp, EPS, "exact").residual - surf.contact(xm, EPS, "exact").residual) / (2 * h)
    return K


def test_fillet_table():
    prof = build_profile([(0.0, 0.0), (10.0, 0.0), (10.0, 10.0)], [2.0])
    assert prof[:, 0].tolist() == [LINE, ARC, LINE]
    np.testing.assert_allclose(prof[:, 2][:2], [8.0, np.pi])  # the arc: a quarter circle of radius 2
    assert prof[1, 2] == pytest.approx(0.5 * np.pi * 2.0)
    np.testing.assert_allclose(prof[1, 3:5], [8.0, 2.0])  # centre on the left of the walk (a left turn)
    assert prof[0, 10] == -np.inf and prof[-1, 11] == np.inf  # open ends extend
    np.testing.assert_allclose(prof[:, 1], [0.0, 8.0, 8.0 + np.pi])


@pytest.mark.parametrize("x", [[33.0, 1.0, 2.5], [34.5, 7.0, 4.0], [31.0, -2.0, 1.0], [32.0, 3.0, 0.5]])
def test_arc_is_the_cylinder(x):
    """On the corner the profile is the cylinder it replaces: gap, normal, normalised curvature, tangent of
    every case."""
    x = np.array(x)
    P, C = punch(), Cylinder((30.0, 0.0, 5.782), (0, 1, 0), 5.0)
    p, c = P.project(x), C.project(x)
    assert p.gap == pytest.approx(c.gap, abs=1e-12)
    np.testing.assert_allclose(p.normal, c.normal, atol=1e-12)
    assert p.h_cov[0, 0] / p.a_cov[0, 0] == pytest.approx(c.h_cov[0, 0] / c.a_cov[0, 0])
    for case in ("a", "b", "exact"):
        np.testing.assert_allclose(P.contact(x, EPS, case).tangent, C.contact(x, EPS, case).tangent,
                                   atol=1e-11 * EPS)


def test_flat_is_the_plane():
    x = np.array([12.0, 4.0, 0.9])
    P, Q = punch(), Plane((0.0, 0.0, 0.782), (0.0, 0.0, -1.0))
    p, q = P.project(x), Q.project(x)
    assert p.gap == pytest.approx(q.gap) and p.gap < 0
    np.testing.assert_allclose(p.normal, q.normal, atol=1e-15)
    np.testing.assert_allclose(P.contact(x, EPS, "exact").tangent, Q.contact(x, EPS, "exact").tangent,
                               atol=1e-12)


def test_normal_continuous_across_joints():
    """The tangent-continuous profile has a continuous gap and normal across its joints: along lines 0.3 mm
    inside the punch crossing the bottom-corner joint (x = 30) and the corner-wall joint (z = 5.782)."""
    P = punch()
    for line in (np.column_stack([np.linspace(25.0, 33.0, 801), np.full(801, 2.0), np.full(801, 1.082)]),
                 np.column_stack([np.full(801, 34.7), np.full(801, 2.0), np.linspace(3.0, 9.0, 801)])):
        pr = [P.project(x) for x in line]
        n = np.array([p.normal for p in pr])
        g = np.array([p.gap for p in pr])
        step = np.linalg.norm(line[1] - line[0])
        assert np.abs(np.diff(n, axis=0)).max() < 2.0 * step / (5.0 - 0.3)  # at most the arc's turning
        assert np.abs(np.diff(g)).max() <= step * (1 + 1e-9)
        assert {int(np.searchsorted(P.prof[:, 1], p.xi[0], side="right")) - 1 for p in pr} >= {1}


def test_sharp_corner_is_a_vertex():
    """A corner without fillet: the closest point is the corner, the normal points from it to the slave, and
    the exact tangent is that of a vertex, eps (n n + g_e / g t t) in the profile's plane."""
    P = punch(0.0)
    assert P.prof[1, 0] == ARC and P.prof[1, 7] == pytest.approx(SHARP * (60.0 + 35.0))
    corner = np.array([35.0, 0.0, 0.782])
    d = np.array([0.6, 0.0, -0.8])
    x = corner + 0.2 * d + np.array([0, 3.0, 0])
    pr = P.project(x)
    assert pr.gap == pytest.approx(0.2, rel=1e-6)
    np.testing.assert_allclose(pr.normal, d, atol=1e-6)
    # inside the tool (a slave pressed onto the corner region from outside, now 0.05 deep across the wall)
    y = np.array([34.97, 1.0, 0.79])
    r = P.contact(y, EPS, "exact")
    assert r.gap < 0
    K = fd_tangent(P, y)
    assert np.linalg.norm(r.tangent - K) < 1e-6 * np.linalg.norm(K)
    # cases a and c take the vertex's stiffness as their curvature part: equal to the exact tangent there
    for case in ("a", "c"):
        np.testing.assert_allclose(P.contact(y, EPS, case).tangent, r.tangent, rtol=1e-12)
    np.testing.assert_allclose(sum(r.parts.values()), r.tangent, atol=1e-12 * EPS)
    assert not np.any(r.parts["second_order"])


def test_revolved_pole_is_umbilic():
    """A revolved profile reaching the axis perpendicularly: on the axis the metric stays regular and the
    surface's curvature is the meridian's in every direction (a spherical cap of radius 4 here)."""
    R = 4.0
    # a cap: quarter arc from the pole down to the equator, drawn as a polyline with one big fillet
    cap = Profile([(0.0, R), (R, R), (R, -1.0)], [R], revolve={"axis": (0, 0, 1), "center": (0, 0, 0)})
    sph_c = np.array([0.0, 0.0, 0.0])
    for x in ([0.0, 0.0, R - 0.1], [1e-12, 0.0, R - 0.1], [0.5, 0.3, R - 0.2]):
        x = np.array(x)
        pr = cap.project(x)
        assert pr.gap == pytest.approx(np.linalg.norm(x - sph_c) - R, abs=1e-9)
        assert np.linalg.cond(pr.a_cov) < 1e3 or pr.a_cov[1, 1] > 0
        kap = np.linalg.solve(pr.a_cov, pr.h_cov)
        np.testing.assert_allclose(np.diag(kap), [-1.0 / R, -1.0 / R], rtol=1e-6)
        r = cap.contact(x, EPS, "exact")
        K = fd_tangent(cap, x, 1e-7)
        assert np.linalg.norm(r.tangent - K) < 1e-6 * np.linalg.norm(K)


def test_mirrored_drawing_keeps_its_side():
    """The same punch drawn in (x, z) along +y (a left-handed plane) and along -y (right-handed): one
    surface."""
    a = punch()
    b = Profile([(35.0, 60.0), (35.0, 0.0), (0.0, 0.0)], [5.0], extrude={"axis": (0, -1, 0),
                                                                       "origin": (0.0, 0.0, 0.782)})
    rng = np.random.default_rng(3)
    for _ in range(20):
        x = rng.uniform([0, -5, -2], [45, 5, 10])
        pa, pb = a.project(x), b.project(x)
        assert pa.gap == pytest.approx(pb.gap, abs=1e-12)
        np.testing.assert_allclose(pa.normal, pb.normal, atol=1e-12)
        np.testing.assert_allclose(np.cross(*pa.rho_cov) / np.linalg.norm(np.cross(*pa.rho_cov)), pa.normal,
                                   atol=1e-12)
    # below the punch's bottom is outside (positive gap), above it inside
    assert a.project(np.array([10.0, 0.0, 0.5])).gap > 0 > a.project(np.array([10.0, 0.0, 1.0])).gap


@pytest.mark.parametrize("points,fillets,match", [
    ([(0, 0)], None, "at least 2"),
    ([(0, 0), (0, 0), (1, 1)], [0.0], "coincide"),
    ([(0, 0), (1, 0), (0, 0.0)], [0.0], "turns back"),
    ([(0, 0), (1, 0), (1, 1)], [5.0], "reduce the radii"),
    ([(0, 0), (1, 0), (1, 1)], [1.0, 2.0], "one per interior corner"),
    ([(0, 0), (1, 0), (1, 1)], [-1.0], "one per interior corner"),
])
def test_bad_profiles(points, fillets, match):
    with pytest.raises(ValueError, match=match):
        build_profile(points, fillets)


def test_bad_placement():
    with pytest.raises(ValueError, match="either extrude"):
        Profile([(0, 0), (1, 0)])
    with pytest.raises(ValueError, match="extrude.u"):
        Profile([(0, 0), (1, 0)], extrude={"axis": (1, 1, 0)})
    with pytest.raises(ValueError, match="perpendicular"):
        Profile([(0, 0), (1, 0)], extrude={"axis": (0, 0, 1), "u": (0, 0.5, 1)})
    with pytest.raises(ValueError, match="must not be negative"):
        Profile([(-1, 0), (1, 0)], revolve={"axis": (0, 0, 1)})


def test_friction_on_the_axis_of_a_revolved_profile():
    """A slave node on the axis of a revolved tool (the axis node of an axisymmetric blank under a flat punch):
    no angle coordinate there, so it takes the normal force only (zero tangential force, as symmetry gives
    it) with a finite tangent; just off the axis friction acts again."""
    from covcontact.contact.friction import OPEN, SLIP, STICK, surface_friction

    punch = Profile([(0.0, 0.0), (20.0, 0.0), (20.0, -30.0)], [4.0], revolve={"axis": (0, 0, 1)})
    on = np.array([0.0, 0.0, -0.3])
    hist = surface_friction(punch, on + [0.01, 0.0, 0.0], EPS, 50.0, 0.3).history
    r = surface_friction(punch, on, EPS, 50.0, 0.3, hist)
    assert r.state == SLIP and np.all(np.isfinite(r.tangent))
    np.testing.assert_allclose(r.residual, [0.0, 0.0, -0.3 * EPS], atol=1e-12)
    assert not np.any(r.history)
    assert surface_friction(punch, on + [0.0, 0.0, 0.6], EPS, 50.0, 0.3).state == OPEN
    off = surface_friction(punch, np.array([1e-3, 0.0, -0.3]), EPS, 50.0, 0.3, hist)
    assert off.state == STICK and abs(off.residual[0]) > 0.1
