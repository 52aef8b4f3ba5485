"""The Python API: a Problem made of bodies, boundary conditions, loads, contact pairs and steps.

The TOML loader (``covcontact.io.loader``) builds exactly these objects; ``Problem.run`` does what
``covcontact run`` does.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .motion import RigidMotion
from .mesh import Mesh

COMPONENTS = {"x": 0, "y": 1, "z": 2}
TANGENT_CASES = ("a", "b", "c", "d", "exact")


@dataclass
class Body:
    """A deformable body: a mesh, its element formulation and its material."""

    name: str
    mesh: Mesh
    material: Any
    formulation: str = "solid"
    options: dict = field(default_factory=dict)


@dataclass
class RigidBody:
    """A rigid body: an analytic surface or a mesh moving rigidly.

    ``shape`` "plane" (``params`` point, normal), "cylinder" (center, axis, radius, outside) or "sphere"
    (center, radius, outside) for an analytic surface; or ``mesh``, a Mesh whose nodes carry no unknowns
    (slave nodes and/or master faces of contact pairs), with ``shape`` "mesh".

    With ``free`` components the body gets a reference node (six unknowns: translation and rotation vector
    about ``reference``): the free components follow equilibrium under ``force`` / ``moment`` (ramped over
    the first stage, then held) and the contact forces, the others follow ``motion``.
    """

    name: str
    motion: RigidMotion = field(default_factory=RigidMotion)
    mesh: Mesh | None = None
    shape: str = ""
    params: dict = field(default_factory=dict)
    free: tuple[int, ...] = ()          # components left to equilibrium: 0..5 = x, y, z, rx, ry, rz
    force: tuple = (0.0, 0.0, 0.0)      # applied force (at load factor 1 of the first stage)
    moment: tuple = (0.0, 0.0, 0.0)     # applied moment about the reference point
    reference: tuple | None = None      # reference point (default: centre, point, or the mesh's centroid)

    def reference_point(self) -> np.ndarray:
        if self.reference is not None:
            return np.asarray(self.reference, dtype=float)
        if self.mesh is not None:
            return self.mesh.points.mean(axis=0)
        return np.asarray(self.params.get("center", self.params.get("point")), dtype=float)


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
    """Dead pressure ``lam * value`` on a face set (positive pushes against the outward normal)."""

    body: str
    set: str
    value: float
    name: str = ""


@dataclass
class Traction:
    """Dead traction ``lam * value`` (force per reference area) on a face set."""

    body: str
    set: str
    value: tuple[float, float, float]
    name: str = ""


@dataclass
class ContactPair:
    """A node-to-surface contact pair.

    slave: (body name, node set name); the body may be deformable or a rigid meshed body.
    master: (body name, face set name) of a deformable or rigid meshed body, or (rigid body name, "")
    for an analytic surface.
    penalty: eps_N, or "auto" (``auto_factor`` times Young's modulus over the facet size of the master
    body, or of the slave body against a rigid master; times the tributary area for "nodal" weighting).
    method: "penalty", or "augmented" (Uzawa updates of per-node multipliers after each converged step
    until the largest penetration is below ``gap_tolerance``, absolute, or ``gap_tolerance_relative``
    times the mean master facet size; at most ``max_augmentations`` updates per step).
    """

    name: str
    slave: tuple[str, str]
    master: tuple[str, str]
    penalty: float | str
    weighting: str = "nodal"
    tangent: str = "a"
    two_pass: bool = False
    max_penetration: float | None = None
    friction: float = 0.0
    tangential_penalty: float | None = None
    method: str = "penalty"
    gap_tolerance: float | None = None
    gap_tolerance_relative: float | None = None
    max_augmentations: int = 20
    auto_factor: float = 10.0
    enabled: bool = True               # off: the pair does nothing until a stage switches it on


@dataclass
class Steps:
    """Load-factor schedule: ``factors`` are the load factors at the end of each step."""

    factors: tuple[float, ...]

    @classmethod
    def equal(cls, n: int, final: float = 1.0) -> "Steps":
        return cls(tuple(float(final) * (k + 1) / n for k in range(n)))


@dataclass
class Stage:
    """A later stage of the analysis: it continues from the end state of the stage before.

    In every stage a quantity goes linearly in the stage's load factor lam from its value at the start of
    the stage (lam = 0) to its target (lam = 1); what a stage does not mention holds its value.

    release: names of Dirichlet conditions whose dofs become free; the reactions they carried at the start
        of the stage are applied as forces ramped to zero, (1 - lam) r, clipped at 0 beyond lam = 1.
    targets: new values of named Dirichlet conditions (tuple, one per component) and named loads (force or
        traction: 3-vector; pressure: a number).
    remove: names of loads ramped to zero.
    motions: new motions of named rigid bodies and of Dirichlet conditions with a motion, continuing from
        the pose the earlier stages left (``covcontact.motion.StagedMotion``).
    contacts: pair name -> True (switched on) or False (switched off) at the start of the stage.
    """

    name: str
    steps: Steps
    release: tuple[str, ...] = ()
    targets: dict = field(default_factory=dict)
    remove: tuple[str, ...] = ()
    motions: dict = field(default_factory=dict)
    contacts: dict = field(default_factory=dict)


@dataclass
class SolverOptions:
    """Newton and linear solver settings."""

    linear: str = "auto"
    max_iterations: int = 25
    rtol: float = 1e-8
    atol: float = 1e-12
    etol: float = 1e-16
    criterion: str = "residual"
    max_cutbacks: int = 6
    line_search: bool = False
    divergence_factor: float = 1e4
    #: inexact Newton: a step's later corrections by GMRES preconditioned with the factorisation of its first,
    #: refactorising when GMRES needs more than ``krylov_max`` iterations or the outer convergence stalls
    #: (direct solvers); "auto": where the factorisation is expensive enough to pay (PARDISO's flop count)
    reuse_factorization: bool | str = "auto"
    krylov_max: int = 30
    #: first iterate of a step: "tangent" (the tangent at the converged state with the prescribed increment)
    #: or "extrapolate" (the previous step's increment scaled to this one, then Newton)
    predictor: str = "tangent"
    #: precision of PARDISO's factorisations: "double", "single" (refined to double-precision accuracy by GMRES),
    #: or "auto" (single where it pays: PardisoSolver's rule); the other solvers factorise in double precision
    factorization_precision: str = "auto"
    #: threaded PARDISO in its reproducible mode (MKL's conditional numerical reproducibility): the same input
    #: gives the same bits on every run; False trades that for substitutions about 1.5 times faster on two threads
    reproducible: bool = True


@dataclass
class OutputOptions:
    """What to write: VTU every ``every`` converged steps, a checkpoint every ``checkpoint_every`` converged
    steps (the last step always gets both)."""

    vtu: bool = True
    every: int = 1
    pictures: bool = False
    checkpoint_every: int = 1


@dataclass
class Problem:
    """A complete problem; ``run`` solves it and writes the results."""

    name: str
    bodies: list[Body]
    dirichlet: list[Dirichlet] = field(default_factory=list)
    forces: list[NodalForce] = field(default_factory=list)
    pressures: list[Pressure] = field(default_factory=list)
    tractions: list[Traction] = field(default_factory=list)
    rigid: list[RigidBody] = field(default_factory=list)
    contacts: list[ContactPair] = field(default_factory=list)
    steps: Steps = field(default_factory=lambda: Steps.equal(1))
    solver: SolverOptions = field(default_factory=SolverOptions)
    output: OutputOptions = field(default_factory=OutputOptions)
    description: str = ""
    source: Path | None = None
    stages: list[Stage] = field(default_factory=list)  # the stages after the first (this object's own)
    stage_name: str = "stage1"                           # the name of the first stage
    units: str = ""  # as stated by the user, e.g. "mm, N, MPa" (length first): labels of the pictures

    def stage_list(self) -> list[tuple[str, Steps]]:
        """(name, steps) of every stage, the first included."""
        return [(self.stage_name, self.steps)] + [(s.name, s.steps) for s in self.stages]

    def body(self, name: str) -> Body:
        for b in self.bodies:
            if b.name == name:
                return b
        raise KeyError(f"no deformable body named {name!r}")

    def run(self, out: str | Path | None = None, tangent: str | None = None, quiet: bool = True,
            solver: str | None = None, resume: bool = False):
        """Solve the problem and write the results to ``out`` (default ``results/<name>``).

        ``tangent`` overrides every contact pair's tangent case; ``resume`` continues from the last
        checkpoint in ``out`` (``covcontact.io.checkpoint.CheckpointError`` if there is none that fits).
        """
        from .solvers.run import solve_problem

        return solve_problem(self, out=out, tangent=tangent, quiet=quiet, linear=solver, resume=resume)
