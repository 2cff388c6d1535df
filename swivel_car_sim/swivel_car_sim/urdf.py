"""URDF of the swivel car (and of a car-like baseline of the same size) from a SwivelCarParams.

ROS-free. The geometry has one source of truth, ``swivel_car_model.params.SwivelCarParams``:
``base_link`` is the middle of the rear axle at wheel-centre height (x forward, y left, z up),
the rear column rises from it to the apex at ``phi / 2``, the front column runs from the apex down
to the front axle, the swivel joint turns the front T about ``params.swivel_axis`` through the
apex. Wheels sit at ``y = +-h`` on each axle.

Mass layout (the thesis gives only the total, 21 kg, and I_s = 0.84 kg m^2 about the rear axle):
four wheels of ``wheel_mass``; of the rest M', each column 5 %, the front axle housing
(differential) 10 %, and the remaining 80 % split between the central body at the apex and the
rear axle housing so that the inertia about the rear axle equals ``params.inertia`` where that is
reachable (it is for Table 2: the body gets 2.6 kg, the rear axle 12.6 kg). Note the thesis is not
self-consistent here: its lift dynamics put all 21 kg at the apex C_m, which would give
21 * l^2 = 1.31 kg m^2, not 0.84; we keep the mass and I_s of Table 2, so our centre of mass
sits lower and further back than the thesis' point mass.

Only the wheels have collision shapes: the columns of a phi < 0 design would otherwise cut the
ground (thesis Fig. 15b says such a design needs a different body), and the climbing contact
that matters is the wheel's.
"""

from __future__ import annotations

import argparse
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from swivel_car_model.params import SwivelCarParams

ROBOT_VARIANTS = ('swivel', 'car_like')
WHEEL_JOINTS = ('rear_left_wheel_joint', 'rear_right_wheel_joint',
                'front_left_wheel_joint', 'front_right_wheel_joint')
STEER_JOINTS = {'swivel': 'swivel_joint', 'car_like': 'steering_joint'}
CAR_LIKE_MAX_STEERING = 0.6  # [rad] turntable steering limit of the baseline car

_COLUMN_FRACTION = 0.05  # [1] of the non-wheel mass, each column
_FRONT_AXLE_FRACTION = 0.10  # [1] of the non-wheel mass
_MIN_SPLIT_FRACTION = 0.05  # [1] the body and rear axle each keep at least this much of the split
# The tyre touches the ground as a thin disc, as the thesis models it. A flat cylinder of the
# full wheel_width, tilted by the swivel (up to 60 deg), rides on its rim edge and rolls like
# a cone: at theta2 = 1 rad it turned on a 4x tighter circle than the offset-tricycle model and
# lifted the body 0.03 rad more than the lift constraint. wheel_width still sets the inertia
# and the visuals.
TYRE_CONTACT_WIDTH = 0.004  # [m]


@dataclass(frozen=True)
class _Part:
    """A rigid piece of a link: mass, centre of mass and inertia about it, in the link frame."""

    mass: float  # [kg]
    com: np.ndarray  # [m]
    inertia: np.ndarray  # [kg m^2] 3x3 about com
    visual: str  # URDF <visual> element


@dataclass(frozen=True)
class RobotDescription:
    """A generated robot.

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


def _cylinder(mass: float, radius: float, start: np.ndarray, end: np.ndarray,
              material: str) -> _Part:
    """A solid cylinder (rod) from ``start`` to ``end`` in the link frame."""
    axis = end - start
    length = float(np.linalg.norm(axis))
    a = axis / length
    transverse = mass * (3.0 * radius ** 2 + length ** 2) / 12.0
    axial = mass * radius ** 2 / 2.0
    inertia = transverse * (np.eye(3) - np.outer(a, a)) + axial * np.outer(a, a)
    centre = (start + end) / 2.0
    visual = (f'<visual><origin xyz="{_fmt(centre)}" rpy="{_fmt(_rpy_z_to(a))}"/>'
              f'<geometry><cylinder radius="{radius:.9g}" length="{length:.9g}"/></geometry>'
              f'<material name="{material}"/></visual>')
    return _Part(mass, centre, inertia, visual)


def _box(mass: float, size: np.ndarray, centre: np.ndarray, material: str) -> _Part:
    sx, sy, sz = size
    inertia = np.diag([sy ** 2 + sz ** 2, sx ** 2 + sz ** 2, sx ** 2 + sy ** 2]) * mass / 12.0
    visual = (f'<visual><origin xyz="{_fmt(centre)}" rpy="0 0 0"/>'
              f'<geometry><box size="{_fmt(size)}"/></geometry>'
              f'<material name="{material}"/></visual>')
    return _Part(mass, np.asarray(centre, dtype=float), inertia, visual)


def _combine(parts: list[_Part]) -> tuple[float, np.ndarray, np.ndarray]:
    """Total mass, centre of mass and inertia about it (parallel axis theorem)."""
    mass = sum(p.mass for p in parts)
    com = sum(p.mass * p.com for p in parts) / mass
    inertia = np.zeros((3, 3))
    for p in parts:
        d = p.com - com
        inertia += p.inertia + p.mass * (float(d @ d) * np.eye(3) - np.outer(d, d))
    return mass, com, inertia


def _inertia_about_y_axis(parts: list[_Part], offset: np.ndarray) -> float:
    """I_yy about the y axis through base_link of parts whose link sits at ``offset``."""
    total = 0.0
    for p in parts:
        c = p.com + offset
        total += p.inertia[1, 1] + p.mass * (c[0] ** 2 + c[2] ** 2)
    return total


def _link(name: str, parts: list[_Part], collision: str = '') -> str:
    mass, com, inertia = _combine(parts)
    return (f'  <link name="{name}">\n'
            f'    <inertial><origin xyz="{_fmt(com)}" rpy="0 0 0"/><mass value="{mass:.9g}"/>'
            f'<inertia ixx="{inertia[0, 0]:.9g}" ixy="{inertia[0, 1]:.9g}" '
            f'ixz="{inertia[0, 2]:.9g}" iyy="{inertia[1, 1]:.9g}" iyz="{inertia[1, 2]:.9g}" '
            f'izz="{inertia[2, 2]:.9g}"/></inertial>\n'
            + ''.join(f'    {p.visual}\n' for p in parts)
            + (f'    {collision}\n' if collision else '')
            + '  </link>\n')


def _joint(name: str, kind: str, parent: str, child: str, xyz: np.ndarray,
           axis: np.ndarray | None = None, limit: float | None = None,
           effort: float = 1000.0, velocity: float = 100.0) -> str:
    text = (f'  <joint name="{name}" type="{kind}"><parent link="{parent}"/>'
            f'<child link="{child}"/><origin xyz="{_fmt(xyz)}" rpy="0 0 0"/>')
    if axis is not None:
        text += f'<axis xyz="{_fmt(axis)}"/>'
    if limit is not None:
        text += (f'<limit lower="{-limit:.9g}" upper="{limit:.9g}" effort="{effort:.9g}" '
                 f'velocity="{velocity:.9g}"/>')
    elif kind == 'continuous':
        text += f'<limit effort="{effort:.9g}" velocity="{velocity:.9g}"/>'
    return text + '</joint>\n'


def _wheel(p: SwivelCarParams) -> tuple[_Part, str]:
    """A wheel: solid disc about its link's y axis, with its cylinder collision (load with
    pybullet.URDF_USE_IMPLICIT_CYLINDER, else pybullet makes it a faceted hull)."""
    half = np.array([0.0, p.wheel_width / 2.0, 0.0])
    part = _cylinder(p.wheel_mass, p.r, -half, half, 'tyre')
    collision = (f'<collision><origin xyz="0 0 0" rpy="{_fmt([math.pi / 2.0, 0.0, 0.0])}"/>'
                 f'<geometry><cylinder radius="{p.r:.9g}" '
                 f'length="{min(p.wheel_width, TYRE_CONTACT_WIDTH):.9g}"/>'
                 '</geometry></collision>')
    return part, collision


def _split_mass(p: SwivelCarParams, fixed_inertia: float, rest: float,
                body_inertia_per_kg: float, rear_inertia_per_kg: float) -> float:
    """Body mass so that the inertia about the rear axle is ``p.inertia``, clamped."""
    low, high = _MIN_SPLIT_FRACTION * rest, (1.0 - _MIN_SPLIT_FRACTION) * rest
    # I(m_b) = fixed + m_b * body + (rest - m_b) * rear is linear in m_b.
    slope = body_inertia_per_kg - rear_inertia_per_kg
    if abs(slope) < 1e-12:
        return rest / 2.0
    m_body = (p.inertia - fixed_inertia - rest * rear_inertia_per_kg) / slope
    return min(high, max(low, m_body))


def build_robot(params: SwivelCarParams, variant: str = 'swivel',
                max_steering: float = CAR_LIKE_MAX_STEERING) -> RobotDescription:
    """Generate the URDF of a swivel car or of the car-like baseline.

    Parameters
    ----------
    params : SwivelCarParams
        Geometry and masses.
    variant : str
        'swivel' (the thesis' design) or 'car_like' (fixed rear axle, a single front axle
        steered on a turntable about the vertical through its centre, same wheels, mass,
        wheelbase and track).
    max_steering : float
        Steering limit of the car-like baseline. # [rad]

    Returns
    -------
    RobotDescription

    Raises
    ------
    ValueError
        Unknown variant or max_steering not in (0, pi/2).
    """
    if variant not in ROBOT_VARIANTS:
        raise ValueError(f'robot_variant must be one of {ROBOT_VARIANTS}, got {variant!r}')
    if not (math.isfinite(max_steering) and 0.0 < max_steering < math.pi / 2.0):
        raise ValueError(f'max_steering must be in (0, pi/2), got {max_steering!r}')
    p = params
    wb = p.wheelbase
    apex = p.apex
    front = p.front_axle
    rod = min(0.02, p.r / 3.0, p.h / 4.0)  # [m] radius of columns and axle housings
    axle_half = np.array([0.0, p.h - p.wheel_width / 2.0, 0.0])
    rest_mass = p.mass - 4.0 * p.wheel_mass
    m_col = _COLUMN_FRACTION * rest_mass
    m_front = _FRONT_AXLE_FRACTION * rest_mass
    m_split = rest_mass - 2.0 * m_col - m_front
    zero = np.zeros(3)

    wheel_part, wheel_collision = _wheel(p)
    wheel_offsets = [np.array([0.0, p.h, 0.0]), np.array([0.0, -p.h, 0.0]),
                     front + [0.0, p.h, 0.0], front + [0.0, -p.h, 0.0]]
    wheel_inertia = _inertia_about_y_axis([wheel_part], zero) * 4.0 + 2.0 * p.wheel_mass * wb ** 2

    if variant == 'swivel':
        body_centre = apex
        body_size = np.array([0.4 * p.l, 0.6 * p.h, 0.25 * p.l])
        front_origin = apex  # swivel joint on the axis, at the apex
        fixed_parts = [_cylinder(m_col, rod, zero, apex, 'frame')]
        front_parts = [_cylinder(m_col, rod, zero, front - apex, 'frame'),
                       _cylinder(m_front, rod, front - apex - axle_half,
                                 front - apex + axle_half, 'frame')]
    else:
        body_centre = np.array([wb / 2.0, 0.0, 0.0])
        body_size = np.array([wb, 0.6 * p.h, 0.25 * p.l])
        front_origin = front  # turntable about the vertical through the front axle centre
        fixed_parts = [_cylinder(2.0 * m_col, rod, zero, front, 'frame')]
        front_parts = [_cylinder(m_front, rod, -axle_half, axle_half, 'frame')]

    fixed_inertia = (wheel_inertia + _inertia_about_y_axis(fixed_parts, zero)
                     + _inertia_about_y_axis(front_parts, front_origin))
    unit_body = _box(1.0, body_size, body_centre, 'body')
    unit_rear = _cylinder(1.0, rod, -axle_half, axle_half, 'frame')
    m_body = _split_mass(p, fixed_inertia, m_split,
                         _inertia_about_y_axis([unit_body], zero),
                         _inertia_about_y_axis([unit_rear], zero))
    base_parts = [_cylinder(m_split - m_body, rod, -axle_half, axle_half, 'frame'),
                  _box(m_body, body_size, body_centre, 'body')] + fixed_parts
    front_link = 'front_t' if variant == 'swivel' else 'front_axle'
    steer_joint = STEER_JOINTS[variant]

    all_parts = base_parts + [
        _Part(q.mass, q.com + front_origin, q.inertia, '') for q in front_parts] + [
        _Part(wheel_part.mass, wheel_part.com + o, wheel_part.inertia, '')
        for o in wheel_offsets]
    total_mass, com, _ = _combine(all_parts)
    inertia = _inertia_about_y_axis(all_parts, zero)

    if variant == 'swivel':
        steer = _joint(steer_joint, 'revolute', 'base_link', front_link, front_origin,
                       axis=p.swivel_axis, limit=p.max_swivel_angle)
    else:
        steer = _joint(steer_joint, 'revolute', 'base_link', front_link, front_origin,
                       axis=np.array([0.0, 0.0, 1.0]), limit=max_steering)
    wheel_links = ['rear_left_wheel', 'rear_right_wheel', 'front_left_wheel', 'front_right_wheel']
    parents = ['base_link', 'base_link', front_link, front_link]
    origins = [wheel_offsets[0], wheel_offsets[1],
               wheel_offsets[2] - front_origin, wheel_offsets[3] - front_origin]
    text = (f'<?xml version="1.0"?>\n'
            f'<!-- Generated by swivel_car_sim.urdf from SwivelCarParams({_params_text(p)}); '
            f'do not edit. -->\n'
            f'<robot name="{"swivel_car" if variant == "swivel" else "car_like"}">\n'
            '  <material name="frame"><color rgba="0.6 0.6 0.65 1"/></material>\n'
            '  <material name="body"><color rgba="0.9 0.5 0.1 1"/></material>\n'
            '  <material name="tyre"><color rgba="0.1 0.1 0.1 1"/></material>\n'
            + _link('base_link', base_parts)
            + _link(front_link, front_parts)
            + steer
            + ''.join(_link(name, [wheel_part], wheel_collision) for name in wheel_links)
            + ''.join(_joint(j, 'continuous', parent, link, origin, axis=np.array([0, 1.0, 0]))
                      for j, parent, link, origin in zip(WHEEL_JOINTS, parents, wheel_links,
                                                         origins))
            + '</robot>\n')
    return RobotDescription(text, variant, steer_joint, WHEEL_JOINTS, total_mass, inertia, com)


def _params_text(p: SwivelCarParams) -> str:
    return ', '.join(f'{name}={getattr(p, name):.6g}' for name in ('l', 'h', 'phi', 'r', 'mass'))


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
        robot = build_robot(SwivelCarParams(), variant)
        (args.out / default_urdf_path(variant)).write_text(robot.urdf)
        print(f'{variant}: mass {robot.mass:.3f} kg, I about rear axle '
              f'{robot.inertia_about_rear_axle:.3f} kg m^2, com {np.round(robot.com, 4)} m')


if __name__ == '__main__':
    main()
