"""Prescribed rigid-body motion (of a rigid body or a node set), scaled by a load factor.

    x(lam) = c + R(lam theta) (X - c) + lam T

with R the rotation by the rotation vector lam theta (Rodrigues' formula) about the centre c. In a later
stage of an analysis a motion continues from the pose the earlier stages left (:class:`StagedMotion`): composed onto
it (the stage's rotation acts on the current positions), or, with ``total``, as the body's total rotation vector and
displacement, reached linearly from the values the stage starts with (CalculiX's meaning of a prescribed rotation
vector on a rotational node).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def _vec3(v, what):
    a = np.asarray(v, dtype=np.float64)
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise ValueError(f"{what} must be 3 finite numbers, got {v!r}")
    return a


def rotation_vector_near(Rm: np.ndarray, guess) -> np.ndarray:
    """The rotation vector of the rotation matrix ``Rm`` nearest to ``guess``: of the vectors n (phi + 2 pi k) that
    give it (n, phi the axis and angle of the principal one), the one closest to ``guess`` (the principal one,
    angle up to pi, for a guess of zero)."""
    from scipy.spatial.transform import Rotation

    g = np.asarray(guess, dtype=np.float64)
    r = Rotation.from_matrix(np.asarray(Rm, dtype=np.float64)).as_rotvec()
    phi = float(np.linalg.norm(r))
    if phi < 1e-12:  # the identity: 2 pi k along the guess
        ng = float(np.linalg.norm(g))
        k = round(ng / (2.0 * np.pi))
        return g * (2.0 * np.pi * k / ng) if k else np.zeros(3)
    n = r / phi
    k = round((float(n @ g) - phi) / (2.0 * np.pi))
    return n * (phi + 2.0 * np.pi * k)


def rotation_matrix(theta) -> np.ndarray:
    """Rotation matrix of the rotation vector ``theta`` (axis * angle in radians), Rodrigues."""
    w = np.asarray(theta, dtype=np.float64)
    t = float(np.linalg.norm(w))
    K = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
    if t < 1e-8:  # series: sin t / t = 1 - t^2/6, (1 - cos t) / t^2 = 1/2 - t^2/24
        return np.eye(3) + (1.0 - t * t / 6.0) * K + (0.5 - t * t / 24.0) * (K @ K)
    return np.eye(3) + (np.sin(t) / t) * K + ((1.0 - np.cos(t)) / (t * t)) * (K @ K)


@dataclass
class RigidMotion:
    """Rigid motion: translation T, rotation vector theta (radians) about ``center``.

    Attributes:
        translation: (3,) translation at lam = 1.
        rotation: (3,) rotation vector at lam = 1 (axis times angle).
        center: (3,) centre of rotation.
        path: optional (k, 4) rows (lam, tx, ty, tz), lam strictly increasing from 0: the translation
            follows this polyline in the load factor (constant beyond the last row) instead of
            lam * translation (which must then be zero), e.g. press down, then slide.
        total: in a later stage (:class:`StagedMotion`), ``rotation`` is the body's total rotation vector and
            ``translation`` the total displacement of ``center`` (both from the reference configuration) at the
            stage's end, each reached linearly in the load factor from its value at the stage's start (CalculiX's
            meaning of a *BOUNDARY on a rotational node); without it (default) they act on the current positions.
            The same in the first stage.
    """

    translation: tuple | np.ndarray = (0.0, 0.0, 0.0)
    rotation: tuple | np.ndarray = (0.0, 0.0, 0.0)
    center: tuple | np.ndarray = (0.0, 0.0, 0.0)
    path: tuple | np.ndarray | None = None
    total: bool = False

    def __post_init__(self):
        self.translation = _vec3(self.translation, "translation")
        self.rotation = _vec3(self.rotation, "rotation")
        self.center = _vec3(self.center, "center")
        self.total = bool(self.total)
        if self.path is not None and self.total:
            raise ValueError("a total motion gives its end displacement as translation, not as a path")
        if self.path is not None:
            P = np.asarray(self.path, dtype=np.float64)
            if P.ndim != 2 or P.shape[1] != 4 or P.shape[0] < 2 or not np.all(np.isfinite(P)):
                raise ValueError("path must be two or more rows [lam, tx, ty, tz] of finite numbers")
            if P[0, 0] != 0.0 or np.any(np.diff(P[:, 0]) <= 0.0):
                raise ValueError("path load factors must start at 0 and increase strictly")
            if np.any(self.translation != 0.0):
                raise ValueError("give either translation or path, not both")
            self.path = P

    def offset(self, lam: float = 1.0) -> np.ndarray:
        """Translation at load factor ``lam``."""
        if self.path is None:
            return float(lam) * self.translation
        return np.array([np.interp(float(lam), self.path[:, 0], self.path[:, 1 + i]) for i in range(3)])

    def matrix(self, lam: float = 1.0) -> np.ndarray:
        """Rotation matrix R(lam theta)."""
        return rotation_matrix(float(lam) * self.rotation)

    def rotation_vector(self, lam: float = 1.0) -> np.ndarray:
        """The total rotation vector lam theta at load factor ``lam``."""
        return float(lam) * self.rotation

    def state(self, lam: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(Q, b, theta): the pose at ``lam`` and its total rotation vector (where a next stage starts)."""
        return (*self.pose(lam), self.rotation_vector(lam))

    def apply(self, X, lam: float = 1.0) -> np.ndarray:
        """Positions (..., 3) moved to load factor ``lam``."""
        X = np.asarray(X, dtype=np.float64)
        if X.shape[-1] != 3:
            raise ValueError(f"points must have 3 coordinates in the last axis, got shape {X.shape}")
        Rm = self.matrix(lam)
        return self.center + (X - self.center) @ Rm.T + self.offset(lam)

    def rotate(self, V, lam: float = 1.0) -> np.ndarray:
        """Directions (..., 3) rotated to load factor ``lam`` (no translation)."""
        V = np.asarray(V, dtype=np.float64)
        return V @ self.matrix(lam).T

    def pose(self, lam: float) -> tuple[np.ndarray, np.ndarray]:
        """(Q, b): the motion at load factor ``lam`` as the affine map X -> Q X + b."""
        return self.matrix(lam), self.apply(np.zeros(3), lam)


class StagedMotion:
    """A stage's motion continuing from the pose the earlier stages left.

    The pose at the start of the stage is the affine map X -> Q X + b (a rotation Q and a translation b) with the
    total rotation vector theta_0 (R(theta_0) = Q). The stage's own ``RigidMotion`` then either acts on the current
    positions, about the centre the earlier stages carried along (the motion's ``center`` names a point of the body
    in its reference configuration):

        x(lam) = c + R(lam theta)(Q X + b - c) + T(lam),    c = Q center + b,

    or (``motion.total``) gives the total rotation vector theta_1 and displacement d_1 of ``center`` at the stage's
    end, reached linearly from theta_0 and d_0 = Q center + b - center:

        x(lam) = center + d(lam) + R(theta(lam))(X - center),
        theta(lam) = theta_0 + lam (theta_1 - theta_0),    d(lam) = d_0 + lam (d_1 - d_0).

    The two are the same while the rotation keeps its axis. Same interface as ``RigidMotion`` (``apply``,
    ``rotate``, ``matrix``, ``rotation_vector``).
    """

    def __init__(self, motion: RigidMotion, Q: np.ndarray | None = None, b: np.ndarray | None = None,
                 theta: np.ndarray | None = None):
        self.motion = motion
        self.Q = np.eye(3) if Q is None else np.asarray(Q, dtype=np.float64)
        self.b = np.zeros(3) if b is None else np.asarray(b, dtype=np.float64)
        # the total rotation vector at the start (not given: the principal one of Q)
        self.theta0 = rotation_vector_near(self.Q, np.zeros(3)) if theta is None else _vec3(theta, "theta")
        self.center = self.Q @ motion.center + self.b
        self.total = bool(getattr(motion, "total", False))
        if self.total:
            self.d0 = self.center - motion.center

    def start(self, X) -> np.ndarray:
        """Positions (..., 3) at the start of the stage."""
        return np.asarray(X, dtype=np.float64) @ self.Q.T + self.b

    def rotation_vector(self, lam: float = 1.0) -> np.ndarray:
        """The body's total rotation vector at ``lam`` (composed rotations about different axes: the vector of
        R(lam theta) Q nearest to theta_0 + lam theta)."""
        lam = float(lam)
        if self.total:
            return self.theta0 + lam * (self.motion.rotation - self.theta0)
        a = self.motion.rotation
        guess = self.theta0 + lam * a
        if not np.any(np.cross(a, self.theta0)):  # the same axis (or no rotation): exact
            return guess
        return rotation_vector_near(self.matrix(lam), guess)

    def moved_by(self, lam: float = 1.0) -> np.ndarray:
        """How far the centre has moved since the stage's start at ``lam``."""
        if self.total:
            return float(lam) * (self.motion.translation - self.d0)
        return self.motion.offset(lam)

    def _displacement(self, lam: float) -> np.ndarray:
        """(total motions) the displacement of ``center`` at ``lam``."""
        return self.d0 + float(lam) * (self.motion.translation - self.d0)

    def matrix(self, lam: float = 1.0) -> np.ndarray:
        if self.total:
            return rotation_matrix(self.rotation_vector(lam))
        return self.motion.matrix(lam) @ self.Q

    def apply(self, X, lam: float = 1.0) -> np.ndarray:
        X = np.asarray(X, dtype=np.float64)
        if X.shape[-1] != 3:
            raise ValueError(f"points must have 3 coordinates in the last axis, got shape {X.shape}")
        if self.total:
            c0 = self.motion.center
            return c0 + self._displacement(lam) + (X - c0) @ self.matrix(lam).T
        c = self.center
        return c + (self.start(X) - c) @ self.motion.matrix(lam).T + self.motion.offset(lam)

    def rotate(self, V, lam: float = 1.0) -> np.ndarray:
        return np.asarray(V, dtype=np.float64) @ self.matrix(lam).T

    def pose(self, lam: float) -> tuple[np.ndarray, np.ndarray]:
        """(Q, b) of the pose reached at load factor ``lam`` (where the next stage starts)."""
        return self.matrix(lam), self.apply(np.zeros(3), lam)

    def state(self, lam: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(Q, b, theta): the pose at ``lam`` and its total rotation vector (where the next stage starts)."""
        return (*self.pose(lam), self.rotation_vector(lam))

    @classmethod
    def hold(cls, Q: np.ndarray, b: np.ndarray, theta: np.ndarray | None = None) -> "StagedMotion":
        """Standing still at the pose (Q, b) (total rotation vector ``theta``)."""
        return cls(RigidMotion(), Q, b, theta)


def unit_vector(v, what: str) -> np.ndarray:
    """v / |v| for a non-zero finite 3-vector; ValueError naming ``what`` otherwise."""
    a = np.asarray(v, dtype=np.float64)
    nv = np.linalg.norm(a) if a.shape == (3,) else 0.0
    if a.shape != (3,) or not np.isfinite(nv) or nv == 0.0:
        raise ValueError(f"{what} must be a non-zero finite 3-vector, got {v!r}")
    return a / nv


def frame_from_axis(e3: np.ndarray) -> np.ndarray:
    """A right-handed orthonormal frame (rows e1, e2, e3) around the unit vector e3."""
    helper = np.eye(3)[int(np.argmin(np.abs(e3)))]
    e1 = np.cross(helper, e3)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(e3, e1)
    return np.ascontiguousarray(np.vstack([e1, e2, e3]))
