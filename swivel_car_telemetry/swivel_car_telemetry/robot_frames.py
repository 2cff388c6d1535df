"""
The frames of a URDF's links from joint positions, as robot_state_publisher computes them.

One transform parent link -> child link per joint. ROS-free.

Used where robot_state_publisher is not installed, by ``robot_description_node`` for /tf and
/tf_static.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from typing import Mapping
import xml.etree.ElementTree as ElementTree

import numpy as np

MOVING = ('revolute', 'continuous', 'prismatic')


@dataclass(frozen=True)
class Joint:
    """
    One URDF joint.

    Attributes
    ----------
    name, kind, parent, child : str
        As in the URDF (kind: fixed, revolute, continuous, prismatic...).
    xyz : numpy.ndarray
        Origin of the child frame in the parent frame at position 0. # [m]
    rotation : numpy.ndarray
        Its orientation, quaternion (x, y, z, w).
    axis : numpy.ndarray
        Unit joint axis in the child frame.

    """

    name: str
    kind: str
    parent: str
    child: str
    xyz: np.ndarray
    rotation: np.ndarray
    axis: np.ndarray


@dataclass(frozen=True)
class Frame:
    """A transform parent -> child: translation [m] and quaternion (x, y, z, w)."""

    parent: str
    child: str
    translation: tuple[float, float, float]
    rotation: tuple[float, float, float, float]


def _floats(text: str | None, default: str) -> np.ndarray:
    return np.array([float(v) for v in (text or default).split()])


def _quaternion_from_rpy(roll: float, pitch: float, yaw: float) -> np.ndarray:
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return np.array([sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
                     cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy])


def _multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return np.array([aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz])


def parse_joints(urdf: str) -> list[Joint]:
    """
    Parse the joints of a URDF document.

    Raises
    ------
    ValueError
        Not a URDF robot, or a joint without parent or child.

    """
    try:
        robot = ElementTree.fromstring(urdf)
    except ElementTree.ParseError as error:
        raise ValueError(f'not XML: {error}') from None
    if robot.tag != 'robot':
        raise ValueError(f'not a URDF robot: root element <{robot.tag}>')
    joints = []
    for element in robot.findall('joint'):
        parent, child = element.find('parent'), element.find('child')
        if parent is None or child is None:
            raise ValueError(f'joint {element.get("name")!r} lacks a parent or a child')
        origin = element.find('origin')
        axis = element.find('axis')
        direction = _floats(axis.get('xyz') if axis is not None else None, '1 0 0')
        joints.append(Joint(
            element.get('name', ''), element.get('type', ''), parent.get('link', ''),
            child.get('link', ''),
            _floats(origin.get('xyz') if origin is not None else None, '0 0 0'),
            _quaternion_from_rpy(*_floats(origin.get('rpy') if origin is not None else None,
                                          '0 0 0')),
            direction / np.linalg.norm(direction)))
    return joints


def joint_frame(joint: Joint, position: float = 0.0) -> Frame:
    """Return the transform parent -> child of ``joint`` at ``position`` [rad or m]."""
    translation, rotation = joint.xyz, joint.rotation
    if joint.kind in ('revolute', 'continuous'):
        half = position / 2.0
        rotation = _multiply(rotation, np.append(joint.axis * math.sin(half), math.cos(half)))
    elif joint.kind == 'prismatic':
        rotated = _multiply(_multiply(rotation, np.append(joint.axis * position, 0.0)),
                            rotation * np.array([-1.0, -1.0, -1.0, 1.0]))
        translation = translation + rotated[:3]
    return Frame(joint.parent, joint.child, tuple(float(v) for v in translation),
                 tuple(float(v) for v in rotation))


def fixed_frames(joints: list[Joint]) -> list[Frame]:
    """Return the frames of the fixed joints (robot_state_publisher's /tf_static)."""
    return [joint_frame(j) for j in joints if j.kind not in MOVING]


def moving_frames(joints: list[Joint], positions: Mapping[str, float]) -> list[Frame]:
    """Return the frames of the moving joints named in ``positions`` (its /tf)."""
    return [joint_frame(j, positions[j.name]) for j in joints
            if j.kind in MOVING and j.name in positions]


class RateLimit:
    """
    At most one publication per ``period`` [s] of message time.

    As robot_state_publisher's publish_frequency limits /tf, but by the messages' stamps, not
    a clock, so a lockstep sim gives the same publications every run. Time going back (a
    restarted sim) starts again.
    """

    def __init__(self, period: float) -> None:
        if not (isinstance(period, (int, float)) and math.isfinite(period) and period >= 0.0):
            raise ValueError(f'the period must be a number >= 0 s, got {period!r}')
        self._period = period  # [s]
        self._last: float | None = None  # [s] message time of the last publication

    def due(self, t: float) -> bool:
        """Return whether a message of time ``t`` [s] is published (and count it if so)."""
        # 1 ns of slack: stamps are whole nanoseconds, a period of 0.05 s is not in floats.
        if self._last is None or t < self._last or t - self._last >= self._period - 1e-9:
            self._last = t
            return True
        return False
