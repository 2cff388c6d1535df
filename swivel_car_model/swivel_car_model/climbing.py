"""
Step-climbing geometry (thesis chapter III).

The approach for phi > 0, the assisting torque and minimum approach angle for phi < 0.

All positions are in the level base_link frame of :mod:`swivel_car_model.kinematics` (same sign
conventions: ``theta2 > 0`` lifts the **left** front wheel, the right one steers). Corrections
to the thesis (listed in docs/thesis_reproduction.md):

* eq. 76 uses ``2 l cos(phi)`` for the wheelbase (it is ``2 l cos(phi/2)``) and an ordinary
  tricycle; the steering wheel of the swivel car touches the ground at the offset ``(a, b)``,
  so the centre of rotation is taken from :func:`planar.curvature_for_swivel`.
* eqs. 77-85 (chords, sine law, ``R_2 = R' + h - v``) approximate the path of the lifted
  wheel's lowest point; here the arc is composed exactly: pose after the swivel move (its
  drift, :func:`dynamics.swivel_pose_drift`), then an arc at constant curvature, and the lowest
  point ``P_L`` carried along.
* eq. 86 prints ``F = tau_D r``; the force at the rim is ``tau_D / r``. Eq. 88 labels both
  components ``F_T``; the one normal to the column is ``F_w sin(phi/2)``. Eq. 91's lever is
  replaced by the exact moment of the force about the (pitched) swivel axis.
* eqs. 92-97 (``P_L`` and ``C_F`` through ``theta3`` solutions) are replaced by the exact
  extreme points of the tilted wheel discs.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np

from swivel_car_model import dynamics, kinematics, planar
from swivel_car_model.params import SwivelCarParams

ArrayLike = kinematics.ArrayLike


def _finite(name: str, value: ArrayLike) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(arr)):
        raise ValueError(f'{name} must be finite, got {value!r}')
    return arr


def _rim_extreme(centre: np.ndarray, axle: np.ndarray, direction: np.ndarray,
                 r: float) -> np.ndarray:
    """Rim point of a disc furthest along ``direction``: ``C + r (d - (d.a) a) / |...|``."""
    along = np.sum(direction * axle, axis=-1, keepdims=True)
    radial = direction - along * axle
    norm = np.linalg.norm(radial, axis=-1, keepdims=True)
    return centre + r * radial / np.where(norm > 0.0, norm, 1.0)


def _front_wheels(p: SwivelCarParams, theta2: np.ndarray):
    """(steering wheel centre, lifted wheel centre, shared shaft direction), each (..., 3)."""
    frames = kinematics.forward_kinematics(p, theta2)
    right, left = frames.o3[..., :3, 3], frames.o3_left[..., :3, 3]
    lifts_left = (theta2 >= 0.0)[..., None]
    return (np.where(lifts_left, right, left), np.where(lifts_left, left, right),
            frames.o3[..., :3, 2])


def lifted_wheel_lowest_point(p: SwivelCarParams, theta2: ArrayLike) -> np.ndarray:
    """Return the lifted wheel's lowest rim point ``P_L``, (..., 3), in level base_link [m]."""
    t2 = np.asarray(theta2, dtype=float)
    _, lifted, axle = _front_wheels(p, t2)
    return _rim_extreme(lifted, axle, np.array([0.0, 0.0, -1.0]), p.r)


def steering_wheel_front_point(p: SwivelCarParams, theta2: ArrayLike) -> np.ndarray:
    """Return the steering wheel's foremost rim point ``C_F``, (..., 3), in level base_link [m]."""
    t2 = np.asarray(theta2, dtype=float)
    steering, _, axle = _front_wheels(p, t2)
    return _rim_extreme(steering, axle, np.array([1.0, 0.0, 0.0]), p.r)


# ----------------------------------------------------------------------------------------------
# phi > 0: approach distance and heading (eqs. 76-85)

@dataclass(frozen=True)
class ApproachPlan:
    """
    How to approach a step so that the lifted wheel lands on its edge at heading ``gamma``.

    The robot starts at base_link = origin with heading ``theta_i`` to the step normal (the
    step face is the line ``X = distance`` of a world frame whose X axis is the normal), turns
    the swivel to ``theta2`` (drifting by ``swivel_pose_drift``), then drives forward on an
    arc of ``radius`` through ``arc_angle`` until its heading to the normal is ``gamma``.
    """

    theta2: float  # [rad] swivel angle held while driving (its sign picks the lifted wheel)
    distance: float  # [m] start base_link to the step face along the normal
    arc_angle: float  # [rad] heading change while driving
    radius: float  # [m] signed turning radius of base_link (positive = left)
    lifted_radius: float  # [m] radius of the path of the lifted wheel's lowest point
    arc_length: float  # [m] distance driven by base_link


def approach_for_step(p: SwivelCarParams, step_height: float, gamma: float, theta_i: float,
                      include_drift: bool = True) -> ApproachPlan:
    """
    Approach distance for a step at incidence ``theta_i`` ending at heading ``gamma``.

    Headings are measured from the step normal, positive counter-clockwise. The turn
    ``gamma - theta_i`` picks the swivel sign: the swivel angle of
    :func:`kinematics.swivel_for_step` (smallest that clears ``step_height``) with the sign
    whose curvature turns that way.

    Raises
    ------
    ValueError
        NaN, a step out of reach, or a turn of zero / more than a half turn.

    """
    for name, value in (('step_height', step_height), ('gamma', gamma), ('theta_i', theta_i)):
        _finite(name, value)
    magnitude = float(kinematics.swivel_for_step(p, step_height))
    turn = gamma - theta_i
    if magnitude == 0.0 or turn == 0.0 or abs(turn) >= math.pi:
        raise ValueError(
            f'need a step > 0 and 0 < |gamma - theta_i| < pi, got step {step_height!r}, '
            f'gamma - theta_i = {turn!r}')
    # curvature_for_swivel is odd in theta2: pick the sign that turns towards gamma
    kappa_positive = planar.curvature_for_swivel(p, magnitude)
    theta2 = magnitude if kappa_positive * turn > 0.0 else -magnitude
    kappa = planar.curvature_for_swivel(p, theta2)
    # Only x, along the step's normal, sets the distance to the edge.
    x, yaw = 0.0, theta_i
    if include_drift:
        dx, dy, dyaw = dynamics.swivel_pose_drift(p, 0.0, theta2)
        x = dx * math.cos(yaw) - dy * math.sin(yaw)
        yaw += dyaw
    arc = gamma - yaw
    if arc * kappa <= 0.0:
        raise ValueError(
            f'the swivel drift already turned past gamma (heading {yaw!r} rad after the swivel '
            f'move); approach with a larger |gamma - theta_i|')
    x_end = x + (math.sin(gamma) - math.sin(yaw)) / kappa
    lowest = lifted_wheel_lowest_point(p, theta2)
    distance = x_end + lowest[0] * math.cos(gamma) - lowest[1] * math.sin(gamma)
    radius = 1.0 / kappa
    return ApproachPlan(theta2=theta2, distance=float(distance), arc_angle=float(arc),
                        radius=radius,
                        lifted_radius=float(math.hypot(lowest[0], radius - lowest[1])),
                        arc_length=float(arc / kappa))


# ----------------------------------------------------------------------------------------------
# phi < 0: induced (assisting) swivel torque (eqs. 86-91)

def induced_swivel_torque(p: SwivelCarParams, drive_torque: ArrayLike,
                          theta2: ArrayLike = 0.0) -> ArrayLike:
    """
    Swivel torque induced by the step pushing back on the wheel that is to be lifted.

    The wheel's drive torque ``tau_D`` pushes it against the step edge with ``F = tau_D / r``;
    the reaction ``-F`` (horizontal, backwards, applied at the wheel centre) has a moment about
    the pitched swivel axis. At ``theta2 = 0`` this is ``h F sin(-phi/2)`` (eqs. 88-89).

    Parameters
    ----------
    p : SwivelCarParams
        The car's model parameters.
    drive_torque : float or array
        Drive torque at the wheel touching the step, >= 0. # [N m]
    theta2 : float or array
        Swivel angle; ``>= 0`` lifts the left wheel (it is the one at the step). # [rad]

    Returns
    -------
    float or array
        Assisting torque: positive helps lift the wheel at the step (phi < 0), negative
        pushes it down (phi > 0). # [N m]

    """
    tau = _finite('drive_torque', drive_torque)
    if np.any(tau < 0.0):
        raise ValueError(f'drive_torque must be >= 0, got {drive_torque!r}')
    t2 = kinematics._check_swivel(p, theta2)
    theta1 = np.asarray(kinematics.lift_angle(p, t2))
    c1, s1 = np.cos(theta1), np.sin(theta1)
    pitch = np.stack([np.stack([c1, np.zeros_like(c1), -s1], -1),
                      np.stack([np.zeros_like(c1), np.ones_like(c1), np.zeros_like(c1)], -1),
                      np.stack([s1, np.zeros_like(c1), c1], -1)], -2)
    axis = pitch @ p.swivel_axis
    _, lifted, _ = _front_wheels(p, t2)
    front_axle = pitch @ p.front_axle
    force = np.stack(np.broadcast_arrays(-tau / p.r, 0.0 * tau, 0.0 * tau), axis=-1)
    moment = np.cross(lifted - front_axle, force)
    sign = np.where(t2 >= 0.0, 1.0, -1.0)  # positive = towards lifting the wheel at the step
    torque = sign * np.sum(axis * moment, axis=-1)
    return float(torque) if torque.ndim == 0 else torque


# ----------------------------------------------------------------------------------------------
# phi < 0: minimum approach angle (eqs. 92-100)

def min_approach_angle(p: SwivelCarParams, theta2: ArrayLike) -> ArrayLike:
    """
    Angle between the step face and the ground line through ``P_L`` and ``C_F`` (eq. 100).

    Approaching the step face at less than this angle lets the steering wheel's front ``C_F``
    reach the face before the lifted wheel's lowest point ``P_L`` is over the edge.

    Returns
    -------
    float or array
        In ``[0, pi/2]``. # [rad]

    """
    t2 = kinematics._check_swivel(p, theta2)
    line = (steering_wheel_front_point(p, t2) - lifted_wheel_lowest_point(p, t2))[..., :2]
    angle = np.arctan2(np.abs(line[..., 0]), np.abs(line[..., 1]))
    return float(angle) if angle.ndim == 0 else angle


def min_approach_angle_for_step(p: SwivelCarParams, step_height: ArrayLike) -> ArrayLike:
    """Return :func:`min_approach_angle` at the smallest swivel angle clearing the step [rad]."""
    return min_approach_angle(p, kinematics.swivel_for_step(p, step_height))
