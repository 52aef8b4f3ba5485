"""What each stage of an analysis prescribes: Dirichlet values and motions, loads, rigid motions, pairs.

The first stage is the problem itself (every quantity goes from 0 at lam = 0 to its value at lam = 1,
rigid motions as given); each later ``covcontact.problem.Stage`` starts where the one before ended and
changes what it names (docs/theory.md section 13):

- a Dirichlet condition with a value goes linearly from its value at the start of the stage to its target;
  one with a motion follows the stage's motion from the pose the earlier stages left; a condition the stage
  does not mention holds its value (or pose);
- a released condition frees its dofs; the reaction r it carried at the start of the stage is applied as
  the force max(0, 1 - lam) r (the support is withdrawn gradually); what is left of it at the end of the
  stage (a stage ending before lam = 1) is held as a constant force in the stages after;
- a load goes linearly from its start value to its target (``remove``: 0);
- a rigid body follows its new motion from its pose at the start of the stage, or stands still;
- contact pairs are on or off for the whole stage.

Everything here is a function of the problem and the stage index, except the released reactions, which
belong to the solution and travel in the committed state (``State.forces``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..motion import StagedMotion


@dataclass
class _Condition:
    """One Dirichlet condition in one stage: its dofs and how they move."""

    name: str
    nodes: np.ndarray            # global node numbers
    components: tuple[int, ...]
    start: np.ndarray | None     # (ncomp,) value at lam = 0 (value conditions)
    target: np.ndarray | None    # (ncomp,) value at lam = 1
    motion: object = None        # RigidMotion / StagedMotion (motion conditions)
    rigid: object = None         # the ReferenceBody of a rigid body's prescribed components
    #: the condition starts from the displacement its dofs had when it began (``Loading.applied``): to ``target``,
    #: or (``held``) staying there
    from_state: bool = False
    held: bool = False

    @property
    def dofs(self) -> np.ndarray:
        if self.rigid is not None:  # components 0..5 of the pair (A, B)
            node = np.where(np.asarray(self.components) < 3, self.rigid.A, self.rigid.B)
            return 3 * node + np.asarray(self.components) % 3
        return (3 * self.nodes[:, None] + np.asarray(self.components)[None, :]).ravel()

    def values(self, X: np.ndarray, lam: float) -> np.ndarray:
        """Prescribed displacement of ``dofs`` at lam (X: reference positions of all nodes)."""
        if self.rigid is not None:  # a reference node pair: translation and (total) rotation vector of the motion
            t = self.motion.apply(self.rigid.origin, lam) - self.rigid.origin
            q = np.concatenate([t, self.motion.rotation_vector(lam)])
            return q[list(self.components)]
        if self.motion is None:
            v = self.start + lam * (self.target - self.start)
            return np.tile(v, len(self.nodes))
        Xn = X[self.nodes]
        return (self.motion.apply(Xn, lam) - Xn)[:, list(self.components)].ravel()

    def end(self, lam_end: float) -> tuple:
        """(start value, pose) this condition leaves for the next stage (a condition from the state: its target,
        reached at the end of the stage, or None while it holds the state's values); the pose as (Q, b, total
        rotation vector)."""
        if self.from_state:
            return (None if self.held else self.target), None
        if self.motion is None:
            return self.start + lam_end * (self.target - self.start), None
        return None, self.motion.state(lam_end)


@dataclass
class StageSpec:
    """Stage ``index`` (0: the problem's own first stage) resolved against the problem."""

    index: int
    name: str
    factors: tuple[float, ...]
    conditions: list[_Condition]
    released: np.ndarray                   # dofs freed at the start of this stage
    load_start: np.ndarray                 # (n_dofs,) external load at lam = 0
    load_target: np.ndarray                # (n_dofs,) at lam = 1
    motions: dict[str, object]             # rigid body name -> motion in this stage
    contacts: dict[str, bool]              # pair name -> on
    release_names: tuple[str, ...] = ()
    constrained: np.ndarray = field(default=None, repr=False)
    rigid_loads: dict = field(default_factory=dict)  # reference body -> (force, moment) at lam = 0 and at 1
    #: free dofs of reference bodies whose contact pairs are all off in this stage: held where the stage
    #: found them (nothing else would restrain them)
    parked: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64), repr=False)
    parked_names: tuple[str, ...] = ()
    #: parked dofs moved by a motion this stage gives their body: (dofs, StagedMotion, components 0..2)
    parked_moves: list = field(default_factory=list, repr=False)
    #: contact pairs released at the start of this stage: switched off, their forces ramped to zero
    released_pairs: tuple[str, ...] = ()
    #: pair name -> Coulomb coefficient in this stage (the frictional pairs)
    friction: dict = field(default_factory=dict)
    #: conditions that start in this stage, from the displacement their dofs have then
    applied_names: tuple[str, ...] = ()
    #: the loads go linearly to their targets (False: they take them at once, a step load)
    ramp: bool = True
    #: follower pressures (on the current faces, not in load_start / load_target): load key -> (value at lam = 0,
    #: at lam = 1)
    followers: dict = field(default_factory=dict)
    #: the right-hand sides of the problem's equations (in its order) at lam = 0 and at lam = 1
    equations: tuple = (np.zeros(0), np.zeros(0))

    @property
    def lam_end(self) -> float:
        return self.factors[-1]


class StagePlan:
    """Every stage of a problem, resolved once (docs/theory.md section 13)."""

    def __init__(self, problem, system):
        self.problem = problem
        self.system = system
        n_dofs = system.n_dofs
        loads = {}   # name -> (vector of the load at value 1 per component: a function value -> (n_dofs,))
        values = {}  # load name -> current value (np.ndarray)
        all_loads = [("force", f) for f in problem.forces] + [("pressure", p) for p in problem.pressures] \
            + [("traction", t) for t in problem.tractions] \
            + [("body_force", b) for b in getattr(problem, "body_forces", [])]
        for i, (kind, load) in enumerate(all_loads):
            key = load.name or f"#{i}"
            loads[key] = load
            values[key] = np.zeros_like(np.atleast_1d(np.asarray(load.value, dtype=float)))
        targets = {k: np.atleast_1d(np.asarray(ld.value, dtype=float)) for k, ld in loads.items()}
        #: the follower pressures by load key (their values per stage: StageSpec.followers)
        self.followers = {k: ld for k, ld in loads.items() if getattr(ld, "follower", False)}

        conds: list[_Condition] = []
        late: dict[str, list[_Condition]] = {}  # stage name -> the conditions that start there
        for i, bc in enumerate(problem.dirichlet):
            nodes = system.global_nodes(bc.body, bc.set)
            if getattr(bc, "stage", None) is not None:
                late.setdefault(bc.stage, []).append(_Condition(
                    bc.name or f"#{i}", nodes, bc.components, None, np.asarray(bc.values, dtype=float),
                    from_state=True, held=bc.held))
                continue
            if bc.motion is not None:
                conds.append(_Condition(bc.name or f"#{i}", nodes, bc.components, None, None, bc.motion))
            else:
                zero = np.zeros(len(bc.components))
                conds.append(_Condition(bc.name or f"#{i}", nodes, bc.components, zero,
                                        np.asarray(bc.values, dtype=float)))
        motions = {rb.name: rb.motion for rb in problem.rigid}
        contacts = {c.name: bool(c.enabled) for c in problem.contacts}
        self.stages: list[StageSpec] = []
        self.stages.append(self._spec(0, problem.stage_name, problem.steps.factors, conds, np.zeros(0, np.int64),
                                      loads, values, targets, motions, contacts, ()))
        self.stages[0].friction = {c.name: c.friction for c in problem.contacts if c.friction > 0.0}
        self.stages[0].ramp = bool(getattr(problem, "ramp", True))
        eqs = list(getattr(problem, "equations", None) or [])
        eq_start, eq_target = np.zeros(len(eqs)), np.array([float(getattr(e, "value", 0.0)) for e in eqs])
        self.stages[0].equations = (eq_start, eq_target)
        #: whether an equation has a right-hand side in some stage (the model then sets them at every evaluation)
        self.equation_values = bool(np.any(eq_target)) or any(
            e.name and e.name in st.targets for st in problem.stages for e in eqs)
        zero = np.zeros(3)
        self.stages[0].rigid_loads = {ref.name: (zero, ref.force, zero, ref.moment)
                                      for ref in getattr(system, "reference", [])}
        for k, st in enumerate(problem.stages, start=1):
            prev = self.stages[-1]
            lam_end = prev.lam_end
            new_conds, released = _carried_conditions(prev, st)
            starting = []
            for c in late.get(st.name, []):
                target = st.targets.get(c.name)
                starting.append(_Condition(c.name, c.nodes, c.components, None,
                                           c.target if target is None else np.broadcast_to(
                                               np.asarray(target, dtype=float), c.target.shape).astype(float),
                                           from_state=True, held=c.held and target is None))
            new_conds += starting
            values = {key: values[key] + lam_end * (targets[key] - values[key]) for key in loads}
            targets = dict(values)
            for key in loads:
                if key in st.remove:
                    targets[key] = np.zeros_like(values[key])
                elif key in st.targets:
                    targets[key] = np.broadcast_to(np.asarray(st.targets[key], dtype=float),
                                                   values[key].shape).astype(float)
            new_motions = {}
            for name, m in prev.motions.items():
                pose = m.state(lam_end)
                nm = st.motions.get(name)
                new_motions[name] = StagedMotion(nm, *pose) if nm is not None else StagedMotion.hold(*pose)
            new_contacts = dict(prev.contacts)
            new_contacts.update({k2: bool(v) for k2, v in st.contacts.items()})
            cond_names = {c.name for c in prev.conditions}
            pairs_released = tuple(n for n in st.release if n not in cond_names and n in new_contacts)
            new_contacts.update({n: False for n in pairs_released})
            rel = np.unique(np.concatenate(released)) if released else np.zeros(0, np.int64)
            spec = self._spec(k, st.name, st.steps.factors, new_conds, rel, loads, values, targets,
                              new_motions, new_contacts, tuple(st.release), st.motions, pairs_released)
            spec.rigid_loads = _carried_rigid_loads(prev, st)
            spec.friction = {**prev.friction, **getattr(st, "friction", {})}
            spec.applied_names = tuple(c.name for c in starting)
            spec.ramp = bool(getattr(st, "ramp", True))
            eq_start = eq_start + lam_end * (eq_target - eq_start)
            eq_target = np.array([float(st.targets[e.name]) if e.name and e.name in st.targets else eq_start[i]
                                  for i, e in enumerate(eqs)])
            spec.equations = (eq_start, eq_target)
            self.stages.append(spec)
        self.n_dofs = n_dofs

    def _spec(self, index, name, factors, conds, released, loads, start, target, motions, contacts, names,
              moved=None, released_pairs=()):
        sysm = self.system
        f0 = np.zeros(sysm.n_dofs)
        f1 = np.zeros(sysm.n_dofs)
        followers = {}
        for key, load in loads.items():
            if getattr(load, "follower", False):
                followers[key] = (float(start[key][0]), float(target[key][0]))
                continue
            f0 += sysm.load_vector(load, start[key])
            f1 += sysm.load_vector(load, target[key])
        conds = list(conds)
        parked, parked_names, parked_moves = [], [], []
        for ref in getattr(sysm, "reference", []):
            comps = tuple(c for c in range(6) if c not in ref.free)
            if comps:
                conds.append(_Condition(f"rigid:{ref.name}", np.array([ref.A]), comps, None, None,
                                        motions[ref.name], ref))
            pairs = [c.name for c in self.problem.contacts if ref.name in (c.slave[0], c.master[0])]
            off = not any(contacts.get(n, True) for n in pairs) and not ref.attached.size
            # a stage motion for a body with free components takes them over: the body is held where the
            # stage found it and translated by the motion (e.g. a blank holder lifted off by displacement)
            # (a body with attached nodes: the motion moves its prescribed components on, the free ones stay free)
            driven = moved is not None and ref.name in moved and not ref.attached.size
            if ref.free and (off or driven):
                parked += [3 * (ref.A if c < 3 else ref.B) + c % 3 for c in ref.free]
                parked_names.append(ref.name)
                trans = tuple(c for c in ref.free if c < 3)
                if driven and trans:
                    parked_moves.append((3 * ref.A + np.array(trans), motions[ref.name], trans))
        constrained = np.zeros(sysm.n_dofs, dtype=bool)
        for c in conds:
            constrained[c.dofs] = True
        constrained[getattr(sysm, "planar_dofs", np.zeros(0, dtype=np.int64))] = True  # planar bodies' z-dofs: zero
        parked = np.array(sorted(parked), dtype=np.int64)
        constrained[parked] = True
        released = released[~constrained[released]] if released.size else released
        return StageSpec(index, name, tuple(factors), conds, released, f0, f1, motions, contacts, names,
                         constrained, parked=parked, parked_names=tuple(parked_names), parked_moves=parked_moves,
                         released_pairs=tuple(released_pairs), followers=followers)

    def __len__(self) -> int:
        return len(self.stages)

    def __getitem__(self, k: int) -> StageSpec:
        return self.stages[k]


def _carried_conditions(prev: StageSpec, st) -> tuple[list[_Condition], list[np.ndarray]]:
    """The Dirichlet conditions of stage ``st`` from those its previous stage ``prev`` left (values from their
    end value to the new target or held, motions continued from their pose), and the dofs of those ``st``
    releases. The conditions of rigid bodies are rebuilt from the stage's motions, not carried."""
    lam_end = prev.lam_end
    new_conds, released = [], []
    for c in prev.conditions:
        if c.rigid is not None:
            continue
        if c.name in st.release:
            released.append(c.dofs)
            continue
        start, pose = c.end(lam_end)
        if c.from_state and start is None:  # held at the state's values, unless given a target now
            if c.name in st.targets:
                new_conds.append(_Condition(c.name, c.nodes, c.components, None, np.broadcast_to(np.asarray(
                    st.targets[c.name], dtype=float), (len(c.components),)).astype(float), from_state=True))
            else:
                new_conds.append(c)
            continue
        if c.motion is None:
            target = np.asarray(st.targets.get(c.name, start), dtype=float)
            if target.shape != start.shape:
                target = np.broadcast_to(target, start.shape).astype(float)
            new_conds.append(_Condition(c.name, c.nodes, c.components, start, target))
        else:
            m = st.motions.get(c.name)
            nm = StagedMotion(m, *pose) if m is not None else StagedMotion.hold(*pose)
            new_conds.append(_Condition(c.name, c.nodes, c.components, None, None, nm))
    return new_conds, released


def _carried_rigid_loads(prev: StageSpec, st) -> dict:
    """The applied force and moment of every reference body in stage ``st``: (force, its target, moment, its
    target), from where the stage before left them to the stage's new values (removed: zero; else held)."""
    out = {}
    lam_end = prev.lam_end
    for name, (f0, f1, m0, m1) in prev.rigid_loads.items():
        f, m = f0 + lam_end * (f1 - f0), m0 + lam_end * (m1 - m0)
        if name in st.remove:
            out[name] = (f, 0.0 * f, m, 0.0 * m)
        elif name in st.targets:  # a new force, or a table with a new force and/or moment
            tgt = st.targets[name]
            if isinstance(tgt, dict):
                out[name] = (f, np.asarray(tgt.get("force", f), dtype=float), m,
                             np.asarray(tgt.get("moment", m), dtype=float))
            else:
                out[name] = (f, np.asarray(tgt, dtype=float), m, m)
        else:
            out[name] = (f, f, m, m)
    return out


class Loading:
    """The prescribed displacements and external forces of one stage as functions of its load factor."""

    def __init__(self, spec: StageSpec, X: np.ndarray, release: np.ndarray | None = None,
                 held: np.ndarray | None = None, parked: np.ndarray | None = None, applied: np.ndarray | None = None):
        self.spec = spec
        self.X = X
        n = len(spec.load_start)
        #: the displacements the dofs of conditions that started in a later stage had when they started
        self.applied = np.zeros(n) if applied is None else applied
        self.release = np.zeros(n) if release is None else release
        self.held = np.zeros(n) if held is None else held
        self.parked = np.zeros(n) if parked is None else parked  # displacements of the parked dofs
        self.constrained = spec.constrained
        self.free = ~spec.constrained
        self._dofs = [c.dofs for c in spec.conditions]
        self._has_motion = any(c.motion is not None for c in spec.conditions)

    def prescribed(self, lam: float) -> np.ndarray:
        """Displacement vector: zero on free dofs, the conditions' values on constrained ones (later
        conditions win where sets overlap)."""
        u = np.zeros(len(self.constrained))
        for c, dofs in zip(self.spec.conditions, self._dofs):
            if c.from_state:
                u0 = self.applied[dofs]
                u[dofs] = u0 if c.held else u0 + lam * (np.tile(c.target, len(c.nodes)) - u0)
            else:
                u[dofs] = c.values(self.X, lam)
        if self.spec.parked.size:
            u[self.spec.parked] = self.parked[self.spec.parked]
            for dofs, motion, comps in self.spec.parked_moves:
                u[dofs] += motion.moved_by(lam)[list(comps)]
        return u

    def external(self, lam: float) -> np.ndarray:
        """External force vector at lam: loads, the released reactions' ramp, the held forces."""
        s = self.spec
        w = lam if s.ramp else 1.0  # (a step load: the target from the stage's first instant, at lam = 0 already)
        f = s.load_start + w * (s.load_target - s.load_start)
        if s.released.size or s.released_pairs or np.any(self.held):
            f = f + max(0.0, 1.0 - lam) * self.release + self.held
        return f

    def equation_rhs(self, lam: float) -> np.ndarray:
        """The right-hand sides of the problem's equations at lam (ramped as the loads are)."""
        w = lam if self.spec.ramp else 1.0
        b0, b1 = self.spec.equations
        return b0 + w * (b1 - b0)

    def follower_values(self, lam: float) -> dict:
        """The follower pressures' values at lam (load key -> pressure), ramped as the other loads are."""
        w = lam if self.spec.ramp else 1.0
        return {k: p0 + w * (p1 - p0) for k, (p0, p1) in self.spec.followers.items()}

    def rigid_load(self, name: str, lam: float) -> tuple[np.ndarray, np.ndarray]:
        """The applied force and moment of reference body ``name`` at lam."""
        f0, f1, m0, m1 = self.spec.rigid_loads[name]
        return f0 + lam * (f1 - f0), m0 + lam * (m1 - m0)

    def left_over(self) -> np.ndarray:
        """The held force the stages after this one inherit: what the ramp has not removed at its end."""
        return self.held + max(0.0, 1.0 - self.spec.lam_end) * self.release
