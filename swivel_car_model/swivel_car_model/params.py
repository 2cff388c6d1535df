"""
The swivel car's geometry, masses and swivel PID gains: one validated parameter object.

Defaults are thesis Table 2 (with r in centimetres: Table 2 prints "7.5 m").

Frames used by the whole stack (REP-103): ``base_link`` sits at the middle of the rear axle, at
wheel-centre height, x forward towards the front axle, y left, z up. With the swivel joint at
zero the car is symmetric: both T columns rise at ``phi / 2`` from the horizontal and meet at the
apex (the central body), the front axle lies ``wheelbase`` ahead, each axle carries its wheels at
``y = +-h``. The swivel joint turns the front T about the front column's axis.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
import math

import numpy as np

from swivel_car_model.checks import check_finite_number


@dataclass(frozen=True)
class SwivelCarParams:
    """
    Geometry, inertia and swivel gains of a swivel car.

    Parameters
    ----------
    l : float
        Length of each T column, rear axle (or front axle) centre to the apex. # [m]
    h : float
        Half-length of each wheel shaft: wheel centre plane to the column. # [m]
    phi : float
        Angle between the T columns as the thesis defines it: each column rises at phi / 2
        from the horizontal. Negative phi puts the apex below the axles. # [rad]
    r : float
        Wheel radius. # [m]
    mass : float
        Total mass of the robot. # [kg]
    inertia : float
        Moment of inertia about the rear axle (thesis I_s). # [kg m^2]
    kp, ki, kd : float
        Swivel PID gains (thesis eq. 26). # [N m/rad], [N m/(rad s)], [N m s/rad]
    wheel_width : float
        Width of each wheel's tread. # [m]
    wheel_mass : float
        Mass of each wheel, part of ``mass``. # [kg]
    max_swivel_angle : float
        Mechanical limit of the swivel joint, symmetric. # [rad]
    swivel_limit : float
        Largest |swivel angle| the stack commands (controller set point, planner command),
        at most ``max_swivel_angle``; the controller lowers it further if the tip-over rule
        needs it. # [rad]
    swivel_torque_limit : float
        Peak torque of the swivel actuator. # [N m]

    Raises
    ------
    ValueError
        A field is not finite or not physical; the message names the field.

    """

    l: float = 0.25  # [m]
    h: float = 0.15  # [m]
    phi: float = math.pi / 3  # [rad]
    r: float = 0.075  # [m]
    mass: float = 21.0  # [kg]
    inertia: float = 0.84  # [kg m^2]
    kp: float = 19.0  # [N m/rad]
    ki: float = 11.45  # [N m/(rad s)]
    kd: float = 5.5  # [N m s/rad]
    wheel_width: float = 0.03  # [m]
    wheel_mass: float = 0.5  # [kg]
    max_swivel_angle: float = math.pi / 2  # [rad]
    swivel_limit: float = 1.4  # [rad]
    swivel_torque_limit: float = 30.0  # [N m]

    def __post_init__(self) -> None:
        for field in fields(self):
            value = getattr(self, field.name)
            check_finite_number(field.name, value)
        for name in ('l', 'h', 'r', 'mass', 'inertia', 'wheel_width', 'wheel_mass',
                     'swivel_torque_limit'):
            if getattr(self, name) <= 0.0:
                raise ValueError(f'{name} must be > 0, got {getattr(self, name)!r}')
        for name in ('kp', 'ki', 'kd'):
            if getattr(self, name) < 0.0:
                raise ValueError(f'{name} must be >= 0, got {getattr(self, name)!r}')
        if not 0.0 < abs(self.phi) < math.pi / 2:
            raise ValueError(f'phi must satisfy 0 < |phi| < pi/2, got {self.phi!r}')
        if not 0.0 < self.max_swivel_angle <= math.pi / 2:
            raise ValueError(
                f'max_swivel_angle must be in (0, pi/2], got {self.max_swivel_angle!r}')
        if not 0.0 < self.swivel_limit <= self.max_swivel_angle:
            raise ValueError(f'swivel_limit must be in (0, max_swivel_angle '
                             f'{self.max_swivel_angle!r}], got {self.swivel_limit!r}')
        if 4.0 * self.wheel_mass >= self.mass:
            raise ValueError(
                f'wheel_mass must be below mass / 4, got {self.wheel_mass!r} of {self.mass!r}')
        if self.wheel_width >= self.h:
            raise ValueError(f'wheel_width must be below h, got {self.wheel_width!r}')
        if self.r >= self.wheelbase:
            raise ValueError(f'r must be below the wheelbase, got {self.r!r}')

    @property
    def wheelbase(self) -> float:
        """Rear axle to front axle at zero swivel, ``2 l cos(phi/2)`` [m]."""
        return 2.0 * self.l * math.cos(self.phi / 2.0)

    @property
    def apex(self) -> np.ndarray:
        """Apex (central body, where the columns meet) in base_link at rest [m]."""
        return np.array([self.l * math.cos(self.phi / 2.0), 0.0,
                         self.l * math.sin(self.phi / 2.0)])

    @property
    def front_axle(self) -> np.ndarray:
        """Front axle centre in base_link at rest [m]."""
        return np.array([self.wheelbase, 0.0, 0.0])

    @property
    def swivel_axis(self) -> np.ndarray:
        """
        Return the unit vector of the swivel joint's axis in base_link at rest [1].

        Along the front column from the apex to the front axle. Positive swivel angles turn
        right-handed about it.
        """
        return np.array([math.cos(self.phi / 2.0), 0.0, -math.sin(self.phi / 2.0)])
