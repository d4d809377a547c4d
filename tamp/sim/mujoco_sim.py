"""MuJoCo backend: the Panda from `robots.mujoco_loader`, a table plane, free-joint blocks.

Offscreen rendering goes through EGL by default (``MUJOCO_GL=egl``, Mesa llvmpipe on a CPU
machine); set ``MUJOCO_GL`` yourself before anything imports mujoco to choose another backend.
Friction grasps rely on the elliptic cones and impratio the loader sets; the weld grasp mode
uses one inactive weld equality per block whose relative pose is set at attach time
(shared/notes/motion-research.md, section 5.3).

Blocks at rest sleep (MuJoCo's sleeping islands, ``sleep_tolerance`` 1 mm/s for 10 steps): a
sleeping block skips the pipeline, and its contacts with the table and other sleeping blocks
are not computed (`MuJoCoSim._contacts` lists pairs with something awake). Anything awake
touching it, a weld to the hand, or writing its ``qpos`` (`MuJoCoSim.set_block_pose`) wakes
it and whatever it rests on or carries; the arm has actuators and never sleeps.
"""

from __future__ import annotations

import math
import os

os.environ.setdefault("MUJOCO_GL", "egl")

import mujoco
import numpy as np

from robots.mujoco_loader import GRIP_ACTUATOR, actuator_name, panda_spec
from robots.panda import PANDA
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

FINGER_BODIES = ("panda_leftfinger", "panda_rightfinger")
HAND_BODY = PANDA.tcp_link
VIDEO_SHADOW_MAP = 1024  # texels a side in a world made for videos: 36 ms a 640x480 frame, not 80


def _quat(yaw: float) -> list[float]:
    return [math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)]


def _add_box(world, name: str, box, **collision) -> None:
    """``box`` (a `tamp.obstacles.Obstacle`: half extents, centre, yaw, colour) as a fixed box
    geom of the MjSpec body ``world``; ``collision``: its contype/conaffinity, if not the
    default's."""
    world.add_geom(
        name=name,
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=list(box.half),
        pos=list(box.centre),
        quat=_quat(box.yaw),
        rgba=[*box.rgb, 1],
        **collision,
    )


def _look_at(eye, target, up) -> list[float]:
    """Quaternion of a MuJoCo camera at ``eye`` looking at ``target`` (camera looks along -z)."""
    back = np.asarray(eye, float) - np.asarray(target, float)
    back /= np.linalg.norm(back)
    right = np.cross(np.asarray(up, float), back)
    right /= np.linalg.norm(right)
    upv = np.cross(back, right)
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, np.column_stack([right, upv, back]).ravel())
    return list(quat)


def _geom(body: Body) -> tuple[mujoco.mjtGeom, list[float]]:
    """MuJoCo geom type and size of a block: a box's half extents, a cylinder's radius and half
    height."""
    if body.kind == "cylinder":
        return mujoco.mjtGeom.mjGEOM_CYLINDER, [body.half[0], body.half[2]]
    return mujoco.mjtGeom.mjGEOM_BOX, list(body.half)


class MuJoCoSim(Simulator):
    name = "mujoco"

    def __init__(self, entities, poses, *args, **kwargs) -> None:
        super().__init__(entities, poses, *args, **kwargs)
        s = panda_spec(timestep=self.physics_dt)
        cam = self.camera
        s.visual.global_.offwidth = max(cam.width, VIDEO_SIZE[0])
        s.visual.global_.offheight = max(cam.height, VIDEO_SIZE[1])
        if self.video:  # llvmpipe spends most of a frame on the 4096^2 default shadow map
            s.visual.quality.shadowsize = VIDEO_SHADOW_MAP
        world, scene = s.worldbody, self.scene
        self._add_surroundings(world)
        bodies = {name: scene.body(name) for name in self.entities}
        if any(b.kind == "cylinder" for b in bodies.values()):  # matte like LatPlan's rubber
            s.add_material(name="block", specular=0.1, shininess=0.1)
        world.add_light(
            name="sun",
            type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL,
            pos=[0.5, 0.3, 2.0],
            dir=[-0.2, -0.1, -1.0],
            diffuse=[0.8, 0.8, 0.8],
        )
        world.add_camera(
            name="scene",
            pos=list(cam.eye),
            quat=_look_at(cam.eye, cam.target, cam.up),
            fovy=cam.fovy,
        )
        self._add_blocks(s, poses, bodies)
        s.option.enableflags |= mujoco.mjtEnableBit.mjENBL_SLEEP
        self.model = m = s.compile()
        self.data = d = mujoco.MjData(m)
        self._index(m)
        d.qpos[self._arm_q] = PANDA.q_home
        d.qpos[self._fingers] = PANDA.finger_open
        self._command(np.asarray(PANDA.q_home), np.zeros(7), "open")
        mujoco.mj_forward(m, d)
        self._renderer: mujoco.Renderer | None = None
        self._video: mujoco.Renderer | None = None  # render_video's, its own GL context
        self.set_view(self.camera, self.lighting)

    def _add_surroundings(self, world) -> None:
        """The floor, the backdrop, the fixed boxes and the drawn regions of the scene."""
        scene = self.scene
        world.add_geom(
            name="floor",
            type=mujoco.mjtGeom.mjGEOM_PLANE,
            size=[3.0, 3.0, 0.01],
            rgba=[*[scene.floor_grey] * 3, 1],
        )
        if scene.backdrop_y is not None:  # collides with nothing (the other geoms have bit 1
            # only); conaffinity 0 too would let the URDF import's discardvisual drop it
            world.add_geom(
                name="backdrop",
                type=mujoco.mjtGeom.mjGEOM_BOX,
                size=[3.0, 0.005, 1.5],
                pos=[0.0, scene.backdrop_y, 1.5],
                rgba=[*[scene.backdrop_grey] * 3, 1],
                contype=0,
                conaffinity=2,
            )
        for o in scene.obstacles:  # fixed boxes (tamp.obstacles)
            _add_box(world, f"obstacle_{o.name}", o)
        for o in scene.marks:  # drawn regions: visual only, like the backdrop
            _add_box(world, f"mark_{o.name}", o, contype=0, conaffinity=2)

    def _add_blocks(self, s, poses, bodies) -> None:
        """Each block at its pose, free to move, and its weld to the hand (off until a
        welded grasp closes)."""
        world, scene = s.worldbody, self.scene
        for i, name in enumerate(self.entities):
            pose = poses[name]
            body = world.add_body(name=f"block_{name}", pos=list(pose.xyz), quat=_quat(pose.yaw))
            body.add_freejoint(name=f"block_{name}")
            shape, size = _geom(bodies[name])
            geom = body.add_geom(
                name=f"block_{name}",
                type=shape,
                size=size,
                mass=body_mass(scene, name),
                rgba=[*colour(i, scene.palette), 1],
                friction=[1.0, 0.03, 0.0001],
                condim=4,
                solref=[0.004, 1.0],
            )
            if bodies[name].kind == "cylinder":
                geom.material = "block"
            s.add_equality(
                type=mujoco.mjtEq.mjEQ_WELD,
                name=f"weld_{name}",
                name1=HAND_BODY,
                name2=f"block_{name}",
                objtype=mujoco.mjtObj.mjOBJ_BODY,
                active=False,
            )

    def _index(self, m) -> None:
        """The compiled model's addresses and ids the simulator reads and writes: the arm's
        and the fingers' joints and actuators, the blocks' bodies, joints and welds, and each
        geom's contact label."""
        scene = self.scene
        self._arm_q = np.array([m.joint(j).qposadr[0] for j in PANDA.arm_joints])
        self._fingers = np.array([m.joint(j).qposadr[0] for j in PANDA.finger_joints])
        self._act = np.array([m.actuator(actuator_name(j)).id for j in PANDA.arm_joints])
        self._grip = m.actuator(GRIP_ACTUATOR).id
        # s: each arm actuator's lead, (kv + joint damping) / kp. The position actuators push
        # kp (ctrl - q) - kv qd, which at a joint velocity lags ctrl by this many seconds of it
        # (9 mrad in a fast lift of the shoulder: 3 mm at the hand, enough to brush a block
        # 2 mm away); commanding q + lead * qd tracks the velocity too, as PyBullet's
        # position control does with its target velocities
        dofs = [m.joint(j).dofadr[0] for j in PANDA.arm_joints]
        kp = m.actuator_gainprm[self._act, 0]
        self._lead = (-m.actuator_biasprm[self._act, 2] + m.dof_damping[dofs]) / kp
        self._finger_ids = [m.body(b).id for b in FINGER_BODIES]
        self._hand = m.body(HAND_BODY).id
        self._block_ids = {n: m.body(f"block_{n}").id for n in self.entities}
        self._block_q = {n: m.joint(f"block_{n}").qposadr[0] for n in self.entities}
        self._block_v = {n: m.joint(f"block_{n}").dofadr[0] for n in self.entities}
        self._weld_ids = {n: m.equality(f"weld_{n}").id for n in self.entities}
        self._geom_names = {m.geom("floor").id: "table"}
        self._geom_names |= {m.geom(f"obstacle_{o.name}").id: o.name for o in scene.obstacles}
        self._geom_names |= {m.geom(f"block_{n}").id: n for n in self.entities}
        # contact scoring: each geom's index in _labels (the robot's are all ROBOT), or -1
        self._labels = [ROBOT, *dict.fromkeys(self._geom_names.values())]
        self._geom_label = np.array(
            [
                self._labels.index(self._geom_names[g]) if g in self._geom_names else -1
                for g in range(m.ngeom)
            ]
        )
        self._geom_label[m.body_rootid[m.geom_bodyid] == m.body_rootid[self._hand]] = 0

    def _command(self, q, qd, gripper) -> None:
        self.data.ctrl[self._act] = np.asarray(q) + self._lead * np.asarray(qd)
        self.data.ctrl[self._grip] = PANDA.finger_open if gripper == "open" else 0.0

    def _step(self) -> None:
        mujoco.mj_step(self.model, self.data)

    def arm_q(self) -> np.ndarray:
        return self.data.qpos[self._arm_q].copy()

    def gripper(self) -> GripperReading:
        m, d = self.model, self.data
        robot = m.body_rootid[self._hand]  # every Panda body shares this root
        forces = [0.0, 0.0]
        f6 = np.zeros(6)
        for i in range(d.ncon):
            con = d.contact[i]
            bodies = (m.geom_bodyid[con.geom1], m.geom_bodyid[con.geom2])
            for k, finger in enumerate(self._finger_ids):
                if finger not in bodies:
                    continue
                other = bodies[1] if bodies[0] == finger else bodies[0]
                if m.body_rootid[other] != robot:  # any contact but the robot's own links
                    mujoco.mj_contactForce(m, d, i, f6)
                    forces[k] += abs(f6[0])
        width = float(d.qpos[self._fingers].sum())
        return GripperReading(width, forces[0], forces[1])

    def _contacts(self) -> set[tuple[str, str]]:
        if self.data.ncon == 0:
            return set()
        codes = self._geom_label[self.data.contact.geom]  # (C, 2): -1 for unnamed geoms
        labels = self._labels
        return {
            (labels[a], labels[b]) for a, b in set(map(tuple, codes.tolist())) if min(a, b) >= 0
        }

    def _block_poses(self) -> dict[str, Pose]:
        out = {}
        for name, adr in self._block_q.items():
            pos = self.data.qpos[adr : adr + 3]
            yaw = body_yaw(self.data.xmat[self._block_ids[name]], self.scene.body(name))
            out[name] = Pose(tuple(float(v) for v in pos), yaw)
        return out

    def set_block_pose(self, block: str, pose: Pose) -> None:
        adr, vadr = self._block_q[block], self._block_v[block]
        self.data.qpos[adr : adr + 3] = pose.xyz
        self.data.qpos[adr + 3 : adr + 7] = _quat(pose.yaw)
        self.data.qvel[vadr : vadr + 6] = 0.0
        mujoco.mj_forward(self.model, self.data)

    def _between_fingers(self) -> str | None:
        """The block both fingers touch (the one between them), or None."""
        m, d = self.model, self.data
        touched: list[set[str]] = [set(), set()]
        blocks = {i: n for n, i in self._block_ids.items()}
        for i in range(d.ncon):
            bodies = (m.geom_bodyid[d.contact[i].geom1], m.geom_bodyid[d.contact[i].geom2])
            for k, finger in enumerate(self._finger_ids):
                if finger in bodies:
                    other = bodies[1] if bodies[0] == finger else bodies[0]
                    if int(other) in blocks:
                        touched[k].add(blocks[int(other)])
        both = touched[0] & touched[1]
        return next(iter(both)) if len(both) == 1 else None

    def attach(self) -> bool:
        self.detach()
        block = self._between_fingers()
        if block is None:
            return False
        m, d = self.model, self.data
        i = self._weld_ids[block]
        hand_q, block_q, inv, rel = np.zeros(4), np.zeros(4), np.zeros(4), np.zeros(3)
        mujoco.mju_mat2Quat(hand_q, d.xmat[self._hand])
        mujoco.mju_mat2Quat(block_q, d.xmat[self._block_ids[block]])
        mujoco.mju_negQuat(inv, hand_q)
        mujoco.mju_rotVecQuat(rel, d.xpos[self._block_ids[block]] - d.xpos[self._hand], inv)
        m.eq_data[i, 0:3] = 0.0  # anchor at the block origin
        m.eq_data[i, 3:6] = rel  # the block's position in the hand frame
        quat = np.zeros(4)
        mujoco.mju_mulQuat(quat, inv, block_q)
        m.eq_data[i, 6:10] = quat
        d.eq_active[i] = 1
        return True

    def detach(self) -> None:
        # only the grasp welds: the finger coupling (a joint equality) must stay active
        self.data.eq_active[list(self._weld_ids.values())] = 0

    def set_view(self, camera: Camera, lighting: Lighting) -> None:
        if (camera.width, camera.height) != (self.camera.width, self.camera.height):
            raise TampError("set_view cannot change the image size of a MuJoCo simulator")
        m, cam, sun = self.model, self.model.camera("scene"), self.model.light("sun")
        self.camera, self.lighting = camera, lighting
        cam.pos[:] = camera.eye
        cam.quat[:] = _look_at(camera.eye, camera.target, camera.up)
        cam.fovy[:] = camera.fovy
        direction = np.asarray(lighting.direction, float)
        sun.dir[:] = direction / np.linalg.norm(direction)
        sun.diffuse[:] = lighting.diffuse
        m.vis.headlight.ambient[:] = lighting.ambient
        m.vis.headlight.diffuse[:] = 0.1
        # renders read the world poses of cameras and lights (cam_xpos, light_xdir), which
        # only the kinematics pass recomputes: without this the view lags one set_view behind
        mujoco.mj_camlight(m, self.data)
        # nor does that pass move the world body's camera before the next physics step (MuJoCo
        # 4.0.1): set its world pose as the step would, or eye and target apply one step late
        self.data.cam_xpos[cam.id] = camera.eye
        mujoco.mju_quat2Mat(self.data.cam_xmat[cam.id], cam.quat)

    def set_colour(self, part, rgb) -> None:
        self._check_part(part)
        if part == "backdrop" and self.scene.backdrop_y is None:
            return
        name = part if part in ("floor", "backdrop") else f"block_{part}"
        self.model.geom(name).rgba[:3] = rgb

    def render(self) -> np.ndarray:
        return self._scene_renderer().render().copy()

    def render_rgbd(self) -> tuple[np.ndarray, np.ndarray]:
        # the classic Renderer undoes the projection itself: float32 z-depth in metres along
        # the optical axis (checked against the table plane in tests/tamp/camera)
        renderer = self._scene_renderer()
        rgb = renderer.render().copy()
        renderer.enable_depth_rendering()
        try:
            depth = renderer.render().copy()
        finally:
            renderer.disable_depth_rendering()
        return rgb, depth

    def render_video(self, size: tuple[int, int] = VIDEO_SIZE) -> np.ndarray:
        m, (w, h) = self.model, size
        if self._video is None or (self._video.width, self._video.height) != (w, h):
            most = (m.vis.global_.offwidth, m.vis.global_.offheight)
            if w > most[0] or h > most[1]:
                raise TampError(
                    f"video size {w}x{h} exceeds the offscreen buffer {most[0]}x{most[1]}"
                )
            if self._video is not None:
                self._video.close()
            self._video = mujoco.Renderer(m, h, w)
        self._video.update_scene(self.data, camera="scene")
        return self._video.render().copy()

    def _snapshot(self) -> Snapshot:
        q = self.data.qpos
        joints = np.concatenate([q[self._arm_q], q[self._fingers]])  # (J + 2,)
        free = np.array([q[a : a + 7] for a in self._block_q.values()]).reshape(-1, 7)  # (N, 7)
        return Snapshot(joints, free[:, :3].copy(), free[:, 3:].copy())

    def show(self, snapshot: Snapshot) -> None:
        q = self.data.qpos
        q[self._arm_q], q[self._fingers] = snapshot.joints[:-2], snapshot.joints[-2:]
        places = zip(self._block_q.values(), snapshot.centres, snapshot.quats, strict=True)
        for adr, xyz, quat in places:
            q[adr : adr + 3], q[adr + 3 : adr + 7] = xyz, quat
        mujoco.mj_kinematics(self.model, self.data)
        mujoco.mj_camlight(self.model, self.data)

    def _scene_renderer(self) -> mujoco.Renderer:
        """The offscreen renderer (made on first use) with the scene camera's current view."""
        if self._renderer is None:
            self._renderer = mujoco.Renderer(self.model, self.camera.height, self.camera.width)
        self._renderer.update_scene(self.data, camera="scene")
        return self._renderer

    def close(self) -> None:
        for renderer in (self._renderer, self._video):
            if renderer is not None:
                renderer.close()
        self._renderer = self._video = None
