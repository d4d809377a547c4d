"""Batched inverse kinematics for the Panda's TCP with pytorch_kinematics, plus pose helpers.

`IKSolver` builds the serial chain ``base_link -> tcp_link`` once (float64) and solves batches of
4x4 targets given in the base frame by damped Gauss-Newton (Levenberg-Marquardt) steps on the
chain's geometric Jacobian, all rows of a batch in one numpy array, clamped to the datasheet limits.
Each target is seeded with the current configuration (the warm start: the nearest IK branch,
a few iterations), the home pose and a few Gaussian perturbations of the current configuration,
all in one batch; rows stop iterating as they converge, and the batch stops once every target
has a converged seed (the valid solution closest to the current configuration is kept). A row
is ``ok`` when it converged and lies inside the datasheet limits; non-convergence is a returned
status, never an exception. pytorch_kinematics supplies the chain for `fk`, `fk_tensor` and
`ik_refine`; the iterations run on a numpy float64 copy of the same URDF chain.

`ik_refine` is the differentiable hook for joint task-motion optimisation: one Gauss-Newton step
at the detached solution, so ``d q / d target = pinv(J)`` by the implicit-function theorem.
"""

from __future__ import annotations

import contextlib
import io
import logging
import math
import os
from dataclasses import dataclass

import numpy as np
import torch

from motion.errors import MotionError
from robots.panda import PANDA, PandaSpec, urdf_path

log = logging.getLogger(__name__)
POLISH = 1e-3  # Gauss-Newton iterates until the errors are this share of the tolerances
EDGE = 1e-3  # rad: a solution this close to a joint limit counts as pinned there
NEAR = 1e-2  # |pose error| (m and rad together) below which the null-space pull stops


@dataclass(frozen=True)
class IKConfig:
    """Damped Gauss-Newton settings (motion-research notes, section 2)."""

    max_iterations: int = 60  # Levenberg-Marquardt steps per stage (warm start, then retries)
    pos_tolerance: float = 1e-4  # m
    rot_tolerance: float = 1e-3  # rad
    perturbed_seeds: int = 4  # Gaussian perturbations of q_current, besides q_current and q_home
    seed_std: float = 0.3  # rad, std of those perturbations
    seed: int = 0  # seeds the perturbations' torch.Generator (fresh per solve: deterministic)
    damping: float = 1e-6  # Levenberg-Marquardt lambda^2 added to J J^T (m^2, rad^2)
    max_step: float = 0.5  # rad, the largest joint change of one step (a trust region)
    null_gain: float = 0.5  # share of the way back to the seed per step, in the null space


@dataclass(frozen=True, eq=False)
class IKResult:
    """One IK solution per target; arrays are read-only numpy."""

    ok: np.ndarray  # (B,) bool: converged and inside the datasheet limits
    q: np.ndarray  # (B, J): the valid solution closest to q_current (else the best attempt)
    pos_err: np.ndarray  # (B,) m
    rot_err: np.ndarray  # (B,) rad


def _import_pytorch_kinematics():
    """Import pytorch_kinematics (its package ``__init__`` imports mujoco, for its MJCF loader).

    MuJoCo picks its OpenGL backend from ``MUJOCO_GL`` once, when first imported; unset, that
    would be GLFW, which needs a display. So the simulators' default (headless EGL unless the
    user chose one, `robots.mujoco_loader`) is set before, as docs/motion.md says; the import
    machinery itself is left alone.
    """
    os.environ.setdefault("MUJOCO_GL", "egl")
    import pytorch_kinematics

    return pytorch_kinematics


def _as_float64(x, shape_tail: tuple[int, ...], name: str) -> np.ndarray:
    """``x`` as float64 with trailing shape ``shape_tail``, adding a batch axis when missing."""
    try:
        a = np.array(x, dtype=np.float64)  # a copy: torch.from_numpy needs a writable array
    except (TypeError, ValueError):
        raise MotionError(f"{name} is not a numeric array") from None
    if a.shape == shape_tail:
        a = a[None]
    if a.ndim != len(shape_tail) + 1 or a.shape[1:] != shape_tail:
        want = ", ".join(map(str, shape_tail))
        raise MotionError(f"{name} has shape {a.shape}; expected ({want}) or (B, {want})")
    if not np.isfinite(a).all():
        raise MotionError(f"{name} contains NaN or inf")
    return a


class IKSolver:
    """Batched IK and FK of ``spec.base_link -> spec.tcp_link`` (float64, CPU)."""

    def __init__(self, spec: PandaSpec = PANDA, config: IKConfig = IKConfig()):
        pk = _import_pytorch_kinematics()
        self.spec = spec
        self.config = config
        self._pk = pk
        stderr = io.StringIO()  # the URDF parser writes "Unknown tag material/contact" here
        with contextlib.redirect_stderr(stderr):
            chain = pk.build_serial_chain_from_urdf(
                urdf_path(spec).read_bytes(), spec.tcp_link, spec.base_link
            )
        for line in stderr.getvalue().splitlines():
            log.debug("URDF parser: %s", line)
        self.chain = chain.to(dtype=torch.float64)
        names = tuple(self.chain.get_joint_parameter_names())
        if names != spec.arm_joints:
            raise MotionError(f"chain joints {names} differ from spec.arm_joints")
        # Clamp (and refine) inside the datasheet limits, not the URDF's hard ones.
        self.chain.low = torch.tensor(spec.q_min, dtype=torch.float64)
        self.chain.high = torch.tensor(spec.q_max, dtype=torch.float64)
        self.q_min = np.array(spec.q_min)
        self.q_max = np.array(spec.q_max)
        self._kin = _kinematics(spec)  # the same chain for numpy FK and Jacobians

    @property
    def dof(self) -> int:
        return len(self.spec.arm_joints)

    def fk_tensor(self, q: torch.Tensor) -> torch.Tensor:
        """Differentiable FK: (B, J) float64 tensor -> (B, 4, 4) TCP poses in the base frame."""
        return self.chain.forward_kinematics(q).get_matrix()

    def fk(self, q) -> np.ndarray:
        """TCP poses (B, 4, 4) in the base frame of q (J,) or (B, J); (J,) counts as B = 1."""
        qa = _as_float64(q, (self.dof,), "q")  # (B, J)
        with torch.no_grad():
            return self.fk_tensor(torch.from_numpy(qa)).numpy()

    def tcp_positions(self, q) -> np.ndarray:
        """TCP positions (B, 3) in the base frame of ``q`` (B, J) by the numpy kinematics of the
        solver's own iterations (no torch; within 1e-6 m of `fk`)."""
        qa = _as_float64(q, (self.dof,), "q")  # (B, J)
        return _fk_jacobian(qa, *self._kin)[0][:, :3, 3]

    def _seeds(self, q_current: np.ndarray) -> torch.Tensor:
        """(M - 1, J) more seeds besides q_current: q_home, Gaussian perturbations of
        q_current (float64 tensor)."""
        gen = torch.Generator().manual_seed(self.config.seed)
        q0 = torch.from_numpy(q_current)
        noise = torch.randn(
            (self.config.perturbed_seeds, self.dof), generator=gen, dtype=torch.float64
        )
        seeds = torch.cat(
            [
                torch.tensor(self.spec.q_home, dtype=torch.float64)[None],
                q0 + self.config.seed_std * noise,
            ]
        )  # (M - 1, J)
        return torch.clamp(seeds, self.chain.low, self.chain.high)

    def _iterate(
        self,
        q: np.ndarray,
        h: np.ndarray,
        iterations: int,
        clamp: bool = True,
        groups: np.ndarray | None = None,
    ):
        """Levenberg-Marquardt from ``q`` (R, J) towards ``h`` (R, 4, 4), every row stopping
        once within POLISH x the tolerances: (q (R, J), pos_err (R,), rot_err (R,),
        converged (R,) within the tolerances). A step that does not lower a row's error is
        taken back and that row's damping raised tenfold; one that does lowers it tenfold.
        ``groups`` (R,) sorted ints: the rows of a group are seeds of one target, the first
        one the warm start; all rows stop once every group has a converged row and every warm
        start has converged or got stuck. Numpy float64 on `_fk_jacobian`."""
        cfg = self.config
        q, seed = q.copy(), q.copy()
        rows = q.shape[0]
        pos, rot = np.full(rows, np.inf), np.full(rows, np.inf)
        err = np.full(rows, np.inf)  # (R,) |e| at q
        lam = np.full(rows, cfg.damping)  # (R,) per-row damping
        jac_at = np.zeros((rows, 6, q.shape[1]))  # (R, 6, J) at q
        e_at = np.zeros((rows, 6))  # (R, 6) at q
        trial = q.copy()  # (R, J) the configurations to evaluate
        active = np.arange(rows)
        eye = np.eye(6)
        for step in range(iterations + 1):
            m, jac = _fk_jacobian(trial[active], *self._kin)  # (A, 4, 4), (A, 6, J)
            e = _pose_error(h[active], m)  # (A, 6)
            norm = np.linalg.norm(e, axis=-1)  # (A,)
            better = norm < err[active]
            lam[active] = np.where(better, np.maximum(lam[active] * 0.1, 1e-12), lam[active] * 10)
            keep = active[better]
            q[keep], err[keep] = trial[keep], norm[better]
            jac_at[keep], e_at[keep] = jac[better], e[better]
            pos[keep] = np.linalg.norm(e[better, :3], axis=-1)
            rot[keep] = np.linalg.norm(e[better, 3:], axis=-1)
            # polish to POLISH x the tolerances: one more step at a quadratic rate
            moving = (pos[active] >= POLISH * cfg.pos_tolerance) | (
                rot[active] >= POLISH * cfg.rot_tolerance
            )
            active = active[moving & (lam[active] < 1e6)]  # a row stuck at a minimum stops
            if step == iterations or not len(active):
                break
            if groups is not None:
                done = (pos < POLISH * cfg.pos_tolerance) & (rot < POLISH * cfg.rot_tolerance)
                first = np.flatnonzero(np.diff(groups, prepend=-1))  # each group's first row
                if np.isin(groups, groups[done]).all() and not np.isin(first, active).any():
                    break  # every target solved, and every warm start converged or stuck
            jac, e, now = jac_at[active], e_at[active], q[active]
            damp = lam[active, None, None] * eye  # (A, 6, 6)
            # back toward the row's seed while far from the target; pure Gauss-Newton near it
            far = err[active, None] > NEAR
            pull = np.where(far, cfg.null_gain * (seed[active] - now), 0.0)  # (A, J)
            dq = _lm_step(jac, e, damp, pull)  # (A, J)
            if clamp:  # a joint at a limit that the step pushes out of it drops out of the step
                out = ((now <= self.q_min + 1e-9) & (dq < 0)) | (
                    (now >= self.q_max - 1e-9) & (dq > 0)
                )
                if out.any():
                    dq = _lm_step(jac * ~out[:, None, :], e, damp, pull * ~out)
            scale = np.minimum(1.0, cfg.max_step / np.maximum(np.abs(dq).max(-1), 1e-12))
            step_q = q[active] + scale[:, None] * dq  # (A, J)
            trial[active] = np.clip(step_q, self.q_min, self.q_max) if clamp else step_q
        converged = (pos < cfg.pos_tolerance) & (rot < cfg.rot_tolerance)
        return q, pos, rot, converged

    def _inside(self, q: np.ndarray) -> np.ndarray:
        """(...,) whether each configuration (..., J) lies inside the datasheet limits."""
        return ((q >= self.q_min - 1e-9) & (q <= self.q_max + 1e-9)).all(-1)

    def solve(self, targets, q_current) -> IKResult:
        """Solve IK for ``targets`` (B, 4, 4) in the base frame from ``q_current`` (J,)."""
        h = _as_float64(targets, (4, 4), "targets")  # (B, 4, 4)
        rot = h[:, :3, :3]
        if np.abs(rot @ rot.transpose(0, 2, 1) - np.eye(3)).max() > 1e-5:
            raise MotionError("targets' rotation blocks are not orthonormal (tolerance 1e-5)")
        qc = np.array(q_current, dtype=np.float64)  # a writable copy for torch.from_numpy
        if qc.shape != (self.dof,) or not np.isfinite(qc).all():
            raise MotionError(f"q_current has shape {qc.shape}; expected finite ({self.dof},)")
        cfg, b = self.config, h.shape[0]
        seeds = np.concatenate([np.clip(qc, self.q_min, self.q_max)[None], self._seeds(qc)])
        m = seeds.shape[0]  # (M, J): q_current first, then the retries
        rows = np.repeat(np.arange(b), m)  # (B * M,) the target of each row
        q, pos_err, rot_err, conv = (
            x.reshape(b, m, *x.shape[1:])
            for x in self._iterate(np.tile(seeds, (b, 1)), h[rows], cfg.max_iterations, True, rows)
        )  # (B, M, J), (B, M), (B, M), (B, M): every seed of every target in one batch
        valid = conv & self._inside(q)  # (B, M)
        # a solution pinned at a joint limit (where the clamp stopped it) leaves that joint no
        # room for the next move: it ranks after every interior one
        pinned = ((q <= self.q_min + EDGE) | (q >= self.q_max - EDGE)).any(-1)  # (B, M)
        dist = np.linalg.norm(q - qc, axis=-1) + np.where(pinned, 100.0, 0.0)  # (B, M)
        dist = np.where(valid, dist, np.inf)
        score = np.where(np.isfinite(pos_err + rot_err), pos_err + rot_err, np.inf)
        best = np.where(valid.any(1), dist.argmin(1), score.argmin(1))  # (B,)
        pick = np.arange(b)
        ok, q = valid.any(1), q[pick, best]
        pos_err, rot_err = pos_err[pick, best], rot_err[pick, best]
        if ok.any():  # the batch stopped on its first solutions: polish the chosen ones
            rows = np.flatnonzero(ok)
            q[rows], pos_err[rows], rot_err[rows], _ = self._iterate(q[rows], h[rows], 3)
        out = IKResult(ok=ok, q=q, pos_err=pos_err, rot_err=rot_err)
        for a in (out.ok, out.q, out.pos_err, out.rot_err):
            a.flags.writeable = False
        return out

    def from_seeds(self, targets, seeds, iterations: int | None = None) -> IKResult:
        """IK of each target ``targets[k]`` (B, 4, 4) from its own seed ``seeds[k]`` (B, J),
        in one batch, with no retries: where it converges, the solution on that seed's
        branch (other postures of the arm at one pose, from seeds spread over the joint
        space). ``iterations``: at most that many steps (default ``config.max_iterations``);
        ``ok`` also requires the datasheet limits."""
        h = _as_float64(targets, (4, 4), "targets")  # (B, 4, 4)
        qs = _as_float64(seeds, (self.dof,), "seeds")  # (B, J)
        if qs.shape[0] != h.shape[0]:
            raise MotionError(f"{qs.shape[0]} seeds for {h.shape[0]} targets")
        q0 = np.clip(qs, self.q_min, self.q_max)
        steps = self.config.max_iterations if iterations is None else iterations
        q, pos_err, rot_err, conv = self._iterate(q0, h, steps)
        ok = conv & self._inside(q)
        return IKResult(ok=ok, q=q, pos_err=pos_err, rot_err=rot_err)

    def follow(self, targets, q_seed, iterations: int = 10) -> IKResult:
        """Batched Gauss-Newton IK from one seed ``q_seed`` (J,) for nearby ``targets`` (B, 4, 4).

        For dense targets along a short path (a few cm apart, near q_seed's pose): every row
        converges to the solution on q_seed's IK branch, with no retries or clamping, so it is
        an order of magnitude cheaper than ``solve``. ``ok`` also requires the datasheet limits.
        At most ``iterations`` steps; rows stop as they converge.
        """
        h = _as_float64(targets, (4, 4), "targets")  # (B, 4, 4)
        qs = np.asarray(q_seed, dtype=np.float64)
        if qs.shape != (self.dof,) or not np.isfinite(qs).all():
            raise MotionError(f"q_seed has shape {qs.shape}; expected finite ({self.dof},)")
        q0 = np.tile(qs, (h.shape[0], 1))  # (B, J)
        q, pos_err, rot_err, conv = self._iterate(q0, h, iterations)
        ok = conv & self._inside(q)
        return IKResult(ok=ok, q=q, pos_err=pos_err, rot_err=rot_err)


def top_down_pose(xyz, yaw: float) -> np.ndarray:
    """(4, 4) TCP pose at ``xyz`` pointing down, rotated by ``yaw`` about z: R = Rz(yaw) Rx(pi)."""
    p = np.asarray(xyz, dtype=np.float64)
    if p.shape != (3,):
        raise MotionError(f"xyz has shape {p.shape}; expected (3,)")
    c, s = math.cos(yaw), math.sin(yaw)
    h = np.eye(4)
    h[:3, :3] = [[c, s, 0.0], [s, -c, 0.0], [0.0, 0.0, -1.0]]
    h[:3, 3] = p
    return h


def pose_yaw(h) -> float:
    """Yaw of a top-down pose (inverse of `top_down_pose`): atan2(R[1, 0], R[0, 0])."""
    h = np.asarray(h, dtype=np.float64)
    return math.atan2(h[1, 0], h[0, 0])


def grasp_yaw(block_yaw: float, hand_yaw: float) -> float:
    """The yaw ``block_yaw + k pi/2`` (a cube is 4-fold symmetric) nearest to ``hand_yaw``.

    Candidates lie in [-pi/4, 3 pi/4): joint 7 sits mid-range where the hand yaw is about
    q1 + pi/4, so over the workspace in front of the robot (|q1| < 0.7) the chosen yaw keeps
    joint 7 at least 0.6 rad inside its limits and repeated grasps cannot wind the wrist up.
    """
    quarter = math.pi / 2
    base = (block_yaw + quarter / 2) % quarter - quarter / 2  # in [-pi/4, pi/4)
    return min((base, base + quarter), key=lambda c: abs(math.remainder(c - hand_yaw, 2 * math.pi)))


def _kinematics(spec: PandaSpec) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The URDF chain for `_fk_jacobian`: joint-origin rotations (J, 3, 3) and offsets (J, 3)
    from link i-1 to link i, and panda_link7 -> TCP (4, 4) (`motion.sphere_check.fk.chain`)."""
    from motion.sphere_check.fk import chain

    rot, off, hand, tcp = chain(spec)
    return rot, off, hand @ tcp


def _fk_jacobian(q: np.ndarray, rot: np.ndarray, off: np.ndarray, tail: np.ndarray):
    """TCP poses (B, 4, 4) and geometric Jacobians (B, 6, J) in the base frame (rows: linear,
    then angular velocity) of ``q`` (B, J), float64, on `_kinematics`' chain. The frame is
    carried as its three axis columns (B, 3) each: a few small array operations per joint."""
    n, joints = q.shape
    cols = [np.zeros((n, 3)) for _ in range(3)]
    for a in range(3):
        cols[a][:, a] = 1.0
    t = np.zeros((n, 3))
    axes, origins = np.empty((n, joints, 3)), np.empty((n, joints, 3))
    c, s = np.cos(q), np.sin(q)  # (B, J)
    for j in range(joints):
        for k in np.flatnonzero(off[j]):  # the joint's origin, in the parent frame
            t = t + off[j, k] * cols[k]  # (B, 3)
        turned = []
        for a in range(3):  # the origin's rotation: new axis a = sum_k rot[k, a] old axis k
            nz = np.flatnonzero(rot[j][:, a])
            col = rot[j][nz[0], a] * cols[nz[0]]
            for k in nz[1:]:
                col = col + rot[j][k, a] * cols[k]
            turned.append(col)
        x, y, z = turned
        axes[:, j], origins[:, j] = z, t
        cj, sj = c[:, j, None], s[:, j, None]
        cols = [x * cj + y * sj, y * cj - x * sj, z]  # the turn about z
    r = np.stack(cols, axis=-1)  # (B, 3, 3)
    m = np.zeros((n, 4, 4))
    m[:, :3, :3] = r @ tail[:3, :3]
    m[:, :3, 3] = t + r @ tail[:3, 3]
    m[:, 3, 3] = 1.0
    d = m[:, None, :3, 3] - origins  # (B, J, 3) joint origin -> TCP
    linear = np.stack(
        [
            axes[..., 1] * d[..., 2] - axes[..., 2] * d[..., 1],
            axes[..., 2] * d[..., 0] - axes[..., 0] * d[..., 2],
            axes[..., 0] * d[..., 1] - axes[..., 1] * d[..., 0],
        ],
        axis=-1,
    )  # (B, J, 3) = axis x d
    return m, np.concatenate([linear, axes], axis=-1).transpose(0, 2, 1)  # (B, 6, J)


def _lm_step(jac: np.ndarray, e: np.ndarray, damp: np.ndarray, pull: np.ndarray) -> np.ndarray:
    """Joint steps (A, J): the damped least-squares step J^+ e towards the pose error ``e``
    (A, 6), J^+ = J^T (J J^T + ``damp``)^-1 with ``jac`` (A, 6, J), plus ``pull`` (A, J)
    projected onto the null space (I - J^+ J): the redundant seventh joint drifts back toward
    the seed, so a solution stays near where it started on the arm's self-motion manifold."""
    jt = jac.transpose(0, 2, 1)  # (A, J, 6)
    pinv = jt @ np.linalg.inv(jac @ jt + damp)  # (A, J, 6)
    task = (pinv @ e[:, :, None])[:, :, 0]  # (A, J)
    null = pull - (pinv @ (jac @ pull[:, :, None]))[:, :, 0]  # (A, J)
    return task + null


def _pose_error(h: np.ndarray, m: np.ndarray) -> np.ndarray:
    """(B, 6): the position error h - m and the axis-angle of R_h R_m^T, for poses (B, 4, 4)."""
    r = h[:, :3, :3] @ m[:, :3, :3].transpose(0, 2, 1)  # (B, 3, 3)
    w = 0.5 * np.stack(
        [r[:, 2, 1] - r[:, 1, 2], r[:, 0, 2] - r[:, 2, 0], r[:, 1, 0] - r[:, 0, 1]], axis=-1
    )  # (B, 3) = sin(theta) axis
    c = np.clip(0.5 * (np.trace(r, axis1=1, axis2=2) - 1.0), -1.0, 1.0)  # (B,) cos(theta)
    sin = np.linalg.norm(w, axis=-1)  # (B,)
    theta = np.arctan2(sin, c)
    factor = np.where(sin > 1e-9, theta / np.maximum(sin, 1e-12), 1.0)
    rotvec = factor[:, None] * w  # (B, 3)
    flip = c < -0.99  # near a half turn sin(theta) loses the axis: read it from (R + I) / 2
    if flip.any():
        b = 0.5 * (r[flip] + np.eye(3))  # (F, 3, 3) = a a^T at theta = pi
        k = np.argmax(np.diagonal(b, axis1=1, axis2=2), axis=-1)  # (F,)
        axis = b[np.arange(len(k)), :, k]  # (F, 3) a column with the largest diagonal
        axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
        sign = np.where((axis * w[flip]).sum(-1) < 0, -1.0, 1.0)
        rotvec[flip] = sign[:, None] * theta[flip, None] * axis
    return np.concatenate([h[:, :3, 3] - m[:, :3, 3], rotvec], axis=-1)


def _rotation_log(r: torch.Tensor) -> torch.Tensor:
    """Axis-angle (B, 3) of rotations (B, 3, 3), differentiable everywhere below angle pi."""
    w = 0.5 * torch.stack(
        [r[:, 2, 1] - r[:, 1, 2], r[:, 0, 2] - r[:, 2, 0], r[:, 1, 0] - r[:, 0, 1]], dim=-1
    )  # (B, 3) = sin(theta) axis
    c = 0.5 * (r.diagonal(dim1=-2, dim2=-1).sum(-1) - 1.0)  # (B,) = cos(theta)
    s2 = (w * w).sum(-1)  # (B,)
    big = s2 > 1e-12
    s = torch.sqrt(torch.where(big, s2, torch.ones_like(s2)))  # safe sqrt, no NaN gradients
    factor = torch.where(big, torch.atan2(s, c) / s, (1.0 - s2 / (3.0 * c * c)) / c)  # theta/sin
    return factor[:, None] * w


def ik_refine(solver: IKSolver, q_star: torch.Tensor, targets: torch.Tensor) -> torch.Tensor:
    """One differentiable Gauss-Newton step q = q* + pinv(J(q*)) e at the detached solution.

    ``q_star`` (B, J) and ``targets`` (B, 4, 4) are float64 tensors; ``e`` stacks the position
    error and the axis-angle of R_target R(q*)^T (the base-frame convention of the geometric
    Jacobian), so gradients flow from the targets to q with d q / d target = pinv(J).
    """
    if q_star.ndim != 2 or q_star.shape[1] != solver.dof:
        raise MotionError(f"q_star has shape {tuple(q_star.shape)}; expected (B, {solver.dof})")
    if targets.shape != (q_star.shape[0], 4, 4):
        raise MotionError(f"targets has shape {tuple(targets.shape)}; expected (B, 4, 4)")
    q0 = q_star.detach().to(torch.float64)
    with torch.no_grad():
        jac, m = solver.chain.jacobian(q0, ret_eef_pose=True)  # (B, 6, J), (B, 4, 4)
        jac_pinv = torch.linalg.pinv(jac)  # (B, J, 6)
    targets = targets.to(torch.float64)
    e_pos = targets[:, :3, 3] - m[:, :3, 3]  # (B, 3)
    e_rot = _rotation_log(targets[:, :3, :3] @ m[:, :3, :3].transpose(1, 2))  # (B, 3)
    e = torch.cat([e_pos, e_rot], dim=-1)  # (B, 6)
    return q0 + (jac_pinv @ e[:, :, None])[:, :, 0]  # (B, J)
