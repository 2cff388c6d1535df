"""
The drive train of the simulated swivel car: one motor, a differential per axle.

ROS-free and pybullet-free. Front and rear carriers are coupled rigidly. pybullet's gear
constraints couple two joints, not the three bodies of a differential, so ``SwivelCarSim``
asks ``DriveTrain`` for the joint torques every physics step and applies them with
TORQUE_CONTROL:

* the motor is speed controlled with a torque limit: a PI loop on the rear carrier speed
  (mean of the two rear wheel speeds, the motor's shaft through the rear differential),
  ``T_m = sat(K_p e + K_i integral(e))``, the integral frozen while saturated;
* the shaft to the front differential is stiff but not infinitely so (explicit torques in a
  0.002 s step cannot be): a torsional spring-damper between the rear and front carrier angles,
  ``T_f = K_s (theta_r - theta_f) + K_d (omega_r - omega_f)``, so the carrier speeds stay equal
  on average and the wind-up stays small (about 0.06 rad at 10 N m);
* an open differential gives both wheels of its axle half the axle's torque (front ``T_f``,
  rear ``T_m - T_f``), their speeds free to differ; a locked one adds the same kind of
  spring-damper between its two wheel angles, ``T_c = K_w (theta_a - theta_b) + D_w (omega_a
  - omega_b)`` taken from wheel a and given to wheel b, so a wheel that loses its grip cannot
  spin away while the other one stands (the torque goes where the traction is).

The gains follow from the wheel inertia and the time step so that the worst case, an axle with
both wheels in the air, is still well damped; their values are in ``DriveGains``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
import math

from swivel_car_model.description import CarDescription
from swivel_car_model.params import SwivelCarParams


@dataclass(frozen=True)
class DriveGains:
    """
    Gains of the drive train model (see the module docstring).

    Attributes
    ----------
    speed_p : float  # [N m s/rad]
    speed_i : float  # [N m/rad]
    shaft_stiffness : float  # [N m/rad]
    shaft_damping : float  # [N m s/rad]
    lock_stiffness : float  # [N m/rad] between the wheels of a locked axle
    lock_damping : float  # [N m s/rad]

    """

    speed_p: float
    speed_i: float
    shaft_stiffness: float
    shaft_damping: float
    lock_stiffness: float
    lock_damping: float

    @classmethod
    def for_robot(cls, params: SwivelCarParams, time_step: float) -> 'DriveGains':
        """
        Make the drive gains for a robot.

        They keep a carrier with both wheels in the air (inertia 2 I_w) stable and well
        damped, and give the loaded speed loop (the whole car on the rear carrier) a damping
        ratio near 0.7.
        """
        wheel_inertia = params.wheel_mass * params.r ** 2 / 2.0  # [kg m^2] about the axle
        free_carrier = 2.0 * wheel_inertia
        loaded_carrier = params.mass * params.r ** 2 + 4.0 * wheel_inertia
        speed_p = free_carrier / time_step  # dead-beat for the free carrier
        speed_i = (speed_p / (2.0 * 0.7)) ** 2 / loaded_carrier
        stiffness = 0.25 * free_carrier / time_step ** 2
        damping = 2.0 * 0.7 * math.sqrt(stiffness * free_carrier)
        # The two wheels of an axle twist against each other with the reduced inertia
        # I_w / 2 (free in the air, the worst case): the same stiffness per time step.
        relative = wheel_inertia / 2.0
        lock_stiffness = 0.25 * relative / time_step ** 2
        lock_damping = 2.0 * 0.7 * math.sqrt(lock_stiffness * relative)
        return cls(speed_p, speed_i, stiffness, damping, lock_stiffness, lock_damping)


class DriveTrain:
    """
    The motor's speed loop, the shaft and the differentials of one robot (module docstring).

    Parameters
    ----------
    description : CarDescription
        The robot: its differentials, drive torque limit, and the masses the gains follow from.
    time_step : float
        Physics step, the period of ``efforts``. # [s]

    """

    def __init__(self, description: CarDescription, time_step: float) -> None:
        self.gains = DriveGains.for_robot(description.model_params(), time_step)
        g = self.gains
        self._gain_values = (g.speed_p, g.speed_i, g.shaft_stiffness, g.shaft_damping,
                             g.lock_stiffness, g.lock_damping)
        self._rear_locked = description.rear_differential == 'locked'
        self._front_locked = description.front_differential == 'locked'
        self._time_step = time_step  # [s]
        self._torque_limit = description.drive_torque_limit  # [N m]
        self._speed_integral = 0.0  # [rad] of the speed error

    def reset(self) -> None:
        """Clear the speed loop's integral (the robot was put down at rest)."""
        self._speed_integral = 0.0

    def efforts(self, rl: Sequence[float], rr: Sequence[float], fl: Sequence[float],
                fr: Sequence[float], swivel_torque: float, drive_speed: float,
                stopped: bool) -> list[float]:
        """
        Return the joint torques of one physics step and advance the speed loop's integral.

        Parameters
        ----------
        rl, rr, fl, fr : sequence of float
            Rear left, rear right, front left, front right wheel joint state: position [rad],
            velocity [rad/s] first (pybullet's getJointStates entries as they come).
        swivel_torque, drive_speed : float
            The command, within the limits. # [N m], [rad/s] of the wheels
        stopped : bool
            The watchdog has tripped: zero swivel torque, drive speed commanded to 0.

        Returns
        -------
        list of float
            Swivel, rear left, rear right, front left, front right torque. # [N m]

        """
        # Every physics step: plain floats and the constants looked up once, since numpy on
        # four numbers costs more than the physics step itself; the clamp is min/max's
        # comparisons without the calls.
        speed_p, speed_i, stiffness, damping, lock_stiffness, lock_damping = self._gain_values
        dt = self._time_step
        if stopped:
            swivel_torque, drive_speed = 0.0, 0.0
        rear_speed, front_speed = (rl[1] + rr[1]) / 2.0, (fl[1] + fr[1]) / 2.0
        error = drive_speed - rear_speed
        limit = self._torque_limit
        unsaturated = speed_p * error + speed_i * (self._speed_integral + error * dt)
        motor = unsaturated if unsaturated > -limit else -limit
        motor = motor if motor < limit else limit
        if motor == unsaturated:
            self._speed_integral += error * dt
        front = (stiffness * ((rl[0] + rr[0]) - (fl[0] + fr[0])) / 2.0
                 + damping * (rear_speed - front_speed))
        rear = motor - front
        rear_lock = (lock_stiffness * (rl[0] - rr[0]) + lock_damping * (rl[1] - rr[1])
                     if self._rear_locked else 0.0)
        front_lock = (lock_stiffness * (fl[0] - fr[0]) + lock_damping * (fl[1] - fr[1])
                      if self._front_locked else 0.0)
        return [swivel_torque, rear / 2.0 - rear_lock, rear / 2.0 + rear_lock,
                front / 2.0 - front_lock, front / 2.0 + front_lock]
