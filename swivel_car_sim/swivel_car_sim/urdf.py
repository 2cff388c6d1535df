"""
URDF of the swivel car (and of a car-like baseline of the same size) from a CarDescription.

ROS-free. The robot has one source of truth, ``swivel_car_model.description.CarDescription``:
its parts (``CarDescription.parts``) become the links' inertials and visuals here, nothing
else is decided in this module but how a link is written. ``base_link`` is the middle of the
rear axle at wheel-centre height (x forward, y left, z up); the swivel joint turns the front T
about the front column's axis through the apex; wheels sit at ``y = +-h`` on each axle.

By default only the wheels have collision shapes: the climbing contact that matters for the
phi > 0 robot is the wheel's (its belly, above the axle line, would first meet the edge of a
13.5 cm step, higher than it climbs), and the phi < 0 designs of the thesis' Table 2 (apex
under the ground, thesis Fig. 15b) can still be simulated. ``body_collision`` gives every
other part its shape too: a phi < 0 robot that can exist
(``swivel_car_model/config/designs/phi_negative.yaml``) hangs its apex below the axle line,
and its belly is what meets a step edge first.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass
import math
from pathlib import Path

import numpy as np

from swivel_car_model.description import (
    BASE_LINK, CAMERA_LINK, CAMERA_OPTICAL_FRAME, CarDescription, combine, FRONT_LINK,
    inertia_about_y_axis, Part, ROBOT_VARIANTS, WHEEL_LINKS)

WHEEL_JOINTS = ('rear_left_wheel_joint', 'rear_right_wheel_joint',
                'front_left_wheel_joint', 'front_right_wheel_joint')
STEER_JOINTS = {'swivel': 'swivel_joint', 'car_like': 'steering_joint'}
CAR_LIKE_MAX_STEERING = 0.6  # [rad] turntable steering limit of the baseline car
# The tyre touches the ground as a thin disc, as the thesis models it. A flat cylinder of the
# full wheel_width, tilted by the swivel (up to 60 deg), rides on its rim edge and rolls like
# a cone: at theta2 = 1 rad it turned on a 4x tighter circle than the offset-tricycle model and
# lifted the body 0.03 rad more than the lift constraint. wheel_width still sets the inertia
# and the visuals.
TYRE_CONTACT_WIDTH = 0.004  # [m]
_MATERIALS = {'body': 'body', **dict.fromkeys(WHEEL_LINKS, 'tyre')}


@dataclass(frozen=True)
class RobotModel:
    """
    A generated robot.

    Attributes
    ----------
    urdf : str
        The URDF document.
    variant : str
        'swivel' or 'car_like'.
    steer_joint : str
        Name of the actuated steering joint (swivel_joint or steering_joint).
    wheel_joints : tuple of str
        The four wheel joints, rear left, rear right, front left, front right.
    mass : float
        Total mass. # [kg]
    inertia_about_rear_axle : float
        Moment of inertia about the rear axle's line (base_link y) at rest. # [kg m^2]
    com : numpy.ndarray
        Centre of mass in base_link at rest. # [m]

    """

    urdf: str
    variant: str
    steer_joint: str
    wheel_joints: tuple[str, ...]
    mass: float
    inertia_about_rear_axle: float
    com: np.ndarray


def _fmt(values) -> str:
    return ' '.join(f'{float(v):.9g}' for v in np.atleast_1d(values))


def _rpy_z_to(direction: np.ndarray) -> np.ndarray:
    """URDF rpy turning the z axis onto ``direction`` (R = Rz(yaw) Ry(pitch))."""
    d = direction / np.linalg.norm(direction)
    return np.array([0.0, math.acos(max(-1.0, min(1.0, d[2]))), math.atan2(d[1], d[0])])


def _shape(part: Part, origin: np.ndarray) -> str:
    """Return the part's <origin> and <geometry> in a link frame with origin ``origin`` [m]."""
    centre = part.com - origin
    if part.shape == 'box':
        return (f'<origin xyz="{_fmt(centre)}" rpy="0 0 0"/>'
                f'<geometry><box size="{_fmt(part.size)}"/></geometry>')
    radius, length = part.size
    return (f'<origin xyz="{_fmt(centre)}" rpy="{_fmt(_rpy_z_to(part.axis))}"/>'
            f'<geometry><cylinder radius="{radius:.9g}" length="{length:.9g}"/></geometry>')


def _visual(part: Part, origin: np.ndarray) -> str:
    material = _MATERIALS.get(part.name, 'frame')
    return f'<visual>{_shape(part, origin)}<material name="{material}"/></visual>'


def _link(name: str, parts: list[Part], origin: np.ndarray, collision: str = '') -> str:
    mass, com, inertia = combine(parts)
    return (f'  <link name="{name}">\n'
            f'    <inertial><origin xyz="{_fmt(com - origin)}" rpy="0 0 0"/>'
            f'<mass value="{mass:.9g}"/>'
            f'<inertia ixx="{inertia[0, 0]:.9g}" ixy="{inertia[0, 1]:.9g}" '
            f'ixz="{inertia[0, 2]:.9g}" iyy="{inertia[1, 1]:.9g}" iyz="{inertia[1, 2]:.9g}" '
            f'izz="{inertia[2, 2]:.9g}"/></inertial>\n'
            + ''.join(f'    {_visual(p, origin)}\n' for p in parts)
            + (f'    {collision}\n' if collision else '')
            + '  </link>\n')


def _joint(name: str, kind: str, parent: str, child: str, xyz: np.ndarray,
           axis: np.ndarray | None = None, limit: float | None = None,
           rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> str:
    # Generous effort and velocity limits: pybullet reads them, and the sim applies the
    # description's actuator limits itself (the drive train model, the swivel clamp).
    effort, velocity = 1000.0, 100.0
    text = (f'  <joint name="{name}" type="{kind}"><parent link="{parent}"/>'
            f'<child link="{child}"/><origin xyz="{_fmt(xyz)}" rpy="{_fmt(rpy)}"/>')
    if axis is not None:
        text += f'<axis xyz="{_fmt(axis)}"/>'
    if limit is not None:
        text += (f'<limit lower="{-limit:.9g}" upper="{limit:.9g}" effort="{effort:.9g}" '
                 f'velocity="{velocity:.9g}"/>')
    elif kind == 'continuous':
        text += f'<limit effort="{effort:.9g}" velocity="{velocity:.9g}"/>'
    return text + '</joint>\n'


def _wheel_collision(d: CarDescription) -> str:
    """
    Return the wheel's cylinder collision.

    Load it with pybullet.URDF_USE_IMPLICIT_CYLINDER, else pybullet makes it a faceted hull.
    """
    return (f'<collision><origin xyz="0 0 0" rpy="{_fmt([math.pi / 2.0, 0.0, 0.0])}"/>'
            f'<geometry><cylinder radius="{d.r:.9g}" '
            f'length="{min(d.wheel_width, TYRE_CONTACT_WIDTH):.9g}"/>'
            '</geometry></collision>')


def _camera_frames(d: CarDescription) -> str:
    """
    Return the depth camera's frames: ``camera_link`` and its REP-103 optical frame.

    Links without an inertial: they are frames for TF, not bodies (pybullet would give each a
    mass of 1 kg, so the sim loads the robot without them and places its camera itself).
    """
    position, pitch = d.camera_mount()
    return (f'  <link name="{CAMERA_LINK}"/>\n  <link name="{CAMERA_OPTICAL_FRAME}"/>\n'
            + _joint(f'{CAMERA_LINK}_joint', 'fixed', BASE_LINK, CAMERA_LINK, position,
                     rpy=(0.0, pitch, 0.0))
            # Optical: z forward, x right, y down.
            + _joint(f'{CAMERA_OPTICAL_FRAME}_joint', 'fixed', CAMERA_LINK,
                     CAMERA_OPTICAL_FRAME, np.zeros(3), rpy=(-math.pi / 2.0, 0.0, -math.pi / 2.0)))


def build_robot(description: CarDescription, variant: str = 'swivel',
                max_steering: float = CAR_LIKE_MAX_STEERING,
                body_collision: bool = False, sensor_frames: bool = True) -> RobotModel:
    """
    Generate the URDF of a swivel car or of the car-like baseline.

    Parameters
    ----------
    description : CarDescription
        Geometry, mass layout and actuator limits.
    variant : str
        'swivel' (the thesis' design) or 'car_like' (rigid frame, a single front axle
        steered on a turntable about the vertical through its centre; same parts, masses,
        wheelbase and track).
    max_steering : float
        Steering limit of the car-like baseline. # [rad]
    body_collision : bool
        Give the columns, axle housings and central body collision shapes too (default:
        the wheels only; see the module docstring).
    sensor_frames : bool
        Add the depth camera's frames (``CarDescription.camera_mount``); the sim leaves
        them out.

    Returns
    -------
    RobotModel

    Raises
    ------
    ValueError
        Unknown variant or max_steering not in (0, pi/2).

    """
    if not (math.isfinite(max_steering) and 0.0 < max_steering < math.pi / 2.0):
        raise ValueError(f'max_steering must be in (0, pi/2), got {max_steering!r}')
    d = description
    parts = d.parts(variant)
    front_link = FRONT_LINK[variant]
    if variant == 'swivel':
        front_origin = d.apex  # swivel joint on the axis, at the apex
        steer_axis = d.model_params().swivel_axis
        steer_limit = d.max_swivel_angle
    else:
        front_origin = np.array([d.wheelbase, 0.0, 0.0])  # turntable at the front axle
        steer_axis = np.array([0.0, 0.0, 1.0])
        steer_limit = max_steering
    steer_joint = STEER_JOINTS[variant]
    origins = {BASE_LINK: np.zeros(3), front_link: front_origin,
               **dict(zip(WHEEL_LINKS, d.wheel_centres()))}
    total_mass, com, _ = combine(parts)
    collision = _wheel_collision(d)
    wheel_parents = [BASE_LINK, BASE_LINK, front_link, front_link]
    text = (f'<?xml version="1.0"?>\n'
            f'<!-- Generated by swivel_car_sim.urdf from CarDescription({_description_text(d)}); '
            f'do not edit. -->\n'
            f'<robot name="{"swivel_car" if variant == "swivel" else "car_like"}">\n'
            '  <material name="frame"><color rgba="0.6 0.6 0.65 1"/></material>\n'
            '  <material name="body"><color rgba="0.9 0.5 0.1 1"/></material>\n'
            '  <material name="tyre"><color rgba="0.1 0.1 0.1 1"/></material>\n'
            + ''.join(_link(link, [p for p in parts if p.link == link], origins[link],
                            collision if link in WHEEL_LINKS else
                            _body_collisions(parts, link, origins[link]) if body_collision
                            else '')
                      for link in (BASE_LINK, front_link) + WHEEL_LINKS)
            + _joint(steer_joint, 'revolute', BASE_LINK, front_link, front_origin,
                     axis=steer_axis, limit=steer_limit)
            + ''.join(_joint(j, 'continuous', parent, link, origins[link] - origins[parent],
                             axis=np.array([0, 1.0, 0]))
                      for j, parent, link in zip(WHEEL_JOINTS, wheel_parents, WHEEL_LINKS))
            + (_camera_frames(d) if sensor_frames else '')
            + '</robot>\n')
    return RobotModel(text, variant, steer_joint, WHEEL_JOINTS, total_mass,
                      inertia_about_y_axis(parts), com)


def _body_collisions(parts: list[Part], link: str, origin: np.ndarray) -> str:
    return '\n    '.join(f'<collision>{_shape(p, origin)}</collision>'
                         for p in parts if p.link == link)


def _description_text(d: CarDescription) -> str:
    return ', '.join(f'{name}={getattr(d, name):.6g}' for name in (
        'l', 'h', 'phi', 'r', 'body_mass', 'body_offset', 'rear_axle_mass', 'front_axle_mass'))


def default_urdf_path(variant: str) -> str:
    """File name of the committed default URDF of ``variant``."""
    return f'{"swivel_car" if variant == "swivel" else "car_like"}.urdf'


def main(argv: list[str] | None = None) -> None:
    """Write the default URDFs: ``python -m swivel_car_sim.urdf --out urdf``."""
    parser = argparse.ArgumentParser(description=main.__doc__)
    parser.add_argument('--out', type=Path, required=True, help='output directory')
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    for variant in ROBOT_VARIANTS:
        robot = build_robot(CarDescription(), variant)
        (args.out / default_urdf_path(variant)).write_text(robot.urdf)
        print(f'{variant}: mass {robot.mass:.3f} kg, I about rear axle '
              f'{robot.inertia_about_rear_axle:.3f} kg m^2, com {np.round(robot.com, 4)} m')


if __name__ == '__main__':
    main()
