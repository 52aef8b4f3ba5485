"""The description of a problem's parts: bodies, rigid bodies, contact pairs, load steps, stages and the
solver and output options (the loads and boundary conditions: ``covcontact.loads``). Plain data, depending on
nothing above the mesh and motion types; ``covcontact.problem.Problem`` puts them together and runs them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .mesh import Mesh
from .motion import RigidMotion

COMPONENTS = {"x": 0, "y": 1, "z": 2}
TANGENT_CASES = ("a", "b", "c", "d", "exact")


@dataclass
class Body:
    """A deformable body: a mesh, its element formulation and its material (or a material per element set,
    ``materials``, bonded through the shared nodes; the cells in no set take ``material``)."""

    name: str
    mesh: Mesh
    material: Any
    formulation: str = "solid"
    options: dict = field(default_factory=dict)
    materials: dict = field(default_factory=dict)  # element set -> material (the other cells take ``material``)

    def material_parts(self, elements: np.ndarray | None = None) -> list[tuple[str, np.ndarray, Any, str]]:
        """(element set name, "" for ``material``; indices into ``elements`` (default all cells); material; cell type)
        of every material with cells among ``elements``, per cell type of a mixed mesh."""
        owner = np.full(self.mesh.n_cells, -1)
        for k, name in enumerate(self.materials):
            owner[self.mesh.element_sets[name]] = k
        els = np.arange(self.mesh.n_cells) if elements is None else np.asarray(elements, dtype=np.int64)
        owner = owner[els]
        parts = []
        for k, (name, material) in enumerate([("", self.material), *self.materials.items()]):
            for cell_type, idx in self.mesh.type_parts(els):
                idx = idx[owner[idx] == k - 1]
                if idx.size:
                    parts.append((name, idx, material, cell_type))
        return parts


@dataclass
class RigidBody:
    """A rigid body: an analytic surface or a mesh moving rigidly.

    ``shape`` "plane" (``params`` point, normal), "cylinder" (center, axis, radius, outside), "sphere"
    (center, radius, outside) or "profile" (points, fillets, extrude or revolve) for an analytic surface; or ``mesh``, a Mesh whose nodes carry no unknowns
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
    mass: float | None = None           # dynamics: the mass of a body with free translations
    inertia: tuple | None = None        # dynamics: principal moments about the reference point (x, y, z axes)
    attach: tuple = ()                  # (body, node set) pairs of deformable nodes that move with the body
    attach_components: tuple = (0, 1, 2)  # the attached nodes' components that follow it (0..2; the others free)

    def reference_point(self) -> np.ndarray:
        if self.reference is not None:
            return np.asarray(self.reference, dtype=float)
        if self.mesh is not None:
            return self.mesh.points.mean(axis=0)
        return np.asarray(self.params.get("center", self.params.get("point")), dtype=float)


@dataclass
class ContactPair:
    """A contact pair: node-to-surface (``type`` "nts") or segment-to-surface ("sts"), or self-contact.

    slave: (body name, node set name); the body may be deformable or a rigid meshed body.
    master: (body name, face set name) of a deformable or rigid meshed body, or (rigid body name, "")
    for an analytic surface.
    penalty: eps_N, or "auto" (``auto_factor`` times Young's modulus over the facet size of the master
    body, or of the slave body against a rigid master; times the tributary area for "nodal" weighting; a tied
    pair: 100 times the larger modulus over the smaller mean shortest facet edge of its two surfaces).
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
    auto_factor: float | None = None   # None: 10, or 100 for law "tied" (penalty "auto")
    enabled: bool = True               # off: the pair does nothing until a stage switches it on
    smoothing: float = 0.0             # width of the band of gaps over which the normal law is rounded (C1)
    law: str = "penalty"               # normal law: "penalty" (with ``smoothing``), "exponential", "arctan", "table"
    clearance: float | None = None     # exponential law: the gap at which the pressure starts
    pressure: float | None = None      # exponential law: the pressure at zero gap
    form: str = "abaqus"               # exponential law: "abaqus" (zero at c0) or "calculix" (p0 exp(-ln100 g/c0))
    tension: float = 0.0               # arctan law: the tension sigma_inf at large clearance
    reach: float | None = None         # arctan and table laws: the largest clearance over sqrt(area) (None: 1e-3)
    table: tuple = ()                  # table law: (overclosure, pressure) points
    type: str = "nts"                  # "nts": slave nodes; "sts": Gauss points of the slave facets
    order: int | None = None           # sts: Gauss points per direction of a slave facet (None: 2 quad4, 3 quad9)
    self_surfaces: tuple | None = None  # self-contact: the (body, face set) surfaces merged into one
    tie_tolerance: float | None = None  # law "tied": largest distance of a tied point (None: 5 % facet size)
    adjust: float | str | None = None  # slave nodes moved onto the master before the first step: below this gap, or a node set
    gap: str = "points"                # sts: the law on each Gauss point's gap, or on each slave node's weighted gap ("nodal")

    def penalty_factor(self) -> float:
        """The factor of ``penalty = "auto"``: ``auto_factor``, else 10 (100 for a tied pair: a tie has no active set
        to chatter, only the conditioning to mind, and stands for CalculiX's exact equations)."""
        if self.auto_factor is not None:
            return float(self.auto_factor)
        return 100.0 if self.law == "tied" else 10.0


@dataclass
class Steps:
    """Load-factor schedule: ``factors`` are the load factors at the end of each step; or, with ``initial``
    (and ``min``, ``max``), automatic increments of the load factor up to ``factors[-1]`` (the stage's end),
    chosen as the steps go (docs/input.md, ``[steps]``); ``output_at``: load factors where results are written
    (automatic increments end exactly there; fixed ones must have a step ending there)."""

    factors: tuple[float, ...]
    initial: float | None = None
    min: float | None = None
    max: float | None = None
    output_at: tuple[float, ...] = ()  # load factors at which results are written (increments end there)

    @classmethod
    def equal(cls, n: int, final: float = 1.0) -> Steps:
        return cls(tuple(float(final) * (k + 1) / n for k in range(n)))

    @classmethod
    def automatic(cls, initial: float, min: float, max: float, final: float = 1.0) -> Steps:
        return cls((float(final),), float(initial), float(min), float(max))

    @property
    def is_automatic(self) -> bool:
        return self.initial is not None

    @property
    def count(self) -> int | None:
        """The number of steps where it is known beforehand (None: automatic increments)."""
        return None if self.is_automatic else len(self.factors)


#: time integration methods of a dynamic stage
DYNAMIC_METHODS = ("generalized-alpha", "hht", "newmark")
#: mass matrices of a dynamic stage ("auto" resolves to one of the others, solvers/dynamics.py ``resolved_mass``)
MASSES = ("auto", "consistent", "lumped", "redistributed", "consistent-redistributed")


@dataclass
class Dynamics:
    """A dynamic stage (``procedure = "dynamic"``): time steps ``dt`` up to ``t_end`` (the stage's load factor is
    t / t_end), the integrator ``method`` with the spectral radius ``rho_inf`` at infinite frequency (1: no
    numerical damping; generalized-alpha in [0, 1], HHT in [0.5, 1]; Newmark is the trapezoidal rule), and the
    ``mass`` matrix, "auto" (redistributed with contact, else consistent), "consistent", "lumped" or "redistributed"
    (docs/theory.md, section 20); ``dt_min`` and ``dt_max``
    make the time steps automatic (from ``dt``, on the local error estimate against ``tolerance``)."""

    dt: float
    t_end: float
    method: str = "generalized-alpha"
    rho_inf: float = 1.0
    mass: str = "auto"
    dt_min: float | None = None  # with dt_max: automatic time steps from dt (docs/theory.md, section 20)
    dt_max: float | None = None
    tolerance: float = 1e-3      # automatic time steps: the local error estimate's target, relative

    @property
    def automatic(self) -> bool:
        return self.dt_min is not None

    def steps(self) -> Steps:
        """The stage's load factors: t / t_end at every time step (the last one may be shorter); automatic time
        steps start at dt and stay within [dt_min, dt_max]."""
        if self.automatic:
            return Steps.automatic(self.dt / self.t_end, self.dt_min / self.t_end, self.dt_max / self.t_end)
        n = int(np.ceil(self.t_end / self.dt * (1.0 - 1e-12)))
        return Steps(tuple(min((k + 1) * self.dt / self.t_end, 1.0) for k in range(n)))


@dataclass
class InitialVelocity:
    """The velocity ``value`` of the nodes of ``set`` of ``body`` (the whole body when ``set`` is empty) at the
    start of the first dynamic stage."""

    body: str
    set: str
    value: tuple[float, float, float]


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
    dynamics: the time stepping of a dynamic stage (None: quasi-static load stepping).
    friction: pair name -> the Coulomb coefficient of a frictional pair from the start of this stage on.
    ramp: the loads go linearly to their targets (True) or take them at once (False, as a step load).
    """

    name: str
    steps: Steps
    release: tuple[str, ...] = ()
    targets: dict = field(default_factory=dict)
    remove: tuple[str, ...] = ()
    motions: dict = field(default_factory=dict)
    contacts: dict = field(default_factory=dict)
    dynamics: Dynamics | None = None  # a dynamic stage (None: quasi-static)
    friction: dict = field(default_factory=dict)
    ramp: bool = True  # False: the loads take their targets at once (the prescribed displacements still ramp)


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
    #: first iterate of a step: "tangent" (the tangent at the converged state with the prescribed increment),
    #: "extrapolate" (the previous step's increment scaled to this one, then Newton) or "auto" (extrapolate in
    #: path-dependent problems, those with a plastic material or a frictional pair; tangent otherwise)
    predictor: str = "auto"
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
