"""Batched inverse kinematics for the Panda's TCP with pytorch_kinematics, plus pose helpers.

`IKSolver` builds the serial chain ``base_link -> tcp_link`` once (float64) and solves batches of
4x4 targets given in the base frame with ``PseudoInverseIK``, seeded with the current
configuration, the home pose and a few Gaussian perturbations of the current configuration
(early stopping once any seed converges). A row is ``ok`` when it converged and lies inside the
datasheet limits; non-convergence is a returned status, never an exception.

`ik_refine` is the differentiable hook for joint task-motion optimisation: one Gauss-Newton step
at the detached solution, so ``d q / d target = pinv(J)`` by the implicit-function theorem.
"""

from __future__ import annotations

import contextlib
import io
import logging
import math
import sys
from dataclasses import dataclass

import numpy as np
import torch

from motion.errors import MotionError
from robots.panda import PANDA, PandaSpec, urdf_path

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class IKConfig:
    """PseudoInverseIK settings (motion-research notes, section 2)."""

    max_iterations: int = 60  # Levenberg-Marquardt steps per solve
    pos_tolerance: float = 1e-4  # m
    rot_tolerance: float = 1e-3  # rad
    perturbed_seeds: int = 4  # Gaussian perturbations of q_current, besides q_current and q_home
    seed_std: float = 0.3  # rad, std of those perturbations
    seed: int = 0  # seeds the perturbations' torch.Generator (fresh per solve: deterministic)


@dataclass(frozen=True, eq=False)
class IKResult:
    """One IK solution per target; arrays are read-only numpy."""

    ok: np.ndarray  # (B,) bool: converged and inside the datasheet limits
    q: np.ndarray  # (B, J): the valid solution closest to q_current (else the best attempt)
    pos_err: np.ndarray  # (B,) m
    rot_err: np.ndarray  # (B,) rad


def _import_pytorch_kinematics():
    """Import pytorch_kinematics without its optional MJCF loader.

    Its package ``__init__`` would import mujoco, which reads ``MUJOCO_GL`` once at import time;
    importing it here, before a simulator backend has set that variable, could pin the wrong GL
    backend. Blocking the name for the duration of this import makes pytorch_kinematics skip it.
    """
    block = "mujoco" not in sys.modules
    if block:
        sys.modules["mujoco"] = None  # type: ignore[assignment]  # import mujoco -> ImportError
    try:
        import pytorch_kinematics
    finally:
        if block and sys.modules.get("mujoco", 0) is None:
            del sys.modules["mujoco"]
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

    def _seeds(self, q_current: np.ndarray) -> torch.Tensor:
        """(M, J) retry configurations: q_current, q_home, Gaussian perturbations of q_current."""
        gen = torch.Generator().manual_seed(self.config.seed)
        q0 = torch.from_numpy(q_current)
        noise = torch.randn(
            (self.config.perturbed_seeds, self.dof), generator=gen, dtype=torch.float64
        )
        seeds = torch.cat(
            [
                q0[None],
                torch.tensor(self.spec.q_home, dtype=torch.float64)[None],
                q0 + self.config.seed_std * noise,
            ]
        )  # (M, J)
        return torch.clamp(seeds, self.chain.low, self.chain.high)

    def solve(self, targets, q_current) -> IKResult:
        """Solve IK for ``targets`` (B, 4, 4) in the base frame from ``q_current`` (J,)."""
        h = _as_float64(targets, (4, 4), "targets")  # (B, 4, 4)
        rot = h[:, :3, :3]
        if np.abs(rot @ rot.transpose(0, 2, 1) - np.eye(3)).max() > 1e-5:
            raise MotionError("targets' rotation blocks are not orthonormal (tolerance 1e-5)")
        qc = np.array(q_current, dtype=np.float64)  # a writable copy for torch.from_numpy
        if qc.shape != (self.dof,) or not np.isfinite(qc).all():
            raise MotionError(f"q_current has shape {qc.shape}; expected finite ({self.dof},)")
        cfg = self.config
        ik = self._pk.PseudoInverseIK(
            self.chain,
            retry_configs=self._seeds(qc),
            max_iterations=cfg.max_iterations,
            pos_tolerance=cfg.pos_tolerance,
            rot_tolerance=cfg.rot_tolerance,
            early_stopping_any_converged=True,
        )
        goal = self._pk.Transform3d(matrix=torch.from_numpy(h), dtype=torch.float64)
        sol = ik.solve(goal)
        q = sol.solutions.numpy()  # (B, M, J)
        pos_err = sol.err_pos.numpy()  # (B, M)
        rot_err = sol.err_rot.numpy()  # (B, M)
        inside = ((q >= self.q_min - 1e-9) & (q <= self.q_max + 1e-9)).all(-1)  # (B, M)
        valid = sol.converged.numpy() & inside  # (B, M)
        dist = np.linalg.norm(q - qc, axis=-1)  # (B, M)
        score = pos_err + rot_err  # (B, M), ranks the attempts of rows without a valid solution
        score = np.where(np.isfinite(score) & inside, score, np.inf)
        best = np.where(
            valid.any(1), np.where(valid, dist, np.inf).argmin(1), score.argmin(1)
        )  # (B,)
        rows = np.arange(h.shape[0])
        out = IKResult(
            ok=valid.any(1),
            q=q[rows, best],
            pos_err=pos_err[rows, best],
            rot_err=rot_err[rows, best],
        )
        for a in (out.ok, out.q, out.pos_err, out.rot_err):
            a.flags.writeable = False
        return out

    def follow(self, targets, q_seed, iterations: int = 10) -> IKResult:
        """Batched Gauss-Newton IK from one seed ``q_seed`` (J,) for nearby ``targets`` (B, 4, 4).

        For dense targets along a short path (a few cm apart, near q_seed's pose): every row
        converges to the solution on q_seed's IK branch, with no retries or clamping, so it is
        an order of magnitude cheaper than ``solve``. ``ok`` also requires the datasheet limits.
        """
        h = torch.from_numpy(_as_float64(targets, (4, 4), "targets"))  # (B, 4, 4)
        qs = np.asarray(q_seed, dtype=np.float64)
        if qs.shape != (self.dof,) or not np.isfinite(qs).all():
            raise MotionError(f"q_seed has shape {qs.shape}; expected finite ({self.dof},)")
        q = torch.tensor(qs).repeat(h.shape[0], 1)  # (B, J)
        with torch.no_grad():
            for _ in range(iterations):
                q = ik_refine(self, q, h)
            m = self.fk_tensor(q)  # (B, 4, 4)
            pos_err = torch.linalg.norm(h[:, :3, 3] - m[:, :3, 3], dim=-1).numpy()  # (B,)
            rot = _rotation_log(h[:, :3, :3] @ m[:, :3, :3].transpose(1, 2))  # (B, 3)
            rot_err = torch.linalg.norm(rot, dim=-1).numpy()  # (B,)
        qn = q.numpy()
        inside = ((qn >= self.q_min - 1e-9) & (qn <= self.q_max + 1e-9)).all(-1)
        ok = (pos_err < self.config.pos_tolerance) & (rot_err < self.config.rot_tolerance) & inside
        return IKResult(ok=ok, q=qn, pos_err=pos_err, rot_err=rot_err)


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
