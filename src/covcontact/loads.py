"""Boundary conditions and loads on the node and face sets of deformable bodies: the types the problem
description (``covcontact.problem``) holds and the assembly (``covcontact.assembly``) turns into vectors."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .motion import RigidMotion


@dataclass
class Dirichlet:
    """Prescribed displacement u_i = lam * value_i on the nodes of ``body``'s node set ``set``.

    With ``motion`` the node set moves rigidly instead, u = motion(X, lam) - X on the given components
    (``values`` unused). ``name`` lets later stages give new targets or release the condition.
    """

    body: str
    set: str
    components: tuple[int, ...]
    values: tuple[float, ...]
    name: str = ""
    motion: RigidMotion | None = None
    #: the stage from which the condition holds (None: from the start); its dofs are free before, and in that stage
    #: they go from the displacement they have when it starts to ``values`` (or, ``held``, keep it)
    stage: str | None = None
    held: bool = False


@dataclass
class Equation:
    """A linear multi-point constraint sum_k c_k u(node_k, component_k) = lam * value (docs/theory.md, "Multi-point
    constraints"): ``terms`` are (body, node set of one node, component 0..2, coefficient c_k); the first term's
    dof is the dependent one, eliminated in favour of the others. The right-hand side goes from 0 to ``value`` over
    the first stage (stage targets move it on, as a Dirichlet condition's)."""

    terms: list[tuple[str, str, int, float]]
    name: str = ""
    value: float = 0.0


#: the kinds of nonlinear multi-point constraints (``MPC``), and how many defining nodes each takes before the
#: constrained ones
KINDS = {"plane": 3, "straight": 2, "beam": 2}


def dependent_components(kind: str, X: np.ndarray) -> list[tuple[int, int]]:
    """The dependent dofs (node index within the constraint's nodes, component) of one constraint of ``kind`` whose
    nodes' reference positions are ``X`` (defining nodes first, then one constrained node; beam: the two)."""
    if kind == "plane":
        n = np.cross(X[0] - X[2], X[1] - X[2])
        return [(3, int(np.argmax(np.abs(n))))]
    k = int(np.argmax(np.abs(X[0] - X[1])))
    if kind == "straight":
        return [(2, j) for j in range(3) if j != k]
    return [(0, k)]


def degenerate(kind: str, X: np.ndarray) -> bool:
    """Whether the defining nodes define nothing: a plane's three on a line, a line's two (or a beam's) at one point."""
    scale = max(1.0, float(np.abs(X).max()))
    if kind == "plane":
        return float(np.linalg.norm(np.cross(X[1] - X[0], X[2] - X[0]))) <= 1e-12 * scale ** 2
    return float(np.linalg.norm(X[1] - X[0])) <= 1e-12 * scale


@dataclass
class MPC:
    """A nonlinear multi-point constraint (docs/theory.md, "Nonlinear multi-point constraints"): ``kind`` "plane"
    (the nodes after the first three stay in the plane of those three), "straight" (the nodes after the first two
    stay on their line) or "beam" (two nodes keep their distance); ``nodes`` (body, node set): the defining nodes'
    sets of one node each first, then sets of any number of constrained nodes (a beam: the two nodes' sets)."""

    kind: str
    nodes: list[tuple[str, str]]
    name: str = ""


@dataclass
class NodalForce:
    """Force ``lam * value`` on every node of a node set (``per_node``) or spread evenly (``total``)."""

    body: str
    set: str
    value: tuple[float, float, float]
    distribution: str = "per_node"
    name: str = ""


@dataclass
class Pressure:
    """Pressure ``lam * value`` on a face set (positive pushes against the outward normal): dead (on the reference
    faces, nodal forces fixed) or, with ``follower``, on the current faces (``covcontact.elements.follower``)."""

    body: str
    set: str
    value: float
    name: str = ""
    follower: bool = False
    #: (c, gx, gy, gz): the pressure at a point of the faces is value (c + g . X), X its reference position (None:
    #: value everywhere)
    profile: tuple[float, float, float, float] | None = None


@dataclass
class BodyForce:
    """Dead body force ``lam * value`` on the cells of ``body`` (of its element set ``cells``, "" all of them): per unit
    reference volume, or (``per_mass``) an acceleration times the material's density (a weight on part of a body).

    With ``axis`` it is the centrifugal load of a spin about the axis through ``center``: the acceleration
    omega^2 (X - c)_perp times the density at the reference positions X, ``value[0]`` = omega^2 (the ramped quantity)."""

    body: str
    cells: str
    value: tuple[float, float, float]
    name: str = ""
    per_mass: bool = False
    axis: tuple[float, float, float] | None = None
    center: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass
class Traction:
    """Dead traction ``lam * value`` (force per reference area) on a face set."""

    body: str
    set: str
    value: tuple[float, float, float]
    name: str = ""
