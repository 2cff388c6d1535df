"""
The robot description: one statement of the swivel car that every part of the stack reads.

Geometry, every mass and where it sits, the drive train, the actuator limits and the swivel
gains. The inertia about the rear axle (thesis I_s) and the total mass are *derived* from the
mass layout, never asserted. The URDF (``swivel_car_sim.urdf``), the sim, the controller, the
odometry, the planner, the benchmarks and the demo all take their values from a
``CarDescription``; the nodes declare its fields as ROS parameters with these defaults and
descriptions (``PARAMETERS``), so a user changes the robot in one place.

The mathematics of the thesis keeps its own parameter set, ``SwivelCarParams`` (thesis
Table 2: the reference set of the reproduction table); ``CarDescription.model_params`` gives
the set that describes this robot.

Rigid bodies, in ``base_link`` at rest (the middle of the rear axle at wheel-centre height,
x forward, y left, z up)::

    base_link: rear axle housing (rod along y), rear column (rod from base_link to the apex),
               central body (batteries, motors, electronics: a box at the apex, shifted
               ``body_offset`` forward)
    front_t:   front column (rod from the apex to the front axle), front axle housing
    wheels:    four solid discs at (0, +-h, 0) and (wheelbase, +-h, 0)

Mass layout and drive train (docs/climbing_design.md). The swivel lifts whichever axle is
lighter, and once the front is on the step the rear axle climbs by traction, which wants
weight on the front wheels. So the batteries, motors and electronics (12 kg) sit in the
central body at the apex, the rear axle housing is light, the differentials are open and the
drive motor gives 20 N m: 21 kg, centre of mass at 47 % of the wheelbase, I_s 1.44 kg m^2
(derived; the thesis' 0.84). The front is still the lighter axle, so on flat ground the
swivel lifts a front wheel and the car steers as the thesis' offset tricycle, and the whole
car climbs 7 cm in every benchmark climb, 8 cm in 93 %. ``config/designs/thesis_inertia.yaml``
is the layout chosen only to match the thesis' I_s (heavy rear axle housing, centre of mass
at 24 %, 10 N m): it climbs 6 cm.

Swivel gains. Thesis Table 2 (kp 19 N m/rad, ki 11.45 N m/(rad s), kd 5.5 N m s/rad, the
documented starting point and ``SwivelCarParams``' defaults) is far too soft for the simulated
car: the swivel must lift the body (about 5 N m of gravity load at 0.5 rad), so with kp = 19 the
proportional term alone cannot hold it and the integral has to do the work: a 0.5 rad step
takes about 3 s to settle, and a 1.2 rad step overshoots by 18 % and does not settle within
3 s (stick-slip limit cycle). Sweeping (kp, ki, kd) on the sim's step responses (0 -> 0.5,
0.5 -> 0, 0 -> 1.2, 1.2 -> -1.2, 0 -> 0.1 rad, set-point rate limit 1.5 rad/s) and on the yaw
rate reached in tight turns gave the defaults here (150, 200, 8), together with the controller's
``integral_band`` of 0.05 rad (the integral winds up while the set point ramps away, then
holds the swivel a few hundredths of a radian past its target for seconds: at 1.3 rad that is
5 % more yaw rate): overshoot <= 0.5 %, 2 % settling 0.4-2.1 s, tight arcs within 1 % of the
asked yaw rate. kd = 8 is above 2 I / dt = 7.2 N m s/rad for the bare front T (I = 0.036
kg m^2) at 100 Hz, but the swivel always carries the body it lifts, and no chatter shows.
See swivel_car_control/README.md for the figures.

The car-like baseline (a rigid frame and a front axle steered on a turntable) carries the same
parts at the same places, its frame rod along the ground, so its mass layout is the same.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields, replace
import math
from typing import Any, Mapping

import numpy as np

from swivel_car_model.checks import check_finite_number
from swivel_car_model.params import SwivelCarParams

ROBOT_VARIANTS = ('swivel', 'car_like')
DIFFERENTIALS = ('open', 'locked')
BASE_LINK = 'base_link'
FRONT_LINK = {'swivel': 'front_t', 'car_like': 'front_axle'}
WHEEL_LINKS = ('rear_left_wheel', 'rear_right_wheel', 'front_left_wheel', 'front_right_wheel')
CAMERA_LINK = 'camera_link'
CAMERA_OPTICAL_FRAME = 'camera_depth_optical_frame'
# The depth camera (a RealSense D435-class stereo camera) sits on the central body's top front
# corner, looking forward and pitched down so that its 58 deg vertical view spans the ground
# from just past the front wheels to beyond the horizon: steps from about 0.3 m to 2 m
# ahead of the front axle. Its housing is left out of the mass layout (72 g against 21 kg).
CAMERA_PITCH = 0.35  # [rad] optical axis below base_link's x axis
CAMERA_CLEARANCE = 0.015  # [m] lens ahead of and above the body's box
# The optical frame's axes (REP 103: x right, y down, z forward) as columns in camera_link
# (x forward, y left, z up).
OPTICAL_IN_CAMERA_LINK = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])


def described(default: Any, description: str) -> Any:
    """
    Make a dataclass field with a description.

    Its ``metadata['description']`` (with its unit) is also its ROS parameter's description.
    """
    return field(default=default, metadata={'description': description})


@dataclass(frozen=True)
class CarDescription:
    """
    The swivel car as built: geometry, mass layout, drive train, actuators, gains.

    Each field's metadata ``description`` (with its unit) is also its ROS parameter's.

    Raises
    ------
    ValueError
        A field is of the wrong type, not finite or not physical; the message names it.

    """

    l: float = described(0.25, 'T column length, axle centre to apex [m]')
    h: float = described(0.15, 'half wheel shaft: wheel centre plane to the column [m]')
    phi: float = described(math.pi / 3, 'angle between the T columns (each rises at phi/2) [rad]')
    r: float = described(0.075, 'wheel radius [m]')
    wheel_width: float = described(0.03, 'wheel tread width [m]')
    max_swivel_angle: float = described(math.pi / 2,
                                        'mechanical swivel joint limit, symmetric [rad]')
    swivel_limit: float = described(
        1.4, 'largest |swivel angle| commanded (controller set point, planner command), at '
        'most max_swivel_angle; the controller lowers it further to keep the tip-over rule '
        '[rad]')
    wheel_mass: float = described(0.5, 'mass of one wheel [kg]')
    body_mass: float = described(
        12.0, 'central body (batteries, motors, electronics) at the apex [kg]')
    body_offset: float = described(
        0.0, 'central body centre forward of the apex, along base_link x [m]')
    rear_axle_mass: float = described(3.2, 'rear axle housing with its differential [kg]')
    front_axle_mass: float = described(1.9, 'front axle housing with its differential [kg]')
    column_mass: float = described(0.95, 'mass of each T column [kg]')
    front_differential: str = described('open', "front axle differential: 'open' or 'locked'")
    rear_differential: str = described('open', "rear axle differential: 'open' or 'locked'")
    drive_torque_limit: float = described(
        20.0, 'largest total drive torque at the wheels (the drive motor) [N m]')
    drive_speed_limit: float = described(20.0, 'largest drive speed at the wheels [rad/s]')
    swivel_torque_limit: float = described(30.0, 'peak torque of the swivel actuator [N m]')
    kp: float = described(150.0, 'swivel PID proportional gain [N m/rad]')
    ki: float = described(200.0, 'swivel PID integral gain [N m/(rad s)]')
    kd: float = described(8.0, 'swivel PID derivative gain, on the measured rate [N m s/rad]')
    wheel_friction: float = described(1.0, 'friction coefficient of the tyres [1]')

    def __post_init__(self) -> None:
        for item in fields(self):
            value = getattr(self, item.name)
            if isinstance(item.default, str):
                if item.name.endswith('_differential') and value not in DIFFERENTIALS:
                    raise ValueError(f'{item.name} must be one of {DIFFERENTIALS}, '
                                     f'got {value!r}')
                continue
            check_finite_number(item.name, value)
            if item.name not in ('phi', 'body_offset', 'kp', 'ki', 'kd') and value <= 0.0:
                raise ValueError(f'{item.name} must be > 0, got {value!r}')
        for name in ('kp', 'ki', 'kd'):
            if getattr(self, name) < 0.0:
                raise ValueError(f'{name} must be >= 0, got {getattr(self, name)!r}')
        if abs(self.body_offset) > self.l:
            raise ValueError(f'body_offset must be within +-l ({self.l!r} m), '
                             f'got {self.body_offset!r}')
        # The remaining geometric rules (phi, wheel width, swivel limit) are the model's.
        self.model_params()

    @classmethod
    def from_values(cls, values: Mapping[str, Any]) -> 'CarDescription':
        """
        Build from parameter values (missing ones take their default).

        An integer where a float is declared counts as that float.

        Raises
        ------
        ValueError
            Unknown name, wrong type or value; the message names the parameter.

        """
        known = {item.name: item for item in fields(cls)}
        unknown = sorted(set(values) - set(known))
        if unknown:
            raise ValueError(f'unknown robot description parameter(s): {", ".join(unknown)}')
        converted = {}
        for name, value in values.items():
            if isinstance(known[name].default, float) and isinstance(value, int) \
                    and not isinstance(value, bool):
                value = float(value)
            converted[name] = value
        return cls(**converted)

    def replace(self, **changes: Any) -> 'CarDescription':
        """Return a copy with ``changes`` (validated)."""
        return replace(self, **changes)

    # --- derived quantities ---------------------------------------------------------------

    # The model's geometry, read from the same l and phi (not dataclass fields).
    wheelbase = SwivelCarParams.wheelbase
    apex = SwivelCarParams.apex

    def parts(self, variant: str = 'swivel') -> list['Part']:
        """
        Return the rigid pieces of the robot with their masses and inertias.

        In base_link at rest; ``variant`` is 'swivel' or 'car_like'.
        """
        if variant not in ROBOT_VARIANTS:
            raise ValueError(f'robot_variant must be one of {ROBOT_VARIANTS}, got {variant!r}')
        zero = np.zeros(3)
        front = np.array([self.wheelbase, 0.0, 0.0])
        apex = self.apex
        rod = min(0.02, self.r / 3.0, self.h / 4.0)  # [m] radius of columns and housings
        axle_half = np.array([0.0, self.h - self.wheel_width / 2.0, 0.0])
        body_size = self.body_size
        front_link = FRONT_LINK[variant]
        parts = [Part.rod('rear_axle', BASE_LINK, self.rear_axle_mass, rod,
                          -axle_half, axle_half),
                 Part.box('body', BASE_LINK, self.body_mass, body_size,
                          apex + [self.body_offset, 0.0, 0.0])]
        if variant == 'swivel':
            parts += [Part.rod('rear_column', BASE_LINK, self.column_mass, rod, zero, apex),
                      Part.rod('front_column', front_link, self.column_mass, rod, apex, front)]
        else:
            parts += [Part.rod('frame', BASE_LINK, 2.0 * self.column_mass, rod, zero, front)]
        parts.append(Part.rod('front_axle', front_link, self.front_axle_mass, rod,
                              front - axle_half, front + axle_half))
        half_tread = np.array([0.0, self.wheel_width / 2.0, 0.0])
        for link, centre in zip(WHEEL_LINKS, self.wheel_centres()):
            parts.append(Part.rod(link, link, self.wheel_mass, self.r, centre - half_tread,
                                  centre + half_tread))
        return parts

    @property
    def body_size(self) -> np.ndarray:
        """Edges of the central body's box along base_link x, y, z [m]."""
        return np.array([0.4 * self.l, 0.6 * self.h, 0.25 * self.l])

    def camera_mount(self) -> tuple[np.ndarray, float]:
        """
        Return where the depth camera's ``camera_link`` sits in base_link at rest.

        Returns
        -------
        (position [m], pitch [rad]): the lens centre, and the optical axis' angle below
        base_link's x axis (camera_link's rotation about base_link's y axis).

        """
        size = self.body_size
        position = self.apex + np.array([self.body_offset + size[0] / 2.0 + CAMERA_CLEARANCE,
                                         0.0, size[2] / 2.0 + CAMERA_CLEARANCE])
        return position, CAMERA_PITCH

    def camera_optical_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """
        Return the depth camera's optical frame in base_link at rest.

        Returns
        -------
        (origin [m], axes [1]): the optical x (right), y (down) and z (forward) axes as the
        columns of a rotation matrix.

        """
        position, pitch = self.camera_mount()
        c, s = math.cos(pitch), math.sin(pitch)
        pitched = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
        return position, pitched @ OPTICAL_IN_CAMERA_LINK

    def wheel_centres(self) -> list[np.ndarray]:
        """
        Wheel centres in base_link at rest [m].

        Rear left, rear right, front left, front right.
        """
        wb = self.wheelbase
        return [np.array([0.0, self.h, 0.0]), np.array([0.0, -self.h, 0.0]),
                np.array([wb, self.h, 0.0]), np.array([wb, -self.h, 0.0])]

    @property
    def mass(self) -> float:
        """Total mass [kg]."""
        return sum(part.mass for part in self.parts())

    @property
    def com(self) -> np.ndarray:
        """Centre of mass in base_link at rest [m]."""
        return combine(self.parts())[1]

    @property
    def com_fraction(self) -> float:
        """Centre of mass along the wheelbase, 0 at the rear axle, 1 at the front [1]."""
        return float(self.com[0]) / self.wheelbase

    @property
    def inertia_about_rear_axle(self) -> float:
        """Moment of inertia about the rear axle's line (thesis I_s) [kg m^2]."""
        return inertia_about_y_axis(self.parts())

    def model_params(self) -> SwivelCarParams:
        """Return the thesis model's parameter set for this robot (mass and I_s derived)."""
        parts = self.parts()
        return SwivelCarParams(
            l=self.l, h=self.h, phi=self.phi, r=self.r,
            mass=sum(part.mass for part in parts), inertia=inertia_about_y_axis(parts),
            kp=self.kp, ki=self.ki, kd=self.kd, wheel_width=self.wheel_width,
            wheel_mass=self.wheel_mass, max_swivel_angle=self.max_swivel_angle,
            swivel_limit=self.swivel_limit, swivel_torque_limit=self.swivel_torque_limit)


def parameters_of(cls: type) -> dict[str, tuple[Any, str]]:
    """Return name -> (default, description) of the ``described`` fields of ``cls``."""
    return {item.name: (item.default, item.metadata['description']) for item in fields(cls)}


PARAMETERS = parameters_of(CarDescription)


@dataclass(frozen=True)
class Part:
    """
    A rigid piece of the robot: its shape, mass and inertia, in base_link at rest.

    Attributes
    ----------
    name : str
    link : str
        The URDF link that carries it.
    mass : float  # [kg]
    com : numpy.ndarray  # [m] centre of mass
    inertia : numpy.ndarray  # [kg m^2] 3x3 about ``com``, base_link axes
    shape : str
        'cylinder' (``size`` = radius, length; ``axis`` its direction) or 'box' (``size`` =
        x, y, z edges).
    size : tuple of float  # [m]
    axis : numpy.ndarray  # [1]

    """

    name: str
    link: str
    mass: float
    com: np.ndarray
    inertia: np.ndarray
    shape: str
    size: tuple[float, ...]
    axis: np.ndarray

    @classmethod
    def rod(cls, name: str, link: str, mass: float, radius: float, start: np.ndarray,
            end: np.ndarray) -> 'Part':
        """Make a solid cylinder from ``start`` to ``end`` [m] of ``radius`` [m]."""
        axis = np.asarray(end, dtype=float) - start
        length = float(np.linalg.norm(axis))
        a = axis / length
        transverse = mass * (3.0 * radius ** 2 + length ** 2) / 12.0
        axial = mass * radius ** 2 / 2.0
        inertia = transverse * (np.eye(3) - np.outer(a, a)) + axial * np.outer(a, a)
        return cls(name, link, float(mass), (np.asarray(start, dtype=float) + end) / 2.0,
                   inertia, 'cylinder', (radius, length), a)

    @classmethod
    def box(cls, name: str, link: str, mass: float, size: np.ndarray,
            centre: np.ndarray) -> 'Part':
        """Make a solid box of edges ``size`` [m] centred at ``centre`` [m], base_link axes."""
        sx, sy, sz = size
        inertia = np.diag([sy ** 2 + sz ** 2, sx ** 2 + sz ** 2, sx ** 2 + sy ** 2]) * mass / 12.0
        return cls(name, link, float(mass), np.asarray(centre, dtype=float), inertia, 'box',
                   tuple(float(s) for s in size), np.array([0.0, 0.0, 1.0]))


def combine(parts: list[Part]) -> tuple[float, np.ndarray, np.ndarray]:
    """Total mass [kg], centre of mass [m] and inertia about it [kg m^2] (parallel axes)."""
    mass = sum(p.mass for p in parts)
    com = sum(p.mass * p.com for p in parts) / mass
    inertia = np.zeros((3, 3))
    for p in parts:
        d = p.com - com
        inertia += p.inertia + p.mass * (float(d @ d) * np.eye(3) - np.outer(d, d))
    return mass, com, inertia


def inertia_about_y_axis(parts: list[Part]) -> float:
    """Return I_yy of ``parts`` about the y axis through base_link [kg m^2]."""
    return float(sum(p.inertia[1, 1] + p.mass * (p.com[0] ** 2 + p.com[2] ** 2)
                     for p in parts))
