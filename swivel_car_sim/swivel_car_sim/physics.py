"""
The simulated swivel car: a pybullet world with the robot, its drive train and step obstacles.

ROS-free. ``SwivelCarSim`` owns one pybullet client (DIRECT unless ``gui``), steps it at a
fixed ``time_step`` and exposes what a motor driver board and an IMU would: joint states, base
orientation, angular velocity and specific force, plus the ground truth pose and twist. The
drive train's torques (``swivel_car_sim.drive_train``) are applied every physics step with
TORQUE_CONTROL; the step obstacles are ``swivel_car_sim.world``'s.
"""

from __future__ import annotations

from dataclasses import dataclass, field
import math
import os
import tempfile

import numpy as np
import pybullet

from swivel_car_model.checks import check_number
from swivel_car_model.description import CarDescription, ROBOT_VARIANTS
from swivel_car_model.params import SwivelCarParams
from swivel_car_sim.drive_train import DriveTrain
from swivel_car_sim.robot_state import RobotState
from swivel_car_sim.urdf import build_robot, RobotModel
from swivel_car_sim.world import BoundClient, Obstacles, StepSpec

GRAVITY = 9.81  # [m/s^2]
MAX_STEPS_PER_CALL = 100_000
# Bullet computes in single precision here: 1 km from the origin a float32 resolves 0.06 mm,
# still far below a wheel's contact; further out the physics degrades without a warning.
WORLD_HALF_EXTENT = 1000.0  # [m]
# The steering joint's hard stop: the most torque it takes to hold the joint at its limit,
# far above the actuator's (30 N m) and what the car's weight puts on the joint.
STOP_TORQUE = 1e5  # [N m]
STOP_ZONE = 1e-3  # [rad] before the stop, where it holds the actuator's torque into it
STOP_HOLD = 0.01  # [rad] the zone while engaged (a knock off the stop of 5e-4 rad rebounded 4e-3)
# Slower than this into the stop, the joint rests on it: a torque away from it frees it.
STOP_RATE = 0.01  # [rad/s]
# How far past its stop the joint may still be: the solver's residual, at most 6e-5 rad
# measured at full torque into the stop, driving or not, and 1.4e-4 rad over 180 s of sim
# thrown from stop to stop while driving (the sim benchmark); pybullet's own joint limit alone
# let the actuator push it 0.02-0.04 rad past.
STOP_SLACK = 1e-3  # [rad]
# Without URDF_USE_IMPLICIT_CYLINDER pybullet turns URDF cylinders into polygonal hulls and the
# wheels bump over their facets (the body hopped 0.4 mm every facet, the IMU's vertical
# specific force had a 3.4 m/s^2 standard deviation at 0.37 m/s).
URDF_FLAGS = pybullet.URDF_USE_INERTIA_FROM_FILE | pybullet.URDF_USE_IMPLICIT_CYLINDER


@dataclass(frozen=True)
class SimConfig:
    """
    Configuration of a SwivelCarSim; validated on construction.

    Parameters
    ----------
    description : CarDescription
        The robot: geometry, mass layout, drive train, actuator limits, tyre friction.
    robot_variant : str
        'swivel' or 'car_like'.
    time_step : float
        Physics step. # [s]
    gui : bool
        Open the pybullet GUI (needs a display) instead of DIRECT.
    watchdog_timeout : float
        Sim time without a command after which the swivel torque is zeroed and the drive
        commanded to stop; 0 disables the watchdog. # [s]
    ground_friction : float
        Coulomb friction coefficient of the ground (pybullet multiplies it with the tyres'
        ``description.wheel_friction``). # [1]
    body_collision : bool
        Give the body (columns, axle housings, central body) collision shapes, not only the
        wheels: for a phi < 0 robot, whose belly hangs below the axle line
        (``swivel_car_sim.urdf``). Needs a robot whose body clears the ground at rest.

    """

    description: CarDescription = field(default_factory=CarDescription)
    robot_variant: str = 'swivel'
    time_step: float = 0.002  # [s]
    gui: bool = False
    watchdog_timeout: float = 0.5  # [s]
    ground_friction: float = 1.0  # [1]
    body_collision: bool = False

    def __post_init__(self) -> None:
        if self.robot_variant not in ROBOT_VARIANTS:
            raise ValueError(
                f'robot_variant must be one of {ROBOT_VARIANTS}, got {self.robot_variant!r}')
        check_number('time_step', self.time_step, above=0.0, unit='s')
        if self.time_step > 0.01:
            raise ValueError(f'time_step must be in (0, 0.01] s, got {self.time_step!r}')
        check_number('ground_friction', self.ground_friction, above=0.0)
        check_number('watchdog_timeout', self.watchdog_timeout, at_least=0.0, unit='s')
        if not isinstance(self.body_collision, bool):
            raise ValueError(f'body_collision must be a bool, got {self.body_collision!r}')

    @property
    def params(self) -> SwivelCarParams:
        """Return the model's parameter set of the robot (geometry, derived mass and inertia)."""
        return self.description.model_params()


class SwivelCarSim:
    """
    A pybullet world holding one swivel car (or car-like baseline) and step obstacles.

    Parameters
    ----------
    config : SimConfig
    initial_pose : tuple of float
        (x [m], y [m], yaw [rad]) of base_link on the ground.

    Notes
    -----
    Deterministic: the same sequence of calls gives the same states. Sim time only moves
    forward (``reset`` keeps it), so ROS clocks fed from it never jump back.

    """

    def __init__(self, config: SimConfig | None = None,
                 initial_pose: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> None:
        self.config = config or SimConfig()
        self.description = self.config.description
        self.params = self.config.params
        self.robot: RobotModel = build_robot(self.description, self.config.robot_variant,
                                             body_collision=self.config.body_collision,
                                             sensor_frames=False)
        self._drive_train = DriveTrain(self.description, self.config.time_step)
        # Read by the watchdog every physics step.
        self._time_step = self.config.time_step  # [s]
        self._watchdog_timeout = self.config.watchdog_timeout  # [s]
        self._client = pybullet.connect(pybullet.GUI if self.config.gui else pybullet.DIRECT)
        if self._client < 0:
            raise RuntimeError('pybullet could not connect' + (' a GUI (is there a display?)'
                                                               if self.config.gui else ''))
        self._pb = BoundClient(self._client)
        self._pb.setPhysicsEngineParameter(fixedTimeStep=self.config.time_step,
                                           enableFileCaching=0, deterministicOverlappingPairs=1)
        self._pb.setGravity(0.0, 0.0, -GRAVITY)
        plane = self._pb.createCollisionShape(pybullet.GEOM_PLANE)
        self._ground = self._pb.createMultiBody(0.0, plane)
        self._pb.changeDynamics(self._ground, -1, lateralFriction=self.config.ground_friction)
        fd, self._urdf_path = tempfile.mkstemp(prefix='swivel_car_', suffix='.urdf')
        with os.fdopen(fd, 'w') as f:
            f.write(self.robot.urdf)
        self._steps = 0
        self._obstacles = Obstacles(self._pb)
        self._body = -1
        self._load_robot(*initial_pose)

    # --- lifecycle -------------------------------------------------------------------------

    def close(self) -> None:
        """Disconnect pybullet and delete the temporary URDF. Idempotent."""
        if self._client >= 0:
            pybullet.disconnect(physicsClientId=self._client)
            self._client = -1
            os.unlink(self._urdf_path)

    def __enter__(self) -> 'SwivelCarSim':
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # --- time and stepping -----------------------------------------------------------------

    @property
    def steps(self) -> int:
        """Physics steps taken since construction [1]."""
        return self._steps

    @property
    def client(self) -> int:
        """Return the pybullet physics client of the world (for sensors that render it)."""
        return self._client

    @property
    def time(self) -> float:
        """Sim time [s]."""
        return self._steps * self._time_step

    def set_command(self, swivel_torque: float, drive_speed: float) -> None:
        """
        Take an actuator command (clamped to the limits); it feeds the watchdog.

        Raises
        ------
        ValueError
            A field is not finite; the previous command stays.

        """
        for name, value in (('swivel_torque', swivel_torque), ('drive_speed', drive_speed)):
            if not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ValueError(f'{name} must be finite, got {value!r}')
        d = self.description
        self._swivel_torque = min(d.swivel_torque_limit,
                                  max(-d.swivel_torque_limit, float(swivel_torque)))
        self._drive_speed = min(d.drive_speed_limit,
                                max(-d.drive_speed_limit, float(drive_speed)))
        self._command_time = self.time

    @property
    def watchdog_tripped(self) -> bool:
        """Whether the last command is older than the watchdog timeout."""
        return self._tripped_at(self._steps)

    def _tripped_at(self, steps: int) -> bool:
        """Whether the watchdog is tripped after ``steps`` physics steps since construction."""
        timeout = self._watchdog_timeout
        return timeout > 0.0 and steps * self._time_step - self._command_time > timeout + 1e-9

    def step(self, steps: int = 1) -> None:
        """Advance the physics by ``steps`` time steps (1 .. 100000)."""
        if not isinstance(steps, int) or not 1 <= steps <= MAX_STEPS_PER_CALL:
            raise ValueError(f'steps must be an integer in [1, {MAX_STEPS_PER_CALL}], '
                             f'got {steps!r}')
        # The hot loop (every physics step): direct pybullet calls, no numpy.
        v_start = self._base_now()[2]
        body, client, joint_ids = self._body, self._client, self._joint_ids
        efforts = self._drive_train.efforts
        joint_states = self._joint_states
        self._joint_states = self._base = None
        # Sim time only grows, so a watchdog not tripped at the last step is not at any.
        may_trip = self._tripped_at(self._steps + steps - 1)
        stop, time_step = self._swivel_stop, self._time_step  # [rad], [s]
        for _ in range(steps):
            swivel, rl, rr, fl, fr = (joint_states if joint_states is not None else
                                      pybullet.getJointStates(body, joint_ids,
                                                              physicsClientId=client))
            joint_states = None
            self._efforts = efforts(rl, rr, fl, fr, self._swivel_torque, self._drive_speed,
                                    may_trip and self.watchdog_tripped)
            # The steering joint's hard stop: pybullet's joint limit is soft (0.02-0.04 rad past
            # it at full torque), so a joint about to pass its stop within the step, or pushed
            # into it within STOP_ZONE (STOP_HOLD once on it: a knock off it may throw it back
            # past), is made to reach it exactly by a velocity motor, solved implicitly (stiff
            # and stable).
            angle, rate, torque = swivel[0], swivel[1], self._efforts[0]
            ahead = angle + rate * time_step
            zone = STOP_HOLD if self._stop_engaged else STOP_ZONE
            upper = ahead > stop - zone and (rate > STOP_RATE or torque > 0.0)
            engaged = upper or (ahead < zone - stop and (rate < -STOP_RATE or torque < 0.0))
            if engaged or self._stop_engaged:
                target = ((stop - angle) if upper else (-stop - angle)) / time_step
                pybullet.setJointMotorControl2(
                    body, joint_ids[0], pybullet.VELOCITY_CONTROL,
                    targetVelocity=target if engaged else 0.0,
                    force=STOP_TORQUE if engaged else 0.0, physicsClientId=client)
                self._stop_engaged = engaged
            pybullet.setJointMotorControlArray(body, joint_ids, pybullet.TORQUE_CONTROL,
                                               forces=self._efforts, physicsClientId=client)
            pybullet.stepSimulation(physicsClientId=client)
            self._steps += 1
        v_end = self._base_now()[2]
        span = steps * self.config.time_step  # [s]
        self._acceleration = ((v_end[0] - v_start[0]) / span, (v_end[1] - v_start[1]) / span,
                              (v_end[2] - v_start[2]) / span)

    # --- robot -----------------------------------------------------------------------------

    def reset(self, x: float = 0.0, y: float = 0.0, yaw: float = 0.0,
              remove_obstacles: bool = False) -> None:
        """
        Put the robot at rest on the ground at (x, y, yaw), swivel at 0, command zero.

        Raises
        ------
        ValueError
            Non-finite pose, a position beyond WORLD_HALF_EXTENT, or the robot would
            overlap an obstacle; nothing changes.

        """
        for name, value in (('x', x), ('y', y), ('yaw', yaw)):
            if not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ValueError(f'{name} must be finite, got {value!r}')
        for name, value in (('x', x), ('y', y)):
            if abs(value) > WORLD_HALF_EXTENT:
                raise ValueError(f'{name} must be within +-{WORLD_HALF_EXTENT} m of the '
                                 f'origin, got {value!r}')
        if not remove_obstacles:
            blocking = self._obstacles_overlapping_robot_at(x, y, yaw)
            if blocking:
                raise ValueError(f'the robot at ({x}, {y}, {yaw}) would overlap obstacle(s) '
                                 f'{", ".join(blocking)}')
        if remove_obstacles:
            self.remove_obstacle('')
        self._pb.removeBody(self._body)
        self._load_robot(x, y, yaw)

    def _load_robot(self, x: float, y: float, yaw: float) -> None:
        pb = self._pb
        orientation = pybullet.getQuaternionFromEuler([0.0, 0.0, yaw])
        self._body = pb.loadURDF(self._urdf_path, [x, y, self.params.r], orientation,
                                 flags=URDF_FLAGS)
        names = {pb.getJointInfo(self._body, i)[1].decode(): i
                 for i in range(pb.getNumJoints(self._body))}
        self.joint_names = (self.robot.steer_joint,) + self.robot.wheel_joints
        self._joint_ids = [names[n] for n in self.joint_names]
        self._wheel_ids = self._joint_ids[1:]
        # The steering joint's mechanical limit, from the URDF (the description's).
        self._swivel_stop = pb.getJointInfo(self._body, self._joint_ids[0])[9]  # [rad]
        self._stop_engaged = False
        # Joint motors are on by default: switch them off so that torques act alone.
        pb.setJointMotorControlArray(self._body, self._joint_ids, pybullet.VELOCITY_CONTROL,
                                     forces=[0.0] * len(self._joint_ids))
        for link in range(-1, pb.getNumJoints(self._body)):
            pb.changeDynamics(self._body, link, lateralFriction=self.description.wheel_friction,
                              linearDamping=0.0, angularDamping=0.0, jointDamping=0.0)
        inertial = pb.getDynamicsInfo(self._body, -1)
        self._com_in_link = (inertial[3], inertial[4])
        self._link_in_com = pybullet.invertTransform(*self._com_in_link)
        self._swivel_torque = 0.0
        self._drive_speed = 0.0
        self._command_time = self.time
        self._drive_train.reset()
        self._efforts = [0.0] * len(self._joint_ids)
        self._acceleration = (0.0, 0.0, 0.0)  # [m/s^2] of base_link, world, over the last step
        self._forget_motion()

    def _forget_motion(self) -> None:
        """Drop what was read of the robot's motion: it moved other than by ``step``."""
        # Each read is a pybullet request (2-3 us): the pose and velocity read at the end of a
        # step serve the next step and state(); the joint states state() reads serve the
        # next step's first drive train torques.
        self._base: tuple[tuple[float, ...], ...] | None = None
        self._joint_states: tuple | None = None

    def _base_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """base_link origin and orientation."""
        pos, orn, _, _ = self._base_now()
        return np.array(pos), np.array(orn)

    def _base_now(self) -> tuple[tuple[float, ...], ...]:
        """
        Return base_link's origin, orientation, origin velocity, angular velocity now.

        In the world frame, as floats, read from pybullet once per physics state (pybullet
        reports the base's inertial frame).
        """
        if self._base is None:
            client = self._client
            com_pos, com_orn = pybullet.getBasePositionAndOrientation(self._body,
                                                                      physicsClientId=client)
            linear, angular = pybullet.getBaseVelocity(self._body, physicsClientId=client)
            pos, orn = pybullet.multiplyTransforms(com_pos, com_orn, *self._link_in_com)
            # v_origin = v_com + omega x (origin - com)
            dx, dy, dz = pos[0] - com_pos[0], pos[1] - com_pos[1], pos[2] - com_pos[2]
            wx, wy, wz = angular
            self._base = (pos, orn, (linear[0] + wy * dz - wz * dy, linear[1] + wz * dx - wx * dz,
                                     linear[2] + wx * dy - wy * dx), angular)
        return self._base

    def state(self) -> RobotState:
        """Return the sensors and the ground truth now."""
        if self._joint_states is None:
            self._joint_states = pybullet.getJointStates(self._body, self._joint_ids,
                                                         physicsClientId=self._client)
        states = self._joint_states
        pos, orn, linear, angular = self._base_now()
        r = pybullet.getMatrixFromQuaternion(orn)
        ax, ay, az = self._acceleration

        def in_base(x: float, y: float, z: float) -> np.ndarray:
            # R^T (x, y, z) summed as numpy's R.T @ v sums it (from +0.0, left to right):
            # the same bits without numpy's cost per call on three numbers.
            return np.array((0.0 + r[0] * x + r[3] * y + r[6] * z,
                             0.0 + r[1] * x + r[4] * y + r[7] * z,
                             0.0 + r[2] * x + r[5] * y + r[8] * z))

        return RobotState(
            time=self.time, joint_names=self.joint_names,
            positions=np.array([s[0] for s in states]),
            velocities=np.array([s[1] for s in states]),
            efforts=np.array(self._efforts), position=np.array(pos), orientation=np.array(orn),
            linear_velocity=in_base(*linear), angular_velocity=in_base(*angular),
            linear_acceleration=in_base(ax, ay, az + GRAVITY))

    def wheel_lowest_points(self) -> np.ndarray:
        """
        Return the lowest point height of each wheel's rim circle [m].

        A thin disc, as the thesis models it; rear left, rear right, front left, front right.
        """
        heights = []
        for joint in self._wheel_ids:
            s = self._pb.getLinkState(self._body, joint, computeForwardKinematics=1)
            axis = np.array(pybullet.getMatrixFromQuaternion(s[5])).reshape(3, 3)[:, 1]
            # Lowest rim point: centre minus r times the unit vector of -z orthogonal to axis.
            down = np.array([0.0, 0.0, -1.0]) - axis * -axis[2]
            norm = np.linalg.norm(down)
            heights.append(s[4][2] + (self.params.r * down[2] / norm if norm > 1e-9
                                      else 0.0))
        return np.array(heights)

    def body_clearance(self) -> float:
        """
        Return the smallest distance from the body's collision shapes to the world [m].

        To the ground and the obstacles, 1 m if farther; negative when they touch
        (penetration). Needs ``SimConfig.body_collision``.
        """
        if not self.config.body_collision:
            raise ValueError('body_clearance needs SimConfig(body_collision=True)')
        reach = 1.0  # [m]
        distances = [point[8] for other in (self._ground, *self._obstacles.bodies.values())
                     for link in (-1, self._joint_ids[0])
                     for point in self._pb.getClosestPoints(self._body, other, reach,
                                                            linkIndexA=link)]
        return min(distances, default=reach)

    # --- replay and rendering --------------------------------------------------------------

    def show_state(self, position: np.ndarray, orientation: np.ndarray,
                   joint_positions: dict[str, float]) -> None:
        """
        Place the robot at a recorded state without simulating.

        base_link at ``position`` [m] with ``orientation`` (quaternion x, y, z, w), joints at
        ``joint_positions`` [rad] (joints not named keep their angle).
        """
        com_pos, com_orn = pybullet.multiplyTransforms(
            list(position), list(orientation), *self._com_in_link)
        self._forget_motion()
        self._pb.resetBasePositionAndOrientation(self._body, com_pos, com_orn)
        for name, joint in zip(self.joint_names, self._joint_ids):
            if name in joint_positions:
                self._pb.resetJointState(self._body, joint, float(joint_positions[name]))

    def render(self, width: int = 320, height: int = 240,
               target: np.ndarray | None = None, distance: float = 1.4,
               yaw: float = -50.0, pitch: float = -25.0) -> np.ndarray:
        """
        Render an RGB image (height x width x 3, uint8) with pybullet's software renderer.

        The camera looks at ``target`` [m] (default base_link) from ``distance`` [m], ``yaw``
        and ``pitch`` [deg] as in pybullet's debug camera.
        """
        if target is None:
            target = self._base_pose()[0]
        view = self._pb.computeViewMatrixFromYawPitchRoll(
            cameraTargetPosition=list(map(float, target)), distance=distance, yaw=yaw,
            pitch=pitch, roll=0.0, upAxisIndex=2)
        projection = self._pb.computeProjectionMatrixFOV(
            fov=50.0, aspect=width / height, nearVal=0.05, farVal=20.0)
        _, _, rgba, _, _ = self._pb.getCameraImage(
            width, height, view, projection, renderer=pybullet.ER_TINY_RENDERER)
        return np.reshape(np.asarray(rgba, dtype=np.uint8), (height, width, 4))[:, :, :3]

    # --- obstacles -------------------------------------------------------------------------

    @property
    def obstacle_names(self) -> tuple[str, ...]:
        return tuple(self._obstacles.bodies)

    def spawn_obstacle(self, spec: StepSpec) -> str:
        """
        Add a step in front of the robot; returns its name.

        Raises
        ------
        ValueError
            Invalid field, duplicate name, or the box would overlap the robot; the world is
            unchanged.

        """
        return self._obstacles.spawn(spec, self._body, *self._base_pose(),
                                     self.params.front_axle)

    def _obstacles_overlapping_robot_at(self, x: float, y: float, yaw: float) -> list[str]:
        """Names of obstacles the robot, placed at rest at (x, y, yaw), would touch."""
        if not self._obstacles.bodies:
            return []
        pb = self._pb
        probe = pb.loadURDF(self._urdf_path, [x, y, self.params.r],
                            pybullet.getQuaternionFromEuler([0.0, 0.0, yaw]), flags=URDF_FLAGS)
        try:
            return self._obstacles.touching(probe)
        finally:
            pb.removeBody(probe)

    def remove_obstacle(self, name: str) -> None:
        """
        Remove the obstacle ``name``; the empty name removes all.

        Raises
        ------
        ValueError
            No obstacle of that name.

        """
        self._obstacles.remove(name)
