"""Joint-space paths for the Panda's free-space phases: OMPL's RRT-Connect plus seeded shortcuts.

``plan_path(start, goal, valid)`` searches the datasheet joint box with OMPL (the only module of
this repository that imports ``ompl``) against the caller's ``valid(q)`` collision check, then
shortens the path with our own seeded shortcutting and re-checks every returned segment with
``valid`` at the checking resolution. With a batched check (``valid_batch``, e.g. the sphere
model of `motion.sphere_check`) it first tries the straight segment and seeded one-via-point
detours, whole segments per call (and, with ``verify``, checks what it finds with ``valid``);
OMPL runs only when that finds nothing. ``path_trajectory`` times the polyline with ruckig, one
rest-to-rest straight segment per piece (an RRT path has sharp corners).

Determinism. OMPL 2.0.1 seeds every ``RNG`` object from one process-global seed generator, and
its Python bindings cannot replace the planner's state sampler. ``RNG.setSeed`` still re-seeds
that generator after the first RNG exists (it only logs an error, which we mute), so each call
re-seeds it with ``config.seed`` right before it builds the planner, under a lock: one seed, one
path, in any order of calls. The planner stops at its first exact solution (RRT* too: the cost
threshold is infinite), so the path does not depend on the machine's speed; shortcutting is
bounded by ``shortcut_attempts``, ``simplify_time`` only caps it (evidence "simplify_capped").
"""

from __future__ import annotations

import math
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from itertools import pairwise

import numpy as np
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from motion.errors import MotionError
from motion.trajectory import JointTrajectory, SpeedLimits, as_path, straight_segment
from robots.panda import PANDA, PandaSpec

PLANNERS = {"rrt_connect": og.RRTConnect, "rrt": og.RRT, "rrt_star": og.RRTstar}
_OMPL_LOCK = threading.RLock()  # OMPL's seed generator is process-global
_BOUND_TOL = 1e-6  # the tolerance of PandaSpec.clamp_error; the OMPL box is widened by it
ou.setLogLevel(ou.LOG_WARN)  # OMPL logs INFO lines to stderr by default; keep the CLI quiet
_SEED_RANGE = 2147483562  # OMPL's seed engine (minstd-seeded ranlux24_base): seeds alias mod this


@dataclass(frozen=True)
class PathPlannerConfig:
    """Settings of `plan_path`; override with ``dataclasses.replace``."""

    planner: str = "rrt_connect"  # one of PLANNERS
    time_limit: float = 5.0  # s of search before "no_path"
    seed: int = 0  # >= 0; the same seed gives the same path
    resolution: float = 0.005  # checking step as a fraction of the joint box's diagonal
    range: float = 0.0  # RRT extension step in rad; 0: OMPL's default (0.2 x diagonal)
    simplify: bool = True  # seeded shortcutting and vertex reduction
    simplify_time: float = 1.0  # s, a cap only: the attempts bound the work
    shortcut_attempts: int = 50  # random partial shortcuts tried (OMPL's shortcutPath, seeded)
    # with a batched check (``plan_path(..., valid_batch=...)``): via points tried per round,
    # their spread about the midpoint per round (rad), and whether ``valid`` verifies the path
    # it finds (off: ``valid_batch`` must be at least as strict as ``valid``, so what it finds
    # free at the checking resolution is free; the sphere model is, tests/motion/
    # test_sphere_check.py, and the guard checks the timed detour again)
    vias: int = 16
    via_spreads: tuple[float, ...] = (0.3, 0.6, 1.0, 1.5)
    verify: bool = False
    batch_time_limit: float = 0.5  # s for the batched RRT-Connect before OMPL takes over

    def __post_init__(self):
        if self.planner not in PLANNERS:
            raise MotionError(f"unknown planner {self.planner!r}; valid: {', '.join(PLANNERS)}")
        checks = {
            "time_limit": self.time_limit > 0.0,
            "seed": isinstance(self.seed, int | np.integer) and self.seed >= 0,
            "resolution": 0.0 < self.resolution < 1.0,
            "range": self.range >= 0.0,
            "simplify_time": self.simplify_time >= 0.0,
            "shortcut_attempts": self.shortcut_attempts >= 0,
            "vias": self.vias >= 1,
            "via_spreads": all(s > 0.0 for s in self.via_spreads),
            "batch_time_limit": self.batch_time_limit >= 0.0,
        }
        for name, ok in checks.items():
            if not ok:
                raise MotionError(f"PathPlannerConfig.{name} = {getattr(self, name)!r} is invalid")


@dataclass(frozen=True, eq=False)
class PathResult:
    """A joint-space path or the reason there is none ("invalid_start", "invalid_goal",
    "no_path", "invalid_path"); ``checks`` counts calls to the caller's ``valid``."""

    ok: bool
    path: np.ndarray | None  # (K, J) rad, read-only, start and goal included
    failure: str | None
    evidence: dict
    time_s: float  # planning + simplification + re-validation wall time
    checks: int


class _Checker:
    """The caller's ``valid`` with a call count; straight segments checked every ``step`` rad."""

    def __init__(self, valid: Callable[[np.ndarray], bool], step: float):
        self.valid, self.step, self.calls = valid, step, 0

    def __call__(self, q) -> bool:
        self.calls += 1
        return bool(self.valid(np.array(q, dtype=np.float64)))

    def segment(self, a: np.ndarray, b: np.ndarray, ends: bool = False) -> bool:
        """The points ``a + k/n (b - a)``, 0 < k < n = ceil(|b - a| / step), as OMPL's discrete
        motion validator places them (bisection order); ``ends`` checks a and b as well."""
        if ends and not (self(a) and self(b)):
            return False
        n = max(1, math.ceil(float(np.linalg.norm(b - a)) / self.step))
        return all(self(a + (k / n) * (b - a)) for k in _bisection_order(n))


def _bisection_order(n: int) -> list[int]:
    order, queue = [], deque([(1, n - 1)])
    while queue:
        lo, hi = queue.popleft()
        if lo <= hi:
            mid = (lo + hi) // 2
            order.append(mid)
            queue.extend([(lo, mid - 1), (mid + 1, hi)])
    return order


def _joint_vector(name: str, q, spec: PandaSpec) -> np.ndarray:
    q = np.asarray(q, dtype=np.float64)
    n_joints = len(spec.arm_joints)
    if q.shape != (n_joints,):
        raise MotionError(f"{name} has shape {q.shape}; expected ({n_joints},)")
    if not np.isfinite(q).all():
        raise MotionError(f"{name} contains NaN or inf: {q.tolist()}")
    error = spec.clamp_error(q)
    if error is not None:
        raise MotionError(f"{name}: {error}")
    return q


def _solve(start, goal, checker: _Checker, lo, hi, config: PathPlannerConfig):
    """OMPL's search; the (K, J) path of its first exact solution or None, and its status."""
    n_joints = start.size
    with _OMPL_LOCK:
        level = ou.getLogLevel()
        ou.setLogLevel(ou.LOG_NONE)  # re-seeding after the first RNG logs an error
        ou.RNG.setSeed(int(config.seed) % _SEED_RANGE + 1)
        ou.setLogLevel(level)
        space = ob.RealVectorStateSpace(n_joints)
        bounds = ob.RealVectorBounds(n_joints)
        for i in range(n_joints):
            bounds.setLow(i, float(lo[i]))
            bounds.setHigh(i, float(hi[i]))
        space.setBounds(bounds)
        si = ob.SpaceInformation(space)
        si.setStateValidityChecker(lambda state: checker(state[0:n_joints]))
        si.setStateValidityCheckingResolution(config.resolution)
        si.setup()
        ends = si.allocState(), si.allocState()
        for state, q in zip(ends, (start, goal), strict=True):
            state[0:n_joints] = q.tolist()
        pdef = ob.ProblemDefinition(si)
        pdef.setStartAndGoalStates(*ends)
        objective = ob.PathLengthOptimizationObjective(si)
        objective.setCostThreshold(ob.Cost(math.inf))  # any solution is good enough: stop at it
        pdef.setOptimizationObjective(objective)
        planner = PLANNERS[config.planner](si)
        if config.range > 0.0:
            planner.setRange(config.range)
        planner.setProblemDefinition(pdef)
        planner.setup()
        deadline = time.perf_counter() + config.time_limit
        status = planner.solve(
            ob.PlannerTerminationCondition(
                lambda: pdef.hasExactSolution() or time.perf_counter() > deadline
            )
        ).asString()
        if not pdef.hasExactSolution():
            return None, status
        states = pdef.getSolutionPath().getStates()
        return np.array([s[0:n_joints] for s in states], dtype=np.float64), status  # (K, J)


def _reduce(path: np.ndarray, checker: _Checker) -> np.ndarray:
    """Drop each interior vertex whose neighbours see each other (one greedy pass)."""
    keep = [path[0]]
    for i in range(1, len(path) - 1):
        if not checker.segment(keep[-1], path[i + 1]):
            keep.append(path[i])
    return np.array([*keep, path[-1]])  # (K', J)


def _shortcut(path: np.ndarray, checker: _Checker, rng, attempts: int, deadline: float):
    """OMPL's shortcutPath, seeded: join two random points of the path when the chord is valid."""
    for _ in range(attempts):
        if len(path) < 3 or time.perf_counter() > deadline:
            break
        knots = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(path, axis=0), axis=1))])
        t = np.sort(rng.uniform(0.0, knots[-1], size=2))
        a, b = np.clip(np.searchsorted(knots, t, side="right") - 1, 0, len(path) - 2)
        if a == b:
            continue
        p, q = _point(path, knots, a, t[0]), _point(path, knots, b, t[1])
        # the chord and both cut pieces are new segments: check each at the resolution
        pieces = ((p, q, True), (path[a], p, False), (q, path[b + 1], False))
        if all(checker.segment(*piece) for piece in pieces):
            path = np.concatenate([path[: a + 1], [p, q], path[b + 1 :]])  # (K', J)
    return path


def _point(path: np.ndarray, knots: np.ndarray, i: int, s: float) -> np.ndarray:
    w = (s - knots[i]) / max(knots[i + 1] - knots[i], 1e-300)
    return path[i] + w * (path[i + 1] - path[i])


def _dedupe(path: np.ndarray) -> np.ndarray:
    """Drop repeated vertices; the first and last stay exactly start and goal."""
    steps = np.linalg.norm(np.diff(path, axis=0), axis=1)  # (K-1,)
    out = path[np.concatenate([[True], steps > 1e-9])]
    if len(out) < 2:
        return path[[0, -1]].copy()
    out[-1] = path[-1]
    return out


class _Batch:
    """The caller's ``valid_batch`` (B, J) -> (B,) with a count of configurations checked."""

    def __init__(self, valid_batch: Callable[[np.ndarray], np.ndarray], step: float):
        self.valid_batch, self.step, self.configs, self.calls = valid_batch, step, 0, 0

    def __call__(self, q: np.ndarray) -> np.ndarray:
        self.configs, self.calls = self.configs + len(q), self.calls + 1
        ok = np.asarray(self.valid_batch(np.ascontiguousarray(q, dtype=np.float64)), dtype=bool)
        if ok.shape != (len(q),):
            raise MotionError(f"valid_batch returned shape {ok.shape} for {len(q)} configurations")
        return ok

    def segments(
        self, a: np.ndarray, b: np.ndarray, stride: int = 8, full: bool = True, rest: bool = False
    ):
        """(P,) bool: whether each segment a[p] -> b[p] ((P, J) each) is valid at the points
        ``a + k/n (b - a)``, 0 <= k <= n = ceil(|b - a| / step) (the ends included), in two
        batched calls: every ``stride``-th point of every segment, then the rest of those
        still valid (``full``; else only the first call: a necessary condition). ``rest``:
        the first call's points are known valid; only the second call is made."""
        n = np.maximum(1, np.ceil(np.linalg.norm(b - a, axis=1) / self.step)).astype(int)  # (P,)
        seg = np.repeat(np.arange(len(n)), n + 1)  # (N,) the segment of each point
        k = np.arange(seg.size) - np.repeat(np.cumsum(n + 1) - (n + 1), n + 1)  # (N,) 0..n
        t = (k / n[seg])[:, None]
        points = a[seg] + t * (b[seg] - a[seg])  # (N, J)
        alive = np.ones(len(n), dtype=bool)
        coarse = (k % stride == 0) | (k == n[seg])
        for part in (~coarse,) if rest else (coarse, ~coarse) if full else (coarse,):
            rows = np.flatnonzero(part & alive[seg])
            if rows.size:
                bad = rows[~self(points[rows])]
                alive[seg[bad]] = False
        return alive


def _screened(valid_batch: Callable[[np.ndarray], np.ndarray], checker: _Checker):
    """``valid_batch``, and ``checker`` (the exact check) on each configuration it refuses."""

    def check(q: np.ndarray) -> np.ndarray:
        ok = np.array(valid_batch(q), dtype=bool)  # (B,)
        for k in np.flatnonzero(~ok):
            ok[k] = checker(q[k])
        return ok

    return check


def _through(start, goal, vias: np.ndarray, batch: _Batch, full: bool, rest: bool = False):
    """(V,) bool: start -> via -> goal valid for each via (V, J) (``full``: at every point;
    else at every 8th, a necessary condition; ``rest``: every 8th point is known valid)."""
    ends = np.broadcast_to(start, vias.shape), np.broadcast_to(goal, vias.shape)
    a, b = np.concatenate([ends[0], vias]), np.concatenate([vias, ends[1]])
    ok = batch.segments(a, b, full=full, rest=rest)
    return ok[: len(vias)] & ok[len(vias) :]  # (V,) both halves valid


def _shortest_via(start, goal, vias: np.ndarray, batch: _Batch) -> np.ndarray | None:
    """The via point (J,) of the shortest valid start -> via -> goal, or None: all vias at every
    8th point in one call, then the survivors in order of length, two at a time, in full."""
    lengths = np.linalg.norm(vias - start, axis=1) + np.linalg.norm(goal - vias, axis=1)
    alive = np.flatnonzero(_through(start, goal, vias, batch, full=False))
    alive = alive[np.argsort(lengths[alive], kind="stable")]
    for k in range(0, alive.size, 2):
        chunk = vias[alive[k : k + 2]]
        ok = _through(start, goal, chunk, batch, full=True, rest=True)  # every 8th: done
        if ok.any():
            return chunk[int(np.argmax(ok))]
    return None


def _via_search(start, goal, batch: _Batch, lo, hi, config: PathPlannerConfig):
    """A path (K <= 3, J) start -> goal straight or through one via point, each segment valid
    under ``batch``, or None. Rounds of ``config.vias`` seeded via points, Gaussian about the
    midpoint with the round's spread; the shortest valid one is pulled towards the midpoint
    while its segments stay valid."""
    if batch.segments(start[None], goal[None])[0]:
        return np.stack([start, goal])
    rng = np.random.default_rng(config.seed)
    mid = (start + goal) / 2.0
    for spread in config.via_spreads:
        vias = np.clip(mid + rng.normal(0.0, spread, (config.vias, start.size)), lo, hi)  # (V, J)
        via = _shortest_via(start, goal, vias, batch)
        if via is None:
            continue
        pulled = mid + np.array([0.25, 0.5, 0.75])[:, None] * (via - mid)  # (3, J) shorter first
        shorter = _shortest_via(start, goal, pulled, batch)
        return np.stack([start, via if shorter is None else shorter, goal])
    return None


def _prefix(batch: _Batch, a: np.ndarray, b: np.ndarray) -> np.ndarray | None:
    """The farthest point of a -> b ((J,) each) up to which every checked point is valid (one
    batched call over the whole line), or None when the first step is already blocked."""
    n = max(1, math.ceil(float(np.linalg.norm(b - a)) / batch.step))
    points = a + (np.arange(1, n + 1) / n)[:, None] * (b - a)  # (n, J)
    ok = batch(points)
    stop = n if ok.all() else int(np.argmin(ok))  # points[:stop] are valid
    return None if stop == 0 else points[stop - 1]


def _batched_connect(start, goal, batch: _Batch, lo, hi, config: PathPlannerConfig, deadline):
    """RRT-Connect (Kuffner and LaValle, 2000) with whole-edge batched checks: each EXTEND
    checks its edge (at most ``reach`` rad) in one call, each CONNECT the whole line to the
    other tree's new node in one call and keeps its valid prefix. The (K, J) path or None."""
    rng = np.random.default_rng(config.seed + 1)
    reach = config.range if config.range > 0 else 1.0
    trees = [([start], [-1]), ([goal], [-1])]  # (nodes, parents) grown from start, from goal
    while time.perf_counter() < deadline:
        nodes, parents = trees[0]
        target = rng.uniform(lo, hi)
        near = int(np.argmin(np.linalg.norm(np.array(nodes) - target, axis=1)))
        step = target - nodes[near]
        step *= min(1.0, reach / max(float(np.linalg.norm(step)), 1e-12))
        new = _prefix(batch, nodes[near], nodes[near] + step)
        if new is not None:
            nodes.append(new)
            parents.append(near)
            others, other_parents = trees[1]
            near = int(np.argmin(np.linalg.norm(np.array(others) - new, axis=1)))
            reached = _prefix(batch, others[near], new)
            if reached is not None:
                others.append(reached)
                other_parents.append(near)
                if np.array_equal(reached, new):
                    first, second = sorted(trees, key=lambda tree: tree[0][0] is not start)
                    # start ... the meeting node, then on from it to the goal
                    return np.array([*_branch(*first)[::-1], *_branch(*second)[1:]])
        trees.reverse()
    return None


def _branch(nodes: list, parents: list) -> list:
    """The nodes from the last one back to its tree's root."""
    out, k = [], len(nodes) - 1
    while k >= 0:
        out.append(nodes[k])
        k = parents[k]
    return out


def _batched_reduce(path: np.ndarray, batch: _Batch) -> np.ndarray:
    """From each kept vertex, jump to the farthest later vertex it sees (one call each)."""
    keep, i = [path[0]], 0
    while i < len(path) - 1:
        later = np.arange(i + 1, len(path))
        ok = batch.segments(np.broadcast_to(path[i], (later.size, path.shape[1])), path[later])
        i = int(later[np.flatnonzero(ok)].max()) if ok.any() else i + 1
        keep.append(path[i])
    return np.array(keep)


def plan_path(
    start,
    goal,
    valid: Callable[[np.ndarray], bool],
    spec: PandaSpec = PANDA,
    config: PathPlannerConfig = PathPlannerConfig(),
    valid_batch: Callable[[np.ndarray], np.ndarray] | None = None,
) -> PathResult:
    """A collision-free joint path ``start -> goal`` (each (J,)) inside spec's joint limits.

    ``valid(q)`` gets a fresh (J,) float64 array and says whether q is collision-free. Every
    segment of the returned path is checked with it every ``resolution x diagonal`` rad (and at
    its ends).

    ``valid_batch(q (B, J)) -> (B,) bool``, optional: a fast batched check that is at least as
    strict as ``valid`` (e.g. `motion.sphere_check.SphereCollision.valid_batch` beside the mesh
    model). It is tried first when it accepts start and goal: the straight segment, then
    rounds of seeded via points, every segment's points checked in one call or two, then an
    RRT-Connect with whole-edge batched checks for at most ``config.batch_time_limit``; the
    path it finds is returned (evidence "search": "via" or "connect"), with ``config.verify``
    only once ``valid`` accepts every segment of it at the checking resolution. When
    ``valid_batch`` refuses start or goal and ``valid`` accepts both, the batched search asks
    ``valid`` about each configuration ``valid_batch`` refuses (evidence "screened"). Otherwise
    ("batched_failed", "batched_refused") OMPL searches with ``valid`` as without it.

    Misuse (shapes, NaN, start or goal outside the limits) raises MotionError; an
    invalid start or goal and a search that runs out of time are failures in the result.
    """
    start, goal = _joint_vector("start", start, spec), _joint_vector("goal", goal, spec)
    if not callable(valid):
        raise MotionError(f"valid must be a callable q -> bool, got {type(valid).__name__}")
    if valid_batch is not None and not callable(valid_batch):
        kind = type(valid_batch).__name__
        raise MotionError(f"valid_batch must be None or a callable (B, J) -> (B,), got {kind}")
    t0 = time.perf_counter()
    lo, hi = np.array(spec.q_min) - _BOUND_TOL, np.array(spec.q_max) + _BOUND_TOL
    checker = _Checker(valid, config.resolution * float(np.linalg.norm(hi - lo)))
    evidence = {"planner": config.planner, "seed": config.seed, "step_rad": checker.step}

    def result(path, failure, **extra) -> PathResult:
        if path is not None:
            path.flags.writeable = False
        info = evidence | extra | {"checks": checker.calls}
        dt = time.perf_counter() - t0
        return PathResult(failure is None, path, failure, info, dt, checker.calls)

    if valid_batch is not None:
        batch = _Batch(valid_batch, checker.step)
        path = _batched_path(start, goal, batch, checker, (lo, hi), config, evidence)
        evidence |= {"batch_configs": batch.configs, "batch_calls": batch.calls}
        evidence |= {"batch_s": time.perf_counter() - t0}
        if path is not None and (
            not config.verify or all(checker.segment(a, b, ends=True) for a, b in pairwise(path))
        ):
            search = "via" if len(path) <= 3 else "connect"
            info = {"search": search, "waypoints": len(path), "length": _length(path)}
            return result(path, None, **info, verified=config.verify)
        evidence["search"] = "batched_failed" if path is None else "batched_refused"
    for name, q in (("start", start), ("goal", goal)):
        if not checker(q):
            return result(None, f"invalid_{name}", **{name: q.tolist()})
    raw, status = _solve(start, goal, checker, lo, hi, config)
    plan_s, plan_checks = time.perf_counter() - t0, checker.calls
    if raw is None:
        return result(None, "no_path", status=status, time_limit=config.time_limit, plan_s=plan_s)
    raw[0], raw[-1] = start, goal
    path, capped = _simplified(raw, checker, config)
    info = {"status": status, "plan_s": plan_s, "plan_checks": plan_checks}
    info |= {"raw_waypoints": len(raw), "waypoints": len(path), "simplify_capped": capped}
    info |= {"raw_length": _length(raw), "length": _length(path)}
    for candidate in (path, raw) if config.simplify else (path,):  # the raw path as fallback
        if all(checker.segment(a, b, ends=True) for a, b in pairwise(candidate)):
            return result(candidate, None, **info, simplified=candidate is path)
    return result(None, "invalid_path", **info)


def _batched_path(start, goal, batch: _Batch, checker: _Checker, bounds, config, evidence: dict):
    """`plan_path`'s batched search with ``batch`` between joint ``bounds`` (lo, hi): the
    seeded via points, then RRT-Connect for at most ``config.batch_time_limit``; the path
    found (reduced), or None, also when ``batch`` refuses start or goal. When it refuses an
    end that ``checker`` accepts, it asks ``checker`` about every configuration it refuses
    from then on (the search is then as strict as ``valid``), noted in ``evidence``."""
    lo, hi = bounds
    ends = batch(np.stack([start, goal]))
    if not ends.all() and checker(start) and checker(goal):
        # the stricter check refuses an end that ``valid`` accepts: ask ``valid`` about
        # every configuration the batch refuses (the search is then as strict as valid)
        batch.valid_batch = _screened(batch.valid_batch, checker)
        evidence["screened"] = True
        ends = batch(np.stack([start, goal]))
    if not ends.all():
        return None
    path = _via_search(start, goal, batch, lo, hi, config)
    if path is None:
        deadline = time.perf_counter() + min(config.batch_time_limit, config.time_limit)
        path = _batched_connect(start, goal, batch, lo, hi, config, deadline)
        if path is not None:
            path = _dedupe(_batched_reduce(path, batch))
    return path


def _simplified(raw: np.ndarray, checker: _Checker, config) -> tuple[np.ndarray, bool]:
    """The search's ``raw`` path without repeats and, with ``config.simplify``, reduced and
    shortcut within ``config.simplify_time``; and whether that time ran out (the path then
    depends on the machine's speed)."""
    path, deadline = _dedupe(raw), time.perf_counter() + config.simplify_time
    if config.simplify:
        rng = np.random.default_rng(config.seed)
        path = _reduce(path, checker)
        path = _reduce(_shortcut(path, checker, rng, config.shortcut_attempts, deadline), checker)
        path = _dedupe(path)
    return path, config.simplify and time.perf_counter() > deadline


def _length(path: np.ndarray) -> float:
    return float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum())


def path_trajectory(
    path, dt: float = 0.002, spec: PandaSpec = PANDA, limits: SpeedLimits = SpeedLimits()
) -> JointTrajectory:
    """Rest-to-rest `straight_segment` along each piece of ``path`` (K >= 2, J), one timeline.

    The trajectory stops at every waypoint (zero velocity), so it never cuts a corner of the
    validated polyline; zero-length pieces are skipped.
    """
    path = as_path(path, spec)
    pieces = [straight_segment(a, b, dt, spec, limits) for a, b in pairwise(path)]
    parts = [p for p in pieces if p.times.size > 1]  # zero-length pieces are a single sample
    if not parts:
        return pieces[-1]
    offsets = np.cumsum([0.0] + [p.duration for p in parts[:-1]])
    cut = [0] + [1] * (len(parts) - 1)  # a later piece's first sample repeats the previous end

    def joined(name: str) -> np.ndarray:
        return np.concatenate([getattr(p, name)[c:] for p, c in zip(parts, cut, strict=True)])

    times = np.concatenate([o + p.times[c:] for p, o, c in zip(parts, offsets, cut, strict=True)])
    return JointTrajectory(
        times, joined("positions"), joined("velocities"), joined("accelerations")
    )
