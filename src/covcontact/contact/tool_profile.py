"""Rigid tool profiles as analytic surfaces (docs/input.md, "Profiles"; docs/theory.md section 5): the
segment table of ``profile.build_profile`` placed by an extrusion or a revolution and moved by a motion;
the compiled geometry is ``analytic.analytic_geometry``'s EXTRUDED and REVOLVED branches."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from covcontact.contact.analytic import EXTRUDED, REVOLVED, _Analytic
from covcontact.contact.profile import build_profile
from covcontact.motion import RigidMotion, unit_vector


def _axis_pair(e3: np.ndarray, u, v) -> tuple[np.ndarray, np.ndarray]:
    """The profile plane's directions (u, v) for extrusion along e3: the given ones, or for an axis along x,
    y or z the other two coordinate axes in order (y, z / x, z / x, y)."""
    axes = np.eye(3)
    along = [i for i in range(3) if abs(abs(e3[i]) - 1.0) < 1e-12]
    others = [i for i in range(3) if along and i != along[0]]
    if u is None and not along:
        raise ValueError("extrude.u: needed for an axis that is not along x, y or z (the direction of the "
                         "profile's first coordinate)")
    uu = axes[others[0]] if u is None else unit_vector(u, "extrude.u")
    if abs(uu @ e3) > 1e-9:
        raise ValueError("extrude.u: must be perpendicular to extrude.axis")
    if v is None:
        v = axes[others[1]] if u is None else np.cross(e3, uu)
    vv = unit_vector(v, "extrude.v")
    if abs(vv @ e3) > 1e-9 or abs(vv @ uu) > 1e-9:
        raise ValueError("extrude.v: must be perpendicular to extrude.axis and to extrude.u")
    return uu, vv


@dataclass
class Profile(_Analytic):
    """Rigid surface swept by a 2D ``points`` polyline with ``fillets`` (``profile.build_profile``).

    extrude = {axis, origin, u, v}: the profile's (p, q) at origin + p u + q v, swept along axis (u, v
    default to the other two coordinate axes of an axis along x, y or z). revolve = {axis, center}: (p, q) =
    (distance from the axis, position along it from center), revolved about the axis. The contact side lies
    on the left when walking along the points (p to the right, q up).
    """

    points: tuple | np.ndarray = ((0.0, 0.0), (1.0, 0.0))
    fillets: tuple | np.ndarray | None = None
    extrude: dict | None = None
    revolve: dict | None = None
    motion: RigidMotion = field(default_factory=RigidMotion)

    def __post_init__(self):
        if (self.extrude is None) == (self.revolve is None):
            raise ValueError("give either extrude = {axis, origin} or revolve = {axis, center}")
        pts = np.asarray(self.points, dtype=np.float64)
        fil = None if self.fillets is None else np.asarray(self.fillets, dtype=np.float64)
        if self.extrude is not None:
            ex = dict(self.extrude)
            e3 = unit_vector(ex.get("axis"), "extrude.axis")
            u, v = _axis_pair(e3, ex.get("u"), ex.get("v"))
            self._place(EXTRUDED, ex.get("origin", (0.0, 0.0, 0.0)), "extrude.origin")
            e2 = np.cross(e3, u)
            hand = 1.0 if v @ e2 > 0.0 else -1.0
            self._frame = np.ascontiguousarray(np.vstack([u, e2, e3]))
            if pts.ndim == 2 and pts.shape[1:] == (2,):
                pts = pts * np.array([1.0, hand])
                if hand < 0.0:  # the mirrored drawing keeps its contact side by walking it backwards
                    pts = pts[::-1]
                    fil = None if fil is None else fil[::-1]
        else:
            rv = dict(self.revolve)
            self._place(REVOLVED, rv.get("center", (0.0, 0.0, 0.0)), "revolve.center", rv.get("axis"),
                        "revolve.axis")
            if pts.ndim == 2 and pts.shape[1:] == (2,) and np.any(pts[:, 0] < 0.0):
                raise ValueError("points: the first coordinate of a revolved profile is the distance from the "
                                 "axis and must not be negative")
        self.prof = build_profile(pts, fil, axis_ends=self.revolve is not None)
