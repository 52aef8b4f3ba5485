"""Rigid bodies with a reference node: six unknowns (translation t, rotation vector theta) in the system.

A rigid body whose motion is not entirely prescribed moves as

    y(X) = p + R(theta) (X - X_ref),    p = X_ref + t,

with X_ref its reference point. Its unknowns live on two extra nodes of the global numbering (docs/theory.md
section 14): node A carries t (so its position X_ref + t is the reference point's), node B carries theta
(its reference position is 0). The contact elements are computed as for any rigid body, at the current pose;
their rows and columns of rigid nodes are then mapped onto A and B by the chain rule:

- a node of a rigid mesh: delta y = delta t - [R Y]_x T(theta) delta theta (R Y = y - p), so the element
  residual f_a adds f_a to A and T^T (R Y x f_a) to B, and the tangent gets P^T K P plus the geometric part
  T^T [f_a]_x [R Y]_x T + d(T^T m)/d theta (m = sum R Y x f_a);
- an analytic surface: the slave's force f(z) depends on its position relative to the body,
  z = R^T (x_s - p) + X_ref; with d = x_s - p, df = K dx_s - K dt + (K [d]_x - [f]_x) T dtheta, and the body
  takes -f and the moment -d x f.

T(theta) = I + (1 - cos t)/t^2 [theta]_x + (t - sin t)/t^3 [theta]_x^2 maps delta theta to the spatial
rotation increment (delta R R^T = [T delta theta]_x); d(T^T v)/d theta is evaluated by a complex step (exact
to round-off).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..motion import rotation_matrix


def skew(v: np.ndarray) -> np.ndarray:
    """[v]_x for (..., 3) vectors: (..., 3, 3)."""
    v = np.asarray(v)
    out = np.zeros(v.shape[:-1] + (3, 3), dtype=v.dtype)
    out[..., 0, 1], out[..., 0, 2] = -v[..., 2], v[..., 1]
    out[..., 1, 0], out[..., 1, 2] = v[..., 2], -v[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -v[..., 1], v[..., 0]
    return out


def tangent_map(theta: np.ndarray) -> np.ndarray:
    """T(theta): delta R R^T = [T(theta) delta theta]_x (real or complex theta)."""
    theta = np.asarray(theta)
    K = skew(theta)
    t2 = theta @ theta
    if abs(t2) < 1e-6:  # series of (1 - cos t)/t^2 and (t - sin t)/t^3
        a = 0.5 - t2 / 24.0 + t2 * t2 / 720.0
        b = 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0
    else:
        t = np.sqrt(t2)
        a = (1.0 - np.cos(t)) / t2
        b = (t - np.sin(t)) / (t2 * t)
    return np.eye(3) + a * K + b * (K @ K)


def tangent_map_derivatives(theta: np.ndarray) -> np.ndarray:
    """D (3, 3, 3) with D[i] = d(T(theta)^T e_i)/d theta, by complex steps: d(T^T v)/d theta = v_i D[i] is
    linear in v, so one evaluation serves every v."""
    h = 1e-30
    out = np.zeros((3, 3, 3))
    for k in range(3):
        th = np.asarray(theta, dtype=complex).copy()
        th[k] += 1j * h
        out[:, :, k] = tangent_map(th).imag / h   # (T^T e_i)_j = T_ij
    return out


def tangent_map_derivative(theta: np.ndarray, v: np.ndarray) -> np.ndarray:
    """d(T(theta)^T v)/d theta for a fixed v: (3, 3)."""
    return np.einsum("i,ijk->jk", np.asarray(v, dtype=np.float64), tangent_map_derivatives(theta))


def rotation_vector(Rm: np.ndarray) -> np.ndarray:
    """The rotation vector of a rotation matrix (angle below pi)."""
    from scipy.spatial.transform import Rotation

    return Rotation.from_matrix(Rm).as_rotvec()


@dataclass
class Pose:
    """The current pose of a reference body, with the interface of ``RigidMotion`` (load factor ignored)."""

    origin: np.ndarray   # X_ref
    p: np.ndarray        # current reference point
    theta: np.ndarray    # rotation vector

    def __post_init__(self):
        self.R = rotation_matrix(self.theta)
        self.center = self.p

    def matrix(self, lam: float = 1.0) -> np.ndarray:
        return self.R

    def apply(self, X, lam: float = 1.0) -> np.ndarray:
        return self.p + (np.asarray(X, dtype=np.float64) - self.origin) @ self.R.T

    def rotate(self, V, lam: float = 1.0) -> np.ndarray:
        return np.asarray(V, dtype=np.float64) @ self.R.T

    def pose(self, lam: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
        return self.R, self.apply(np.zeros(3))


@dataclass
class ReferenceBody:
    """A rigid body's reference node pair in the global numbering."""

    name: str
    A: int                 # node carrying t
    B: int                 # node carrying theta
    origin: np.ndarray     # X_ref
    free: tuple[int, ...]  # free components 0..5 (x, y, z, rx, ry, rz)
    force: np.ndarray      # applied force at load factor 1
    moment: np.ndarray     # applied moment (about the reference point) at load factor 1
    mass: float = 0.0      # dynamics and gravity: the body's mass (on A)
    inertia: np.ndarray = field(default_factory=lambda: np.zeros(3))  # principal moments about X_ref (on B)
    #: global ids of the deformable nodes attached to the body (``covcontact.solvers.constraints.RigidLinks``)
    attached: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    #: the components (0..2) of the attached nodes that follow the body (the others stay free)
    attached_components: tuple = (0, 1, 2)

    def pose(self, x: np.ndarray) -> Pose:
        """The pose at the system positions x (N, 3): A's position is p, B's is theta."""
        return Pose(self.origin, x[self.A].copy(), x[self.B].copy())


def map_rigid_nodes(conn: np.ndarray, R: np.ndarray, K: np.ndarray | None, owner: np.ndarray,
                    bodies: list[ReferenceBody], poses: list[Pose], x_ext: np.ndarray):
    """Element blocks whose nodes include nodes of reference bodies, mapped onto the bodies' A and B nodes.

    conn (m, n) extended node ids, R (m, 3n), K (m, 3n, 3n) or None; owner (n_ext,) the reference body
    index of every extended node (-1: none). Returns a list of (conn, R, K) blocks (rows grouped by which
    columns belong to which body).
    """
    sig = owner[conn]
    if not (sig >= 0).any():
        return [(conn, R, K)]
    out = []
    groups, inverse = np.unique(sig, axis=0, return_inverse=True)
    for g, row_sig in enumerate(groups):
        rows = np.flatnonzero(inverse.ravel() == g)
        c, r = conn[rows], R[rows]
        k = K[rows] if K is not None else None
        keep = np.flatnonzero(row_sig < 0)
        involved = sorted(set(row_sig[row_sig >= 0].tolist()))
        m, n = c.shape
        n_new = len(keep) + 2 * len(involved)
        P = np.zeros((m, 3 * n, 3 * n_new))
        new_conn = np.zeros((m, n_new), dtype=np.int64)
        for j, col in enumerate(keep):
            new_conn[:, j] = c[:, col]
            P[:, 3 * col: 3 * col + 3, 3 * j: 3 * j + 3] = np.eye(3)
        G = np.zeros((m, 3 * n_new, 3 * n_new))
        for q, b in enumerate(involved):
            body, pose = bodies[b], poses[b]
            ja, jb = len(keep) + 2 * q, len(keep) + 2 * q + 1
            new_conn[:, ja], new_conn[:, jb] = body.A, body.B
            T = tangent_map(pose.theta)
            mom = np.zeros((m, 3))
            for col in np.flatnonzero(row_sig == b):
                ry = x_ext[c[:, col]] - pose.p              # R Y, (m, 3)
                fa = r[:, 3 * col: 3 * col + 3]
                P[:, 3 * col: 3 * col + 3, 3 * ja: 3 * ja + 3] = np.eye(3)
                P[:, 3 * col: 3 * col + 3, 3 * jb: 3 * jb + 3] = -skew(ry) @ T
                if k is not None:
                    G[:, 3 * jb: 3 * jb + 3, 3 * jb: 3 * jb + 3] += T.T @ skew(fa) @ skew(ry) @ T
                mom += np.cross(ry, fa)
            if k is not None:
                G[:, 3 * jb: 3 * jb + 3, 3 * jb: 3 * jb + 3] += np.einsum(
                    "mi,ijk->mjk", mom, tangent_map_derivatives(pose.theta))
        r_new = np.einsum("mij,mi->mj", P, r)
        k_new = None if k is None else np.einsum("mia,mij,mjb->mab", P, k, P) + G
        out.append((new_conn, r_new, k_new))
    return out


def map_analytic(slaves: np.ndarray, xs: np.ndarray, f: np.ndarray, K: np.ndarray | None, body: ReferenceBody,
                 pose: Pose):
    """The blocks (slave, A, B) of slaves against an analytic surface carried by a reference body.

    f (m, 3) the force residual on each slave, K (m, 3, 3) its derivative at the fixed pose.
    """
    m = len(slaves)
    T = tangent_map(pose.theta)
    d = xs - pose.p
    conn = np.stack([slaves, np.full(m, body.A), np.full(m, body.B)], axis=1)
    mom = np.cross(d, f)
    r = np.hstack([f, -f, -(mom @ T)])  # T^T (d x f) = (d x f) T
    if K is None:
        return conn, r, None
    Sd, Sf = skew(d), skew(f)
    dfdth = (K @ Sd - Sf) @ T                                    # (m, 3, 3)
    Jf = np.concatenate([K, -K, dfdth], axis=2)                  # df / d(x_s, t, theta)
    Kn = np.zeros((m, 9, 9))
    Kn[:, 0:3] = Jf
    Kn[:, 3:6] = -Jf
    # r_theta = -T^T (d x f): d(d x f) = -[f]_x (dx_s - dt) + [d]_x df
    dd = np.zeros((m, 3, 9))
    dd[:, :, 0:3] = np.eye(3)
    dd[:, :, 3:6] = -np.eye(3)
    dmom = -Sf @ dd + Sd @ Jf
    Kn[:, 6:9] = -np.einsum("ji,mjk->mik", T, dmom)
    Kn[:, 6:9, 6:9] -= np.einsum("mi,ijk->mjk", mom, tangent_map_derivatives(pose.theta))
    return conn, r, Kn


def load_block(body: ReferenceBody, pose: Pose, lam_force: np.ndarray, lam_moment: np.ndarray, want_K: bool):
    """The applied force and moment as a residual block on (A, B): -F on t, -T^T M on theta."""
    T = tangent_map(pose.theta)
    r = np.concatenate([-lam_force, -(T.T @ lam_moment)])[None, :]
    K = None
    if want_K:
        K = np.zeros((1, 6, 6))
        K[0, 3:6, 3:6] = -tangent_map_derivative(pose.theta, lam_moment)
    return np.array([[body.A, body.B]]), r, K
