"""
The simulated world around the robot: step obstacles in a pybullet client; ROS-free.

``StepSpec`` is a step as a request gives it (relative to the robot); ``Obstacles`` places,
spawns, finds and removes the steps of one pybullet client, by name.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from types import MappingProxyType

import numpy as np
import pybullet
from swivel_car_model.checks import check_finite_number


@dataclass(frozen=True)
class StepSpec:
    """
    A rectangular step, relative to base_link at the time of the request.

    See swivel_car_msgs/msg/StepObstacle.msg for the meaning of each field.
    """

    name: str
    height: float  # [m]
    depth: float  # [m]
    width: float  # [m]
    distance: float  # [m]
    yaw: float  # [rad]
    friction: float  # [1]

    def validate(self) -> None:
        """Raise ValueError naming the first bad field."""
        for name in ('height', 'depth', 'width', 'distance', 'yaw', 'friction'):
            check_finite_number(name, getattr(self, name))  # a bool too: True, a 1 m step
        if not 0.0 < self.height <= 1.0:
            raise ValueError(f'height must be in (0, 1] m, got {self.height!r}')
        for name in ('depth', 'width'):
            if not 0.0 < getattr(self, name) <= 20.0:
                raise ValueError(f'{name} must be in (0, 20] m, got {getattr(self, name)!r}')
        if self.distance < 0.0:
            raise ValueError(f'distance must be >= 0 m, got {self.distance!r}')
        if not -math.pi / 2.0 < self.yaw < math.pi / 2.0:
            raise ValueError(f'yaw must be in (-pi/2, pi/2) rad, got {self.yaw!r}')
        if not 0.0 < self.friction <= 10.0:
            raise ValueError(f'friction must be in (0, 10], got {self.friction!r}')


class BoundClient:
    """pybullet functions bound to one physics client."""

    def __init__(self, client: int) -> None:
        self._client = client

    def __getattr__(self, name: str):
        function = getattr(pybullet, name)

        def bound(*args, **kwargs):
            return function(*args, physicsClientId=self._client, **kwargs)
        bound.__name__ = name
        setattr(self, name, bound)
        return bound


class Obstacles:
    """
    The step obstacles of one pybullet client, by name.

    Parameters
    ----------
    pb : BoundClient
        The client the steps live in.

    """

    def __init__(self, pb: BoundClient) -> None:
        self._pb = pb
        self._bodies: dict[str, int] = {}
        self._counter = 0
        self.bodies = MappingProxyType(self._bodies)  # name -> pybullet body, read-only

    def spawn(self, spec: StepSpec, robot: int, base_position: np.ndarray,
              base_orientation: np.ndarray, front_axle: np.ndarray) -> str:
        """
        Add the step ``spec`` in front of the robot; returns its name.

        Parameters
        ----------
        spec : StepSpec
            The step, its distance measured from the front axle along the robot's heading.
        robot : int
            The robot's pybullet body, which the step must not touch.
        base_position, base_orientation : numpy.ndarray
            base_link's origin [m] and orientation (quaternion x, y, z, w) in the world.
        front_axle : numpy.ndarray
            The front axle's middle in base_link. # [m]

        Raises
        ------
        ValueError
            Invalid field, duplicate name, or the box would overlap the robot; the world is
            unchanged.

        """
        spec.validate()
        name = spec.name or self._next_name()
        if name in self._bodies:
            raise ValueError(f'an obstacle named {name!r} exists already')
        position, orientation, half = _step_placement(spec, base_position, base_orientation,
                                                      front_axle)
        pb = self._pb
        shape = pb.createCollisionShape(pybullet.GEOM_BOX, halfExtents=half.tolist())
        if pb.getClosestPoints(bodyA=robot, bodyB=-1, distance=0.0, collisionShapeB=shape,
                               collisionShapePositionB=position.tolist(),
                               collisionShapeOrientationB=orientation):
            pb.removeCollisionShape(shape)
            raise ValueError(f'obstacle {name!r} would overlap the robot (distance '
                             f'{spec.distance} m, yaw {spec.yaw} rad)')
        visual = pb.createVisualShape(pybullet.GEOM_BOX, halfExtents=half.tolist(),
                                      rgbaColor=[0.5, 0.5, 0.8, 1.0])
        body = pb.createMultiBody(0.0, shape, visual, position.tolist(), orientation)
        pb.changeDynamics(body, -1, lateralFriction=spec.friction)
        self._bodies[name] = body
        if not spec.name:
            self._counter += 1
        return name

    def _next_name(self) -> str:
        counter = self._counter
        while f'step_{counter}' in self._bodies:
            counter += 1
        self._counter = counter
        return f'step_{counter}'

    def touching(self, body: int) -> list[str]:
        """Names of the obstacles the pybullet ``body`` touches or penetrates."""
        return [name for name, obstacle in self._bodies.items()
                if self._pb.getClosestPoints(body, obstacle, 0.0)]

    def remove(self, name: str) -> None:
        """Remove the obstacle ``name``, all for ``''``; ValueError if there is none."""
        if name == '':
            for body in self._bodies.values():
                self._pb.removeBody(body)
            self._bodies.clear()
            return
        if name not in self._bodies:
            raise ValueError(f'no obstacle named {name!r} (have: {sorted(self._bodies)})')
        self._pb.removeBody(self._bodies.pop(name))


def _step_placement(spec: StepSpec, base_pos: np.ndarray, base_orn: np.ndarray,
                    front_axle: np.ndarray):
    """Centre, orientation and half extents of the box of ``spec``."""
    rotation = np.array(pybullet.getMatrixFromQuaternion(base_orn)).reshape(3, 3)
    heading = math.atan2(rotation[1, 0], rotation[0, 0])
    contact = base_pos + rotation @ front_axle
    direction = np.array([math.cos(heading), math.sin(heading), 0.0])
    normal_yaw = heading + spec.yaw
    normal = np.array([math.cos(normal_yaw), math.sin(normal_yaw), 0.0])
    edge = np.array([contact[0], contact[1], 0.0]) + spec.distance * direction
    centre = edge + normal * spec.depth / 2.0 + np.array([0.0, 0.0, spec.height / 2.0])
    orientation = pybullet.getQuaternionFromEuler([0.0, 0.0, normal_yaw])
    return centre, orientation, np.array([spec.depth, spec.width, spec.height]) / 2.0
