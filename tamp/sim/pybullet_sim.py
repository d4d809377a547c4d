"""PyBullet backend (``p.DIRECT``, no GUI): Panda, table plane, friction or weld grasps.

Settings follow shared/notes/motion-research.md section 4: finger gear constraint (in the
loader), position control of the arm with the trajectory's positions and velocities, 40 N per
finger, lateral friction 1.0 on the blocks, ``ER_TINY_RENDERER`` for images (no GL needed);
a physics step of ``physics_dt`` (4 ms) with Bullet's default 50 solver iterations (at 30 or
fewer, or at an 8 ms step, a block carried into a wall passes through it instead of stopping
the arm; stopping the solver early at a residual of 1e-4 lets a 3-block stack creep 4 mm in
10 s instead of 0.2 mm).
A world made for videos (``video=True``) draws with OpenGL instead, through PyBullet's EGL
plugin (Mesa llvmpipe on a CPU machine): a 640x480 frame costs about 35 ms of CPU there, about
120 ms with TinyRenderer (measured on the 2-core development machine).

Blocks at rest sleep (Bullet's deactivation): a block whose squared speed ``|v|^2 + |w|^2``
stays under `SLEEP_THRESHOLD` drops out of the solver until anything awake comes near it (the
arm never sleeps, nor does a block in the hand: it touches the fingers or is welded to the
hand) or it is teleported (`PyBulletSim.set_block_pose` wakes every block). Bullet waits 2 s
before a body sleeps; `PyBulletSim._step` puts a block to sleep once `SLEEP_CHECKS` checks
`SLEEP_EVERY` steps apart found it under the threshold (as MuJoCo does after 10 steps), and
Bullet keeps it awake while its island (bodies whose bounding boxes overlap) holds anything
awake. Resting stacks were half of a physics step; their contacts stay in `_contacts`.
"""

from __future__ import annotations

import pkgutil

import numpy as np
import pybullet as p

from robots.panda import PANDA
from robots.pybullet_loader import load_panda
from tamp.scene import Body, Pose, colour
from tamp.sim.base import (
    ROBOT,
    VIDEO_SIZE,
    Camera,
    GripperReading,
    Lighting,
    Simulator,
    body_mass,
    body_yaw,
)
from tamp.sim.truth import Snapshot
from task.errors import TampError

FINGER_FORCE = 40.0  # N per finger
ARM_KP, ARM_KD = 0.3, 1.0  # PyBullet position-control gains
NEAR, FAR = 0.05, 3.0  # m, the camera's clipping planes
LIGHT_DISTANCE = 40.0  # m, OpenGL's light from the camera target (40 m: shadows, no acne)
EDGE = 1.02  # depths this far apart (ratio) in a 2x2 window straddle an edge: not interpolated
# (m/s)^2 + (rad/s)^2: a block sleeps below this for 2 s; at rest they jitter at 5e-9..3e-6
SLEEP_THRESHOLD = 1e-5
SLEEP_EVERY = 5  # physics steps between checks of the blocks' speed
SLEEP_CHECKS = 3  # checks in a row under SLEEP_THRESHOLD before a block is put to sleep


def _quat(yaw: float) -> tuple[float, float, float, float]:
    return p.getQuaternionFromEuler((0.0, 0.0, yaw))


def _egl_plugin(client: int) -> bool:
    """Load the EGL renderer plugin into ``client`` (before any body: it draws only the bodies
    made after it) so that every ``getCameraImage`` of the client goes through OpenGL."""
    egl = pkgutil.get_loader("eglRenderer")
    if egl is None:
        return False
    return p.loadPlugin(egl.get_filename(), "_eglRendererPlugin", physicsClientId=client) >= 0


def _at_pixel_centres(z: np.ndarray) -> np.ndarray:
    """z-depth (H, W) at the pinhole's pixel centres from ``ER_TINY_RENDERER``'s samples.

    TINY samples pixel (u, v) at (u - 1/2, v + 1/2) of the pinhole model (measured against the
    table plane and a box face), so the centre of (u, v) lies midway between the samples of
    (u, v), (u + 1, v), (u, v - 1) and (u + 1, v - 1). On one surface 1/z is affine in the image,
    so their mean 1/z is exact there; across an edge pixel (u, v) keeps its own sample, as the
    RGB image does.
    """
    inv = np.pad(1.0 / z, ((1, 0), (0, 1)), mode="edge")  # (H + 1, W + 1): row -1, column W
    quad = np.stack([inv[1:, :-1], inv[1:, 1:], inv[:-1, :-1], inv[:-1, 1:]])  # (4, H, W)
    smooth = quad.max(0) <= EDGE * quad.min(0)
    return np.where(smooth, 1.0 / quad.mean(0), z)


class PyBulletSim(Simulator):
    name = "pybullet"

    def __init__(self, entities, poses, *args, **kwargs) -> None:
        super().__init__(entities, poses, *args, **kwargs)
        self.client = c = p.connect(p.DIRECT)
        self._gl = self.video and _egl_plugin(c)
        p.setGravity(0, 0, -9.81, physicsClientId=c)
        p.setTimeStep(self.physics_dt, physicsClientId=c)
        plane = p.createCollisionShape(p.GEOM_PLANE, physicsClientId=c)
        grey = [self.scene.floor_grey] * 3
        half = 0.05 if self._gl else 0.001  # top at z = 0.001; OpenGL's shadows need depth
        look = p.createVisualShape(
            p.GEOM_BOX,
            halfExtents=[3.0, 3.0, half],
            rgbaColor=[*grey, 1],
            visualFramePosition=[0, 0, 0.001 - half],
            physicsClientId=c,
        )
        self.table = p.createMultiBody(0, plane, look, [0, 0, 0], physicsClientId=c)
        p.changeDynamics(self.table, -1, lateralFriction=1.0, physicsClientId=c)
        self.backdrop = None
        if self.scene.backdrop_y is not None:  # visual only: nothing collides with it
            wall = p.createVisualShape(
                p.GEOM_BOX,
                halfExtents=[3.0, 0.005, 1.5],
                rgbaColor=[*[self.scene.backdrop_grey] * 3, 1],
                physicsClientId=c,
            )
            at = [0.0, self.scene.backdrop_y, 1.5]
            self.backdrop = p.createMultiBody(0, -1, wall, at, physicsClientId=c)
        self.obstacles = [self._obstacle(o) for o in self.scene.obstacles]
        self.marks = [self._mark(o) for o in self.scene.marks]
        self.robot = load_panda(c)
        self.blocks: dict[str, int] = {}
        for i, name in enumerate(self.entities):
            col, vis = self._block_shapes(self.scene.body(name), colour(i, self.scene.palette))
            pose, mass = poses[name], body_mass(self.scene, name)
            body = p.createMultiBody(mass, col, vis, pose.xyz, _quat(pose.yaw), physicsClientId=c)
            p.changeDynamics(
                body,
                -1,
                lateralFriction=1.0,
                spinningFriction=0.001,
                activationState=p.ACTIVATION_STATE_ENABLE_SLEEPING,
                sleepThreshold=SLEEP_THRESHOLD,
                physicsClientId=c,
            )
            self.blocks[name] = body
        self._weld: int | None = None
        obstacles = zip(self.obstacles, self.scene.obstacles, strict=True)
        self._names = {
            self.table: "table",
            **{b: o.name for b, o in obstacles},
            **{b: n for n, b in self.blocks.items()},
        }
        self._finger_command = ""
        self._steps = 0  # physics steps taken
        self._calm = dict.fromkeys(self.blocks.values(), 0)  # body -> calm checks in a row
        # contact scoring's names of bodies, and the arm's motor settings, made once
        self._scored = {**self._names, self.robot.body: ROBOT}
        self._efforts = list(PANDA.effort)
        self._kp, self._kd = [ARM_KP] * 7, [ARM_KD] * 7
        self.set_view(self.camera, self.lighting)
        self._command(np.asarray(PANDA.q_home), np.zeros(7), "open")
        for _ in range(2 if self._gl else 0):  # the plugin's light lags two images (measured)
            self.render_video((8, 6))

    def _obstacle(self, o) -> int:
        """A fixed box of the scene (`tamp.obstacles.Obstacle`)."""
        c = self.client
        col = p.createCollisionShape(p.GEOM_BOX, halfExtents=list(o.half), physicsClientId=c)
        vis = p.createVisualShape(
            p.GEOM_BOX, halfExtents=list(o.half), rgbaColor=[*o.rgb, 1], physicsClientId=c
        )
        return p.createMultiBody(0, col, vis, list(o.centre), _quat(o.yaw), physicsClientId=c)

    def _mark(self, o) -> int:
        """A region's drawn patch (`tamp.scene.SceneConfig.marks`): visual only, no collision."""
        c = self.client
        vis = p.createVisualShape(
            p.GEOM_BOX, halfExtents=list(o.half), rgbaColor=[*o.rgb, 1], physicsClientId=c
        )
        return p.createMultiBody(0, -1, vis, list(o.centre), _quat(o.yaw), physicsClientId=c)

    def _block_shapes(self, body: Body, rgb) -> tuple[int, int]:
        """Collision and visual shape of one block (a box, or an upright cylinder)."""
        c = self.client
        if body.kind == "cylinder":
            r, h = body.half[0], 2 * body.half[2]
            col = p.createCollisionShape(p.GEOM_CYLINDER, radius=r, height=h, physicsClientId=c)
            vis = p.createVisualShape(
                p.GEOM_CYLINDER, radius=r, length=h, rgbaColor=[*rgb, 1], physicsClientId=c
            )
            return col, vis
        half = list(body.half)
        col = p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=c)
        vis = p.createVisualShape(
            p.GEOM_BOX, halfExtents=half, rgbaColor=[*rgb, 1], physicsClientId=c
        )
        return col, vis

    def _command(self, q, qd, gripper) -> None:
        r, c = self.robot, self.client
        p.setJointMotorControlArray(
            r.body,
            r.arm,
            p.POSITION_CONTROL,
            targetPositions=np.asarray(q, dtype=float).tolist(),
            targetVelocities=np.asarray(qd, dtype=float).tolist(),
            forces=self._efforts,
            positionGains=self._kp,
            velocityGains=self._kd,
            physicsClientId=c,
        )
        if gripper == self._finger_command:
            return
        self._finger_command = gripper
        width = PANDA.finger_open if gripper == "open" else 0.0
        p.setJointMotorControlArray(
            r.body,
            r.fingers,
            p.POSITION_CONTROL,
            targetPositions=[width, width],
            forces=[FINGER_FORCE] * 2,
            physicsClientId=c,
        )

    def _step(self) -> None:
        p.stepSimulation(physicsClientId=self.client)
        self._steps += 1
        if self._steps % SLEEP_EVERY == 0:
            self._sleep_calm_blocks()

    def _sleep_calm_blocks(self) -> None:
        """Count each block's checks in a row under `SLEEP_THRESHOLD`; put it to sleep at
        `SLEEP_CHECKS` (Bullet wakes it when it moves or its island holds anything awake)."""
        c = self.client
        for body in self.blocks.values():
            v, w = p.getBaseVelocity(body, physicsClientId=c)
            calm = v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + w[0] * w[0] + w[1] * w[1] + w[2] * w[2]
            self._calm[body] = self._calm[body] + 1 if calm < SLEEP_THRESHOLD else 0
            if self._calm[body] == SLEEP_CHECKS:
                p.changeDynamics(
                    body, -1, activationState=p.ACTIVATION_STATE_SLEEP, physicsClientId=c
                )

    def arm_q(self) -> np.ndarray:
        states = p.getJointStates(self.robot.body, self.robot.arm, physicsClientId=self.client)
        return np.array([s[0] for s in states])

    def gripper(self) -> GripperReading:
        r, c = self.robot, self.client
        width = sum(s[0] for s in p.getJointStates(r.body, r.fingers, physicsClientId=c))
        # every contact on the finger link, from any body but the robot (pt[2]: the other body)
        forces = [
            sum(
                pt[9]
                for pt in p.getContactPoints(r.body, linkIndexA=link, physicsClientId=c)
                if pt[2] != r.body
            )
            for link in r.fingers
        ]
        return GripperReading(width, forces[0], forces[1])

    def _contacts(self) -> set[tuple[str, str]]:
        """The pairs with the arm or with the block held now: only their contact points are
        read (reading every point, resting stacks included, took a sixth of a physics step)."""
        names, c = self._scored, self.client
        bodies = [self.robot.body]
        if self._held is not None:
            bodies.append(self.blocks[self._held])
        pairs = {
            (pt[1], pt[2])
            for body in bodies
            for pt in p.getContactPoints(bodyA=body, physicsClientId=c)
        }
        return {(names[a], names[b]) for a, b in pairs if a in names and b in names}

    def _block_poses(self) -> dict[str, Pose]:
        out = {}
        for name, body in self.blocks.items():
            pos, orn = p.getBasePositionAndOrientation(body, physicsClientId=self.client)
            yaw = body_yaw(p.getMatrixFromQuaternion(orn), self.scene.body(name))
            out[name] = Pose(tuple(float(v) for v in pos), yaw)
        return out

    def set_block_pose(self, block: str, pose: Pose) -> None:
        body, c = self.blocks[block], self.client
        p.resetBasePositionAndOrientation(body, pose.xyz, _quat(pose.yaw), physicsClientId=c)
        p.resetBaseVelocity(body, [0, 0, 0], [0, 0, 0], physicsClientId=c)
        for other in self.blocks.values():  # what rested on it falls: nothing stays asleep
            p.changeDynamics(
                other, -1, activationState=p.ACTIVATION_STATE_WAKE_UP, physicsClientId=c
            )

    def _between_fingers(self) -> int | None:
        """The block body both fingers touch (the one between them), or None."""
        r, c, blocks = self.robot, self.client, set(self.blocks.values())
        touched = [
            {pt[2] for pt in p.getContactPoints(r.body, linkIndexA=link, physicsClientId=c)}
            & blocks
            for link in r.fingers
        ]
        both = touched[0] & touched[1]
        return next(iter(both)) if len(both) == 1 else None

    def attach(self) -> bool:
        self.detach()
        body = self._between_fingers()
        if body is None:
            return False
        r, c = self.robot, self.client
        link = p.getLinkState(r.body, r.tcp, computeForwardKinematics=True, physicsClientId=c)
        b_pos, b_orn = p.getBasePositionAndOrientation(body, physicsClientId=c)
        inv_pos, inv_orn = p.invertTransform(link[4], link[5])
        rel_pos, rel_orn = p.multiplyTransforms(inv_pos, inv_orn, b_pos, b_orn)
        # the TCP link is massless, so its inertial frame is its link frame
        self._weld = p.createConstraint(
            r.body,
            r.tcp,
            body,
            -1,
            p.JOINT_FIXED,
            [0, 0, 0],
            parentFramePosition=rel_pos,
            childFramePosition=[0, 0, 0],
            parentFrameOrientation=rel_orn,
            physicsClientId=c,
        )
        return True

    def detach(self) -> None:
        if self._weld is not None:
            p.removeConstraint(self._weld, physicsClientId=self.client)
            self._weld = None

    def set_view(self, camera: Camera, lighting: Lighting) -> None:
        c = self.client
        self.camera, self.lighting = camera, lighting
        self._view = p.computeViewMatrix(camera.eye, camera.target, camera.up, physicsClientId=c)
        self._proj = p.computeProjectionMatrixFOV(
            camera.fovy, camera.width / camera.height, NEAR, FAR, physicsClientId=c
        )

    def set_colour(self, part, rgb) -> None:
        self._check_part(part)
        body = {"floor": self.table, "backdrop": self.backdrop, **self.blocks}[part]
        if body is not None:
            rgba = [*(float(v) for v in rgb), 1.0]
            p.changeVisualShape(body, -1, rgbaColor=rgba, physicsClientId=self.client)

    def render(self) -> np.ndarray:
        return self._camera_image()[0]

    def render_video(self, size: tuple[int, int] = VIDEO_SIZE) -> np.ndarray:
        (w, h), cam, light, c = size, self.camera, self.lighting, self.client
        proj = p.computeProjectionMatrixFOV(cam.fovy, w / h, NEAR, FAR, physicsClientId=c)
        # OpenGL takes the light's position from the target (its shadow map's eye): far away
        # along the light; TinyRenderer normalises it. OpenGL ignores the coefficients.
        _, _, rgb, _, _ = p.getCameraImage(
            w,
            h,
            self._view,
            proj,
            flags=p.ER_NO_SEGMENTATION_MASK,
            renderer=p.ER_BULLET_HARDWARE_OPENGL if self._gl else p.ER_TINY_RENDERER,
            lightDirection=[-LIGHT_DISTANCE * v for v in light.direction],
            lightColor=[1.0, 1.0, 1.0],
            lightAmbientCoeff=light.ambient,
            lightDiffuseCoeff=light.diffuse,
            lightSpecularCoeff=0.05,
            shadow=0,
            physicsClientId=c,
        )
        return np.asarray(rgb, dtype=np.uint8).reshape(h, w, 4)[..., :3].copy()

    def _snapshot(self) -> Snapshot:
        r, c = self.robot, self.client
        joints = [s[0] for s in p.getJointStates(r.body, [*r.arm, *r.fingers], physicsClientId=c)]
        bases = [
            p.getBasePositionAndOrientation(b, physicsClientId=c) for b in self.blocks.values()
        ]
        centres = np.array([xyz for xyz, _ in bases]).reshape(-1, 3)  # (N, 3)
        quats = np.array([(w, x, y, z) for _, (x, y, z, w) in bases]).reshape(-1, 4)  # (N, 4)
        return Snapshot(np.array(joints), centres, quats)

    def show(self, snapshot: Snapshot) -> None:
        r, c = self.robot, self.client
        for j, q in zip([*r.arm, *r.fingers], snapshot.joints, strict=True):
            p.resetJointState(r.body, j, q, physicsClientId=c)
        places = zip(self.blocks.values(), snapshot.centres, snapshot.quats, strict=True)
        for body, xyz, (w, x, y, z) in places:
            p.resetBasePositionAndOrientation(body, xyz, (x, y, z, w), physicsClientId=c)

    def render_rgbd(self) -> tuple[np.ndarray, np.ndarray]:
        rgb, buffer = self._camera_image()
        # the OpenGL depth buffer d in [0, 1] -> z-depth: z = far near / (far - (far - near) d)
        depth = FAR * NEAR / (FAR - (FAR - NEAR) * buffer.astype(np.float64))
        return rgb, _at_pixel_centres(depth).astype(np.float32)

    def _camera_image(self) -> tuple[np.ndarray, np.ndarray]:
        """RGB (H, W, 3) uint8 and the raw depth buffer (H, W) in [0, 1]."""
        if self._gl:
            raise TampError("a world made for videos (video=True) renders no camera images")
        cam, light = self.camera, self.lighting
        _, _, rgb, buffer, _ = p.getCameraImage(
            cam.width,
            cam.height,
            self._view,
            self._proj,
            renderer=p.ER_TINY_RENDERER,
            lightDirection=[-v for v in light.direction],
            lightColor=[1.0, 1.0, 1.0],
            lightAmbientCoeff=light.ambient,
            lightDiffuseCoeff=light.diffuse,
            lightSpecularCoeff=0.05,
            shadow=0,
            physicsClientId=self.client,
        )
        rgb = np.asarray(rgb, dtype=np.uint8).reshape(cam.height, cam.width, 4)[..., :3].copy()
        return rgb, np.asarray(buffer, dtype=np.float32).reshape(cam.height, cam.width)

    def close(self) -> None:
        if self.client is not None and p.isConnected(self.client):
            p.disconnect(self.client)
        self.client = None
