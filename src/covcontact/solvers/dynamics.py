"""Implicit dynamics: the generalized-alpha family of time integrators for a dynamic stage (docs/theory.md, section
20).

Chung and Hulbert (1993, J. Appl. Mech. 60, 371-375): the equation of motion is held at the generalized mid-point,

    M a_(n+1-am) + r(u, t)_(n+1-af) = 0,   x_(n+1-a) = (1 - a) x_(n+1) + a x_n,

with r = f_int + f_contact - f_ext the static residual (its value at step n kept from that step, so every
nonlinear term is evaluated at converged configurations only) and Newmark's updates

    a_(n+1) = (u_(n+1) - u_n - dt v_n) / (beta dt^2) - (1 / (2 beta) - 1) a_n,
    v_(n+1) = v_n + dt ((1 - gamma) a_n + gamma a_(n+1)).

The dynamic residual of u_(n+1) is R = M ((1 - am) a_(n+1) + am a_n) + (1 - af) r(u_(n+1)) + af r_n and its
tangent (1 - af) K + (1 - am) / (beta dt^2) M. Parameters from the spectral radius rho at infinite frequency:

- ``"generalized-alpha"``: am = (2 rho - 1) / (rho + 1), af = rho / (rho + 1), gamma = 1/2 - am + af,
  beta = (1 - am + af)^2 / 4 (second order, unconditionally stable, high-frequency damping optimal for rho);
- ``"hht"`` (Hilber, Hughes and Taylor 1977): am = 0, af = (1 - rho) / (1 + rho), gamma = 1/2 + af,
  beta = (1 + af)^2 / 4, rho in [1/2, 1];
- ``"newmark"``: the trapezoidal rule, am = af = 0, gamma = 1/2, beta = 1/4 (no damping, energy conserving for
  linear problems).

A :class:`DynamicModel` wraps the quasi-static model: Newton iterates on it unchanged (its cutbacks halve the time
step). The kinematic state (u, v, a at the end of the step, the static residual r there) is part of the committed
state (``State.dynamics``), so a checkpoint resumes the run bit for bit.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from .procedure import Increment, QuasiStatic, reactions
from .state import State


@dataclass(frozen=True)
class Integrator:
    """Parameters of the generalized-alpha method (am, af, beta, gamma)."""

    alpha_m: float
    alpha_f: float
    beta: float
    gamma: float

    @classmethod
    def of(cls, method: str, rho_inf: float = 1.0) -> Integrator:
        rho = float(rho_inf)
        if method == "newmark":
            return cls(0.0, 0.0, 0.25, 0.5)
        if method == "hht":
            if not 0.5 <= rho <= 1.0:
                raise ValueError(f"HHT needs rho_inf in [0.5, 1], got {rho}")
            af = (1.0 - rho) / (1.0 + rho)
            return cls(0.0, af, 0.25 * (1.0 + af) ** 2, 0.5 + af)
        if method == "generalized-alpha":
            if not 0.0 <= rho <= 1.0:
                raise ValueError(f"generalized-alpha needs rho_inf in [0, 1], got {rho}")
            am, af = (2.0 * rho - 1.0) / (rho + 1.0), rho / (rho + 1.0)
            return cls(am, af, 0.25 * (1.0 - am + af) ** 2, 0.5 - am + af)
        raise ValueError(f"unknown time integration method {method!r}")

    def acceleration(self, u, u_n, v_n, a_n, dt: float) -> np.ndarray:
        return (u - u_n - dt * v_n) / (self.beta * dt * dt) - (0.5 / self.beta - 1.0) * a_n

    def velocity(self, a, v_n, a_n, dt: float) -> np.ndarray:
        return v_n + dt * ((1.0 - self.gamma) * a_n + self.gamma * a)

    def mass_factor(self, dt: float) -> float:
        """d(M a_(n+1-am)) / du = this times M."""
        return (1.0 - self.alpha_m) / (self.beta * dt * dt)


def add_into(K: sp.csr_matrix, M: sp.csr_matrix, c: float, cache: dict, scale: float = 1.0) -> sp.csr_matrix:
    """``scale`` K + c M in K's own sparsity pattern (M's entries lie in it: the mass couples the nodes of an element,
    which the tangent couples already); K is changed in place. ``cache`` keeps the positions for K's pattern. A
    distributed tangent (not a scipy matrix) adds its rank's share itself (``K.add_mass``)."""
    if not sp.issparse(K):
        return K.add_mass(M, c, cache, scale)
    K.data *= scale
    key = (K.shape, K.nnz, id(K.indices), id(K.indptr))
    pos = cache.get("pos") if cache.get("key") == key else None
    if pos is None:
        if not K.has_sorted_indices:
            K.sort_indices()
        n = K.shape[1]
        k_keys = np.repeat(np.arange(K.shape[0], dtype=np.int64), np.diff(K.indptr)) * n + K.indices
        C = M.tocoo()
        m_keys = C.row.astype(np.int64) * n + C.col
        pos = np.searchsorted(k_keys, m_keys)
        if np.any(pos >= k_keys.size) or np.any(k_keys[np.minimum(pos, k_keys.size - 1)] != m_keys):
            raise ValueError("the mass matrix couples dofs the tangent's pattern does not hold")
        cache.update(key=key, pos=pos, data=C.data)
    np.add.at(K.data, pos, c * cache["data"])
    return K


class DynamicModel:
    """The quasi-static ``model`` seen by Newton in a dynamic stage: ``evaluate`` returns the dynamic residual and
    tangent and a trial state with the step's kinematics; everything else is the model's. ``T`` is the stage's
    duration (load factor lam = t / T)."""

    def __init__(self, model, M: sp.csr_matrix, integrator: Integrator, T: float):
        self.model, self.M, self.integ, self.T = model, M, integrator, float(T)
        self._cache: dict = {}
        #: the dofs without mass (the contact nodes of a redistributed mass)
        self.massless = np.asarray(abs(M).sum(axis=1)).ravel() == 0.0
        # they hold their equilibrium at the end of every step, (1 - af) r(u_(n+1)) = 0 (the factor keeps the
        # tangent symmetric): held at the generalized mid-point, (1 - af) r_(n+1) + af r_n = 0, a massless dof out of
        # balance at a step's start (a load that jumps) would swing about its equilibrium from step to step,
        # undamped for af = 1/2 (rho_inf = 1); Dynamic.start balances them at the stage's start
        self.keep_r = (~self.massless).astype(float) if integrator.alpha_f and self.massless.any() else 1.0

    def __getattr__(self, name):
        return getattr(self.model, name)

    def kinematics(self, u: np.ndarray, lam: float, committed: State) -> tuple[np.ndarray, np.ndarray, float]:
        """(a, v, dt) at the end of a step from ``committed`` to load factor ``lam`` with displacement ``u``."""
        d = committed.dynamics
        dt = (lam - committed.lam) * self.T
        if not dt > 0.0:
            raise ValueError(f"a dynamic step needs a positive time step, got {dt}")
        a = self.integ.acceleration(u, d["u"], d["v"], d["a"], dt)
        return a, self.integ.velocity(a, d["v"], d["a"], dt), dt

    def evaluate(self, u: np.ndarray, lam: float, committed: State, guess: State | None = None,
                 want_K: bool = True, timing: dict | None = None):
        # with multi-point constraints the inertia joins the nodal forces at every dof, then the constraints hand
        # them over (R and the stored r are at every dof, Rd the independent dofs')
        cons = getattr(self.model, "constraints", None)
        # (a rigid body's free dofs carry its mass: the quasi-static check that contact restrains them is not asked)
        kw = {"check": False} if getattr(self.model.system, "reference", None) else {}
        R, K, trial = self.model.evaluate(u, lam, committed, guess, want_K=want_K, timing=timing, raw=cons is not None,
                                          **kw)
        g, d = self.integ, committed.dynamics
        a, v, dt = self.kinematics(u, lam, committed)
        fd = self.damping(u, v, g.gamma / (g.beta * dt), K)  # (the dashpots' forces, their tangent into K)
        if fd is not None:
            R = R + fd
        Rd = (self.M @ ((1.0 - g.alpha_m) * a + g.alpha_m * d["a"]) + (1.0 - g.alpha_f) * R
              + g.alpha_f * self.keep_r * d["r"])
        if K is not None:
            K = add_into(K, self.M, g.mass_factor(dt), self._cache, scale=1.0 - g.alpha_f)
        if cons is not None:
            Rd, K = cons.transform(Rd, K)
            if K is not None and self.model.system.reference:
                self.model._check_restrained(K)
        # the work of the applied forces and of the contact forces on the bodies over the step (trapezoidal rule)
        f = applied_forces(self.model, Rd, lam, u)
        du = u - d["u"]
        work = float(d["work"]) + 0.5 * float((d["f"] + f) @ du)
        rc = getattr(self.model, "last_contact_residual", None)
        rc = np.zeros_like(R) if rc is None else rc.copy()
        rc0 = d["rc"] if "rc" in d else np.zeros_like(R)
        wc = float(d["wc"]) if "wc" in d else 0.0
        dyn = dict(d)
        dyn.update(u=u.copy(), v=v, a=a, r=R, rd=Rd, f=f, work=np.array(work), time=np.array(float(d["time"]) + dt),
                   rc=rc, wc=np.array(wc - 0.5 * float((rc0 + rc) @ du)))
        if fd is not None:  # (the work of the dashpots' forces on the bodies, trapezoidal: what they dissipate)
            fd0 = d["fd"] if "fd" in d else np.zeros_like(fd)
            dyn.update(fd=fd, wd=np.array(float(d["wd"] if "wd" in d else 0.0) + 0.5 * float((fd0 + fd) @ du)))
        return Rd, K, trial.but(dynamics=dyn)

    def damping(self, u: np.ndarray, v: np.ndarray, s: float = 0.0, K=None) -> np.ndarray | None:
        """The dashpots' forces at displacement ``u`` and velocity ``v`` (every dof), None without dashpots; with
        ``K`` (the model's raw tangent) their tangent, with dv/du = ``s``, added into it."""
        springs = getattr(self.model, "springs", None)
        if springs is None or not springs.dashpots:
            return None
        from ..elements.springs import add_blocks

        f = np.zeros(self.model.n_dofs)
        pattern = self.model.coupling.pattern if K is not None else None
        if K is not None and K.nnz != pattern.nnz:
            raise ValueError("the tangent is not on the model's pattern")
        blocks = springs.dashpot_blocks(self.model.positions(u), v.reshape(-1, 3), s, K is not None)
        add_blocks(blocks, f, K, pattern)
        return f


def applied_forces(model, Rd: np.ndarray, lam: float, u: np.ndarray) -> np.ndarray:
    """The forces on the bodies from outside at displacement ``u``: the external loads (follower pressures on the
    current faces) and, on constrained dofs, the supports' (the dynamic residual there)."""
    f = model.applied(u, lam).copy()
    c = ~model.free
    cons = getattr(model, "constraints", None)
    if cons is not None:  # (the dofs a constraint eliminates are no supports: its forces do no work in all)
        c &= ~cons.mask
    f[c] += Rd[c]
    return f


def contact_nodes(model) -> np.ndarray:
    """Mask over the system's nodes of the deformable nodes on a contact surface: every slave node (the facet nodes of
    segment-to-surface points) and every node of a mesh master surface (patch points resolved to their nodes); tied
    pairs left out (their surfaces never part, so they cannot rattle)."""
    mask = np.zeros(model.system.n_nodes, dtype=bool)
    contact = getattr(model, "contact", None)
    if contact is None:
        return mask
    for p in contact.passes:
        if getattr(p, "tied", False):
            continue
        nodes = [contact.points.nodes(p.slaves)]
        if p.surface is not None:
            nodes.append(contact.points.nodes(p.surface.faces.ravel()))
        ids = np.concatenate(nodes)
        mask[ids[ids < model.system.n_nodes]] = True
    joined = getattr(model, "any_over_ranks", None)  # (a distributed model's passes hold its rank's slaves)
    return mask if joined is None else joined(mask)


def resolved_mass(mass: str, massless: np.ndarray) -> str:
    """The mass matrix of a stage that asks for ``mass``: ``"auto"`` is the consistent redistributed mass where
    deformable nodes lie on a contact surface (``massless``, :func:`contact_nodes`), the consistent mass elsewhere
    (docs/theory.md, section 20: the contact boundary without inertia cannot rattle, so the contact cannot add
    energy; the consistent mass of the interior rings less after an impact than the lumped one)."""
    if mass != "auto":
        return mass
    return "consistent-redistributed" if np.any(massless) else "consistent"


def _tools_still(model, spec) -> bool:
    """Whether no rigid body's motion changes over the stage ``spec`` (its start and end load factors)."""
    drive = getattr(model, "drive", None)
    if drive is None:
        return True
    a, b = drive(0.0)[2], drive(spec.lam_end)[2]
    return a.size == 0 or bool(np.allclose(a, b, rtol=0.0, atol=1e-14 * max(1.0, float(np.abs(a).max()))))


#: Newton iterations and relative tolerance of the balance of the massless dofs at a dynamic stage's start
BALANCE_ITERATIONS = 20
BALANCE_TOLERANCE = 1e-12


def dof_block(K, mask: np.ndarray) -> sp.csr_matrix:
    """The tangent's block on the dofs of ``mask`` as a scipy matrix (a distributed tangent: its ranks' shares
    summed, on every rank)."""
    if sp.issparse(K):
        return K.tocsr()[mask][:, mask]
    return K.block(mask)


#: the mass matrices without inertia on the contact surfaces
REDISTRIBUTED = ("redistributed", "consistent-redistributed")
#: an energy growth of the bodies beyond this share of the energy in the system is said (``Dynamic._growth``)
GROWTH = 0.01


def initial_velocity(model, problem) -> np.ndarray:
    """The dofs' velocities of ``problem.initial_velocity`` (later entries win where sets overlap)."""
    v = np.zeros(model.n_dofs).reshape(-1, 3)
    for iv in problem.initial_velocity:
        off = model.system.offset(iv.body)
        mesh = problem.body(iv.body).mesh
        nodes = mesh.node_sets[iv.set] if iv.set else np.arange(mesh.n_nodes)
        v[nodes + off] = iv.value
    return v.ravel()


class Dynamic(QuasiStatic):
    """Time stepping of a dynamic stage (``dyn``, a ``covcontact.description.Dynamics``) with the generalized-alpha
    family; the increments are the stage's time steps (``t / t_end`` as load factor) and Newton's cutbacks halve
    them. ``t_start``: the stage's start time (``time`` in the records)."""

    name = "dynamic"

    def __init__(self, model, newton, spec, t_stage: float, staged: bool, control, dyn, problem, t_start: float):
        super().__init__(model, newton, spec, t_stage, staged, control)
        self.dyn, self.problem, self.t_start = dyn, problem, float(t_start)
        self.integrator = Integrator.of(dyn.method, dyn.rho_inf)
        massless = contact_nodes(model)
        self.mass = resolved_mass(dyn.mass, massless)
        massless_here = massless if self.mass in REDISTRIBUTED else None
        self.M = model.system.mass(lumped=self.mass == "lumped", massless=massless_here,
                                   consistent_interior=self.mass == "consistent-redistributed")
        #: the tools (rigid masters) stand still over the stage: the contact's account then holds no tool work
        self.tools_still = _tools_still(model, spec)
        self.energy_warning: str | None = None  # the stage's energy growth, said once (``_growth``)
        #: what the stage's choices do to the energy, said at its start
        self.notes = [] if self.mass in REDISTRIBUTED or not np.any(massless) else [
            f'mass = "{self.mass}" with contact: the contact nodes keep their inertia, so a flat impact can rattle '
            f'(open and close between steps) and gain energy; the run warns if it does; mass = '
            f'"consistent-redistributed" (the default with contact) keeps the energy']
        self.dynamic_model = DynamicModel(model, self.M, self.integrator, dyn.t_end)

    def start(self, state: State, u: np.ndarray | None = None) -> State:
        """The stage's start: a state that has no kinematics yet (the first dynamic stage, or one after a static
        stage) gets them: u, the initial velocities (first dynamic stage) or rest, the acceleration of
        equilibrium M a_0 = -r(u_0) on the free dofs, and the energy account's start."""
        super().start(state)
        if u is None:
            return state
        if "v" in state.dynamics:
            if not self._frees_equations(state.stage):
                return state
            # equations removed at the stage's start: the dofs they held are free from here, and the acceleration
            # the last step left (with the constraint forces in it) is not that of the new equations of motion: the
            # equilibrium acceleration at the same displacement and velocity, as a dynamic step that starts
            R, _, _ = self.model.evaluate(u, state.lam, state, want_K=False, raw=True)
            fd = self.dynamic_model.damping(u, state.dynamics["v"])
            R = R if fd is None else R + fd
            a, Rd = self._equilibrium(R, self.model.free)
            dyn = dict(state.dynamics)
            dyn.update(a=a, r=R, rd=Rd, f=applied_forces(self.model, Rd, state.lam, u))
            if fd is not None:
                dyn["fd"] = fd
            return state.but(dynamics=dyn)
        model = self.model
        cons = getattr(model, "constraints", None)
        R = self._balance_massless(u, state) if cons is None else None
        if R is None:
            R, _, _ = model.evaluate(u, state.lam, state, want_K=False, raw=cons is not None)
        free = model.free
        first = not any(self.problem.stage_dynamics(i) is not None for i in range(state.stage))
        v = initial_velocity(model, self.problem) if first else np.zeros(model.n_dofs)
        v[~free] = 0.0  # (a prescribed dof moves with its prescription)
        if cons is not None:  # (the eliminated dofs' velocities follow the others')
            v = cons.lift(v)
        fd = self.dynamic_model.damping(u, v)  # (dashpots: their forces at the initial velocities)
        R = R if fd is None else R + fd
        a, Rd = self._equilibrium(R, free)  # (Rd: the supports' forces at rest or with the initial velocities' inertia)
        rc = getattr(model, "last_contact_residual", None)
        dyn = {"u": u.copy(), "u0": u.copy(), "v": v, "a": a, "r": R, "rd": Rd, "time": np.array(self.t_start),
               "work": np.array(0.0), "f": applied_forces(model, Rd, state.lam, u),
               "rc": np.zeros_like(R) if rc is None else rc.copy(), "wc": np.array(0.0)}
        if fd is not None:
            dyn.update(fd=fd, wd=np.array(0.0))
        e = self._energies(u, state.but(dynamics=dyn))
        dyn["e0"] = np.array(e["mechanical"])
        dyn["ec0"] = np.array(e["contact"])
        return state.but(dynamics=dyn)

    def _balance_massless(self, u: np.ndarray, state: State) -> np.ndarray | None:
        """The free dofs without mass (the contact nodes of a redistributed mass) brought into equilibrium at the
        stage's start, the others held: Newton on them alone, ``u`` changed in place (their static deflection
        under what loads them: their share of the weight, loads applied at once). Without it the first step would
        take them there at once and lose half the work of that imbalance. Returns the residual at the balanced
        ``u``; None where there is nothing to balance."""
        m = self.dynamic_model.massless & self.model.free
        if not m.any():
            return None
        model = self.model
        # (the rigid bodies' free dofs are held here: whether the tangent restrains them is not asked)
        kw = {"check": False} if getattr(model.system, "reference", None) else {}
        R, K, _ = model.evaluate(u, state.lam, state, **kw)
        ref = max(float(np.linalg.norm(model.applied(u, state.lam))), float(np.linalg.norm(R[~m & model.free])),
                  1e-300)
        for _ in range(BALANCE_ITERATIONS):
            if float(np.linalg.norm(R[m])) <= BALANCE_TOLERANCE * ref:
                break
            u[m] -= sla.spsolve(dof_block(K, m).tocsc(), R[m])
            R, K, _ = model.evaluate(u, state.lam, state, **kw)
        return R

    def _frees_equations(self, stage: int) -> bool:
        """Whether ``stage`` removes equations (its ``remove`` names one)."""
        names = {e.name for e in getattr(self.problem, "equations", None) or [] if e.name}
        return stage > 0 and bool(names & set(self.problem.stages[stage - 1].remove))

    def _equilibrium(self, R: np.ndarray, free: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(a, Rd): the acceleration of M a = -R on the free dofs with mass (``R`` at every dof; with constraints
        solved on the independent dofs with T^T M T and lifted) and the residual with that inertia."""
        cons = getattr(self.model, "constraints", None)
        M = self.M
        if cons is not None:
            R = cons.transform(R, None)[0]
            M = cons.mass(self.M)
        a = np.zeros(len(R))
        inert = free & (M.diagonal() > 0.0)  # (the redistributed mass leaves contact nodes without inertia)
        if np.any(R[inert]):
            a[inert] = sla.spsolve(M[inert][:, inert].tocsc(), -R[inert])
        Rd = R + M @ a
        return (cons.lift(a) if cons is not None else a), Rd

    def advance(self, u: np.ndarray, state: State, step: int, lam: float) -> Increment:
        """A time step: Newton on the dynamic model. With ``reuse_factorization = "auto"`` a dynamic step reuses its
        first factorisation for its later corrections (GMRES preconditioned by it): the mass term dominates a
        dynamic tangent, which then changes little within a step (benchmarks/dynamics.py: one factorisation per
        step instead of 2.2, the same iterations).

        With a frictional pair switched on, Newton's corrections get the secant line search (``Newton._searched``)
        whatever ``line_search`` says. A slave node that comes to rest while slipping has no tangential stiffness
        along its slip (the return mapping's slip tangent, exact) but the inertia and its elements', and its stick
        band, the slip of width 2 kappa / eps_T in which the trial traction lies inside the cone, is far narrower
        than the correction M^-1 beta dt^2 kappa that the slip traction kappa drives: full Newton corrections
        then jump over the band from slip one way to slip the other way and back (a two-cycle of the
        piecewise-linear equation c (u - u*) + f(u) = 0, slopes c outside the band, c + eps_T inside it, which the
        status codes do not see: slip stays slip). The search halves such a jump (the secant of the two-cycle)
        and lands in the band; a correction that reduces du . R keeps its full length, at no extra evaluation.
        Measured (tests/verification/test_friction_stop.py: a block sliding to rest on a rigid plane): 20 to 190
        iterations per step with cutbacks after the stop without it, at most 7 to 10 with it."""
        newton = self.newton
        opt = newton.opt
        self._before = state
        newton.model = self.dynamic_model
        if opt.reuse_factorization == "auto":
            newton.opt = replace(opt, reuse_factorization=True)
        contact = getattr(self.model, "contact", None)
        newton.search_friction = contact is not None and any(
            p.mu > 0.0 and on for p, on in zip(contact.passes, contact.enabled))
        try:
            inc = super().advance(u, state, step, lam)
        finally:
            newton.model, newton.opt = self.model, opt
            newton.search_friction = False
        return inc

    def _error(self, before: State, after: State) -> float:
        """The step's local error estimate (Zienkiewicz and Xie 1991): dt^2 |beta - 1/6| ||a_(n+1) - a_n|| over the
        displacement since the stage's start, in the mass norm ||x||_M = sqrt(x.M x) (dofs without mass, the contact
        nodes of a redistributed mass, follow quasi-statically and do not count)."""
        d0, d1 = before.dynamics, after.dynamics
        dt = float(d1["time"]) - float(d0["time"])

        def norm(x):
            return float(np.sqrt(max(float(x @ (self.M @ x)), 0.0)))

        moved = norm(d1["u"] - d1["u0"])
        if not moved > 0.0:
            return 0.0
        return dt * dt * abs(self.integrator.beta - 1.0 / 6.0) * norm(d1["a"] - d0["a"]) / moved

    def _energies(self, u: np.ndarray, state: State) -> dict:
        """Kinetic, strain and contact (penalty) energy of ``state`` and their sum."""
        d = state.dynamics
        kinetic = 0.5 * float(d["v"] @ (self.M @ d["v"]))
        strain = self.model.system.energy(u, state.elements)
        springs = getattr(self.model, "springs", None)
        if springs is not None:  # (the springs' stored energy)
            strain += springs.energy(self.model.positions(u), u.reshape(-1, 3))
        contact = 0.0
        for k, p in enumerate(state.contact.passes):
            act = self.model.contact.active_mask(k, state.contact)
            g = np.where(act, p.gap, 0.0)
            contact += 0.5 * float(np.sum(np.linalg.norm(p.force[act], axis=1) * np.abs(g[act])))
        if hasattr(self.model, "sum_over_ranks"):  # (a distributed model's passes hold its rank's slaves)
            contact = self.model.sum_over_ranks(contact)
        return {"kinetic": kinetic, "strain": strain, "contact": contact, "mechanical": kinetic + strain + contact}

    def _report(self, inc: Increment, u: np.ndarray, stats0: dict, time0: dict) -> dict:
        if inc.success and self.automatic:  # (the increment control reads it after the report)
            inc.error = self._error(self._before, inc.state)
        entry = super()._report(inc, u, stats0, time0)
        if inc.success and self.automatic:
            entry["error_estimate"] = inc.error
        if not inc.success:
            return entry
        state = inc.state
        d = state.dynamics
        e = self._energies(u, state)
        dissipation = float(entry.get("plastic_work", 0.0))
        # what the contact took out of the bodies and does not hold as penalty energy: the frictional dissipation
        # (and the contact law's numerical losses; a moving rigid tool's work counts against it)
        contact_loss = -float(d.get("wc", 0.0)) - (e["contact"] - float(d.get("ec0", 0.0)))
        damping = float(d["wd"]) if "wd" in d else None  # (what the dashpots dissipated)
        balance = e["mechanical"] + dissipation + contact_loss + (damping or 0.0) - float(d["e0"]) - float(d["work"])
        scale = max(e["mechanical"], float(d["e0"]), abs(float(d["work"])), 1e-300)
        entry["time"] = float(d["time"])
        entry["energy"] = {"kinetic": e["kinetic"], "strain": e["strain"], "contact": e["contact"],
                           "external_work": float(d["work"]), "dissipation": dissipation,
                           "contact_dissipation": contact_loss, "balance_error": balance / scale}
        if damping is not None:
            entry["energy"]["damping"] = damping
        growth = self._growth(entry["energy"], e["mechanical"], d)
        if growth is not None and self.energy_warning is None:
            self.energy_warning = growth
            entry["energy_warning"] = growth
        return entry

    def _growth(self, energy: dict, mechanical: float, d: dict) -> str | None:
        """Why the bodies' energy grows beyond what was brought in, None where it does not: the contact gave back
        more than it took (``contact_dissipation`` below -GROWTH of the energy in the system; judged only while the
        stage's rigid tools stand still, as a moving tool's work is part of that account) or the balance gains more
        than GROWTH. The likely cause and its fix with it."""
        system = max(mechanical, float(d["e0"]), abs(float(d["work"])), 1e-300)
        gained = -energy["contact_dissipation"] / system if self.tools_still else 0.0
        if gained > GROWTH:
            cause = (f"the contact gave the bodies {gained:.1%} of their energy (contact_dissipation "
                     f"{energy['contact_dissipation']:.4g})")
        elif energy["balance_error"] > GROWTH:
            cause = f"the energy balance gained {energy['balance_error']:.1%}"
        else:
            return None
        if self.mass not in REDISTRIBUTED and np.any(contact_nodes(self.model)):
            fix = (f'the contact surfaces rattle with mass = "{self.mass}" (the contact opens and closes between '
                   f'steps): mass = "consistent-redistributed" (the default with contact) keeps the energy')
        else:
            fix = "shorter time steps (dt) or numerical damping (rho_inf below 1) may help"
        return f"the bodies' energy grows: {cause}; {fix}"

    def _reactions(self, u: np.ndarray, lam: float, state: State) -> dict:
        """The supports' resultant forces with the inertia: the step's dynamic residual on their dofs."""
        return reactions(self.model, u, lam, state, R=state.dynamics["rd"])
