"""
Kinematics of the swivel car: lift constraint, steering, contact point, step clearance.

Frames (REP-103). All positions are in the *level* ``base_link`` frame: origin at the middle of
the rear axle at wheel-centre height, x forward, y left, z up, not pitched with the body. The
rear axle is the pivot of the lift, so the rear T + central body pitch nose-up by the lift angle
``theta1`` about the rear axle (the y axis) while the origin stays put; the ground is the plane
``z = -r``.

Sign conventions (the sim and the controller rely on them):

* ``theta2 > 0`` (right-handed about ``params.swivel_axis``, the front column from the apex down
  to the front axle) pushes the **right** front wheel into the ground: it stays in contact and is
  the *steering wheel*; the **left** front wheel lifts. ``theta2 < 0`` mirrors this.
* ``theta1`` is even in ``theta2`` and, for practical geometry, ``>= 0`` (nose up). It can
  turn slightly negative at large ``|theta2|`` when ``h`` is short and ``r`` large: the tilted
  steering wheel's lowest point rises towards its centre faster than the shaft pushes down.
* The steering angle (heading of the steering wheel's rolling direction, positive = turning left,
  counter-clockwise seen from above) is odd in ``theta2``. For ``phi > 0``, ``theta2 > 0`` steers
  **right** (negative steering); for ``phi < 0`` it steers left. This is the thesis' statement
  after Fig. 21 ("clockwise swivel steers clockwise for phi > 0, counter-clockwise for phi < 0").

Derivation (replaces thesis eqs. 1-16; corrections listed in docs/thesis_reproduction.md).
With ``cx = cos(phi/2)``, ``sx = sin(phi/2)``, ``s = |sin theta2|``, ``c2 = cos theta2`` and
``beta = theta1 - phi/2`` (the swivel axis' angle below the horizontal is ``-beta``):

* front wheel shaft direction before the pitch: ``w = (sx sin theta2, cos theta2,
  cx sin theta2)`` (Rodrigues about the swivel axis); pitched, its vertical component is
  ``a_z = sin(theta2) cos(beta)`` (thesis eq. 4, ``cos gamma``).
* steering wheel centre height: ``2 l cx sin(theta1) - h s cos(beta)``.
* a disc of radius ``r`` whose axis has vertical component ``a_z`` has its lowest rim point
  ``r sqrt(1 - a_z^2)`` below its centre, so ground contact (``z = -r``) gives the lift
  constraint (thesis eq. 7 with ``theta1 -> -theta1``)::

      2 l cx sin(theta1) - h s cos(beta) + r (1 - sqrt(1 - s^2 cos^2 beta)) = 0.

  For ``r = 0`` it is linear in ``(sin theta1, cos theta1)``:
  ``theta1 = atan2(h s cx, 2 l cx - h s sx)``; for ``r > 0`` squaring gives a quartic, so we
  start from the ``r = 0`` root (which is continuous from ``theta1 = 0`` at ``theta2 = 0`` and
  so selects the physical branch) and polish with Newton's method to machine precision.
* steering angle: ``atan2(sin(theta2) sin(beta), cos(theta2))`` (thesis eq. 13 without the
  stray square on ``theta1``).
* lowest point of the lifted wheel above the ground: the two front wheels share the shaft
  direction and sit ``2 h`` apart along it, so the lift constraint gives exactly
  ``2 h |sin theta2| cos(beta)`` (replaces thesis eqs. 14-16).
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass
import functools
import math
from types import SimpleNamespace
from typing import Union

import numpy as np

from swivel_car_model.params import SwivelCarParams

ArrayLike = Union[float, np.ndarray]

_ANGLE_TOL = 1e-12  # [rad] rounding slack on the joint limit
_NEWTON_TOL = 1e-14  # [rad]
_NEWTON_MAX_ITER = 50
_POLISH_TOL = 1e-8  # [rad] a Newton step this small leaves an error of ~1e-16
_RESIDUAL_TOL = 1e-9  # [m] a lift angle whose residual exceeds this is not a contact solution
_TABLE_SIZE = 20001  # samples of the cached steering table over [0, max_swivel_angle]
_LIFT_TABLE_SIZE = 4097  # samples of the cached lift table over |sin theta2| in [0, 1]

# The same formulas serve Python floats (fast scalar calls) and numpy arrays.
_MATH = SimpleNamespace(sin=math.sin, cos=math.cos, sqrt=math.sqrt, atan2=math.atan2)
_NP = SimpleNamespace(sin=np.sin, cos=np.cos, sqrt=np.sqrt, atan2=np.arctan2)


def _max_abs(x: ArrayLike) -> float:
    return abs(x) if isinstance(x, float) else float(np.max(np.abs(x), initial=0.0))


def _check_finite(name: str, value: ArrayLike) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(arr)):
        raise ValueError(f'{name} must be finite, got {value!r}')
    return arr


def _check_swivel(p: SwivelCarParams, theta2: ArrayLike) -> np.ndarray:
    arr = _check_finite('theta2', theta2)
    if np.any(np.abs(arr) > p.max_swivel_angle + _ANGLE_TOL):
        raise ValueError(
            f'theta2 must be within +-max_swivel_angle = {p.max_swivel_angle!r} rad, '
            f'got max |theta2| = {float(np.max(np.abs(arr)))!r}')
    return arr


def _lift_residual(p: SwivelCarParams, theta1, s, xp):
    """Return the lift residual f(theta1, s) [m] and its partials (df/dtheta1, df/ds)."""
    cx, sx = math.cos(p.phi / 2.0), math.sin(p.phi / 2.0)
    c1, s1 = xp.cos(theta1), xp.sin(theta1)
    cb, sb = c1 * cx + s1 * sx, s1 * cx - c1 * sx  # cos, sin of beta = theta1 - phi/2
    q = xp.sqrt(abs(1.0 - s * s * cb * cb))
    q_safe = q + 1e-300
    f = 2.0 * p.l * cx * s1 - p.h * s * cb + p.r * (1.0 - q)
    df_dtheta1 = 2.0 * p.l * cx * c1 + p.h * s * sb - p.r * s * s * cb * sb / q_safe
    df_ds = -p.h * cb + p.r * s * cb * cb / q_safe
    return f, df_dtheta1, df_ds


@functools.lru_cache(maxsize=16)
def _lift_table(p: SwivelCarParams) -> tuple[np.ndarray, np.ndarray]:
    """theta1 sampled over s = |sin theta2| in [0, 1], from the r = 0 closed form + Newton."""
    s = np.linspace(0.0, 1.0, _LIFT_TABLE_SIZE)
    cx, sx = math.cos(p.phi / 2.0), math.sin(p.phi / 2.0)
    theta1 = np.arctan2(p.h * s * cx, 2.0 * p.l * cx - p.h * s * sx)
    return s, _newton_lift(p, s, theta1, _NP)[0]


def _newton_lift(p: SwivelCarParams, s, theta1, xp):
    """Newton on the lift constraint; returns theta1 and the partials of the last iterate."""
    for _ in range(_NEWTON_MAX_ITER):
        f, df, df_ds = _lift_residual(p, theta1, s, xp)
        step = f / df
        theta1 = theta1 - step
        if _max_abs(step) < _NEWTON_TOL:
            break
    if _max_abs(f) > _RESIDUAL_TOL or not np.all(np.isfinite(theta1)):
        raise ValueError(
            f'no physical lift angle for these parameters (contact residual {_max_abs(f)!r} m); '
            'the geometry is not physical over the swivel range')
    return theta1, df, df_ds


def _lift_from_s(p: SwivelCarParams, s, theta1=None, xp=_NP):
    """
    Physical root theta1 of the lift constraint for s = |sin theta2|.

    Starts from ``theta1`` if given, else from the cached table (itself started from the
    ``r = 0`` closed form, which selects the root continuous from theta1(0) = 0), then Newton.
    """
    if theta1 is None:
        theta1 = np.interp(s, *_lift_table(p))
    return _newton_lift(p, s, theta1, xp)[0]


def _steering_from(p: SwivelCarParams, theta1, theta2, xp):
    return xp.atan2(xp.sin(theta2) * xp.sin(theta1 - p.phi / 2.0), xp.cos(theta2))


def _as_output(arr: np.ndarray, like: np.ndarray) -> ArrayLike:
    return float(arr) if like.ndim == 0 else arr


def lift_angle(p: SwivelCarParams, theta2: ArrayLike) -> ArrayLike:
    """
    Lift angle: nose-up pitch of the rear T and central body about the rear axle.

    Parameters
    ----------
    p : SwivelCarParams
        Geometry.
    theta2 : float or array
        Swivel angle, ``|theta2| <= p.max_swivel_angle``. # [rad]

    Returns
    -------
    float or array
        Even in ``theta2``, zero at ``theta2 = 0``, nose up positive. # [rad]

    Raises
    ------
    ValueError
        NaN / inf or out-of-range ``theta2``, or no contact solution (non-physical geometry).

    """
    t2 = _check_swivel(p, theta2)
    return _as_output(_lift_from_s(p, np.abs(np.sin(t2))), t2)


def lift_angle_derivative(p: SwivelCarParams, theta2: ArrayLike) -> ArrayLike:
    """
    Return ``d theta1 / d theta2`` by implicit differentiation of the lift constraint [1].

    Odd in ``theta2``. ``theta1`` grows like ``|theta2|`` from zero, so the derivative jumps
    at ``theta2 = 0``; there the right-hand limit is returned.
    """
    t2 = _check_swivel(p, theta2)
    s = np.abs(np.sin(t2))
    theta1 = _lift_from_s(p, s)
    _, df_dtheta1, df_ds = _lift_residual(p, theta1, s, _NP)
    sign = np.where(t2 < 0.0, -1.0, 1.0)
    return _as_output(-df_ds * sign * np.cos(t2) / df_dtheta1, t2)


def steering_angle(p: SwivelCarParams, theta2: ArrayLike) -> ArrayLike:
    """
    Steering angle of the steering wheel as a function of the swivel angle.

    The heading of the steering wheel's rolling direction (its shaft projected on the ground,
    turned by -90 deg) relative to base_link's x axis: ``atan2(sin theta2 sin(theta1 - phi/2),
    cos theta2)``.

    Returns
    -------
    float or array
        Signed steering angle, positive = turning left (counter-clockwise seen from above),
        in ``[-pi/2, pi/2]``. Odd in ``theta2``; for ``phi > 0`` and ``theta2 > 0`` it is
        negative (turning right). # [rad]

    """
    t2 = _check_swivel(p, theta2)
    theta1 = _lift_from_s(p, np.abs(np.sin(t2)))
    return _as_output(_steering_from(p, theta1, t2, _NP), t2)


@dataclass(frozen=True)
class _SteeringTable:
    theta2: np.ndarray  # [rad] increasing samples in [0, theta2_limit]
    theta1: np.ndarray  # [rad]
    magnitude: np.ndarray  # [rad] |steering|, strictly increasing
    theta2_list: list
    theta1_list: list
    magnitude_list: list
    sign: float  # sign of the steering for theta2 > 0


@functools.lru_cache(maxsize=16)
def _steering_table(p: SwivelCarParams) -> _SteeringTable:
    theta2 = np.linspace(0.0, p.max_swivel_angle, _TABLE_SIZE)
    theta1 = _lift_from_s(p, np.sin(theta2))
    steering = _steering_from(p, theta1, theta2, _NP)
    sign = -1.0 if p.phi > 0.0 else 1.0
    magnitude = sign * steering
    rising = np.diff(magnitude) > 0.0
    end = len(theta2) if np.all(rising) else int(np.argmin(rising)) + 1
    theta2, theta1, magnitude = theta2[:end], theta1[:end], magnitude[:end]
    return _SteeringTable(theta2, theta1, magnitude, theta2.tolist(), theta1.tolist(),
                          magnitude.tolist(), sign)


def max_steering_angle(p: SwivelCarParams) -> float:
    """Return the largest |steering angle| reachable monotonically from ``theta2 = 0`` [rad]."""
    return float(_steering_table(p).magnitude[-1])


def swivel_for_steering(p: SwivelCarParams, steering: ArrayLike) -> ArrayLike:
    """
    Swivel angle giving a wanted steering angle (inverse of :func:`steering_angle`).

    Works for both signs of ``phi``: the sign of the result follows the sign conventions of
    the module (for ``phi > 0`` a left turn needs ``theta2 < 0``). Linear interpolation in a
    cached table (per parameter object) plus Newton steps on the exact kinematics (slope
    by implicit differentiation of the lift constraint); the result inverts
    :func:`steering_angle` to ~1e-12 rad.

    Parameters
    ----------
    p : SwivelCarParams
        The car's model parameters.
    steering : float or array
        Wanted steering angle, positive = left, ``|steering| <= max_steering_angle(p)``. # [rad]

    Returns
    -------
    float or array
        The swivel angle of smallest magnitude with that steering angle. # [rad]

    Raises
    ------
    ValueError
        NaN / inf, or ``|steering|`` beyond the reachable range.

    """
    table = _steering_table(p)
    limit = table.magnitude_list[-1]
    if isinstance(steering, (float, int)) and not isinstance(steering, bool):
        steering = float(steering)
        if not math.isfinite(steering):
            raise ValueError(f'steering must be finite, got {steering!r}')
        magnitude = abs(steering)
        if magnitude > limit + _ANGLE_TOL:
            raise ValueError(f'|steering| must be <= {limit!r} rad, got {steering!r}')
        i = min(max(bisect.bisect_right(table.magnitude_list, magnitude), 1),
                len(table.magnitude_list) - 1)
        m0, m1 = table.magnitude_list[i - 1], table.magnitude_list[i]
        u = (magnitude - m0) / (m1 - m0)
        t2 = table.theta2_list[i - 1] + u * (table.theta2_list[i] - table.theta2_list[i - 1])
        t1 = table.theta1_list[i - 1] + u * (table.theta1_list[i] - table.theta1_list[i - 1])
        t2 = _newton_polish_steering(p, t2, t1, magnitude, table.sign, _MATH)
        t2 = min(t2, p.max_swivel_angle)
        return math.copysign(t2, steering * table.sign) if t2 != 0.0 else 0.0
    arr = _check_finite('steering', steering)
    magnitude = np.abs(arr)
    if np.any(magnitude > limit + _ANGLE_TOL):
        raise ValueError(
            f'|steering| must be <= {limit!r} rad, got max {float(np.max(magnitude))!r}')
    t2 = np.interp(magnitude, table.magnitude, table.theta2)
    t1 = np.interp(magnitude, table.magnitude, table.theta1)
    t2 = np.minimum(_newton_polish_steering(p, t2, t1, magnitude, table.sign, _NP),
                    p.max_swivel_angle)
    return _as_output(np.sign(arr * table.sign) * t2, arr)


def _newton_polish_steering(p, theta2, theta1, magnitude, sign, xp):
    """Exact Newton steps on |steering|(theta2) = magnitude, theta2 >= 0 (at most three)."""
    half = p.phi / 2.0
    for _ in range(3):
        s2, c2 = xp.sin(theta2), xp.cos(theta2)
        theta1, df_dtheta1, df_ds = _newton_lift(p, s2, theta1, xp)
        dtheta1 = -df_ds * c2 / df_dtheta1
        sb, cb = xp.sin(theta1 - half), xp.cos(theta1 - half)
        num = s2 * sb
        slope = (c2 * (c2 * sb + s2 * cb * dtheta1) + num * s2) / (num * num + c2 * c2)
        step = (xp.atan2(num, c2) - sign * magnitude) / slope
        theta2 = theta2 - step
        if _max_abs(step) < _POLISH_TOL:
            break
    return theta2


def contact_point(p: SwivelCarParams, theta2: ArrayLike) -> tuple[ArrayLike, ArrayLike]:
    """
    Ground contact point of the steering wheel (thesis eqs. 8-10, derived directly).

    The lowest point of the tilted steering wheel, ``C - r (e_z - a_z a) / |e_z - a_z a|``
    with ``C`` its centre and ``a`` its shaft direction; its height is ``-r`` by the lift
    constraint, so only ``(x, y)`` is returned.

    Returns
    -------
    (x, y) : floats or arrays
        In the level base_link frame. At ``theta2 = 0``: ``(wheelbase, -h)``; for
        ``theta2 > 0`` the right front wheel, ``y < 0``; mirrored for ``theta2 < 0``. # [m]

    """
    t2 = _check_swivel(p, theta2)
    s = np.abs(np.sin(t2))
    x, y = _contact_xy(p, t2, s, _lift_from_s(p, s))
    return _as_output(x, t2), _as_output(y, t2)


def _contact_xy(p: SwivelCarParams, t2: np.ndarray, s: np.ndarray, theta1: np.ndarray):
    side = np.where(t2 < 0.0, 1.0, -1.0)  # +1: the left wheel touches, -1: the right one
    cx, sx = math.cos(p.phi / 2.0), math.sin(p.phi / 2.0)
    c2 = np.cos(t2)
    beta = theta1 - p.phi / 2.0
    centre_x0 = 2.0 * p.l * cx - p.h * sx * s
    centre_z0 = -p.h * cx * s
    centre_x = centre_x0 * np.cos(theta1) - centre_z0 * np.sin(theta1)
    axle_x = -s * np.sin(beta)
    axle_z = s * np.cos(beta)
    q = np.sqrt(np.abs(1.0 - axle_z * axle_z))
    tilt = np.divide(axle_z, q, out=np.zeros_like(q), where=q > 0.0)
    x = centre_x + p.r * tilt * axle_x
    y = side * (p.h * c2 - p.r * tilt * c2)
    return x, y


def _lowest_height(p: SwivelCarParams, s, theta1):
    return 2.0 * p.h * s * np.cos(theta1 - p.phi / 2.0)


def lifted_wheel_lowest_height(p: SwivelCarParams, theta2: ArrayLike) -> ArrayLike:
    """
    Height of the lowest rim point of the lifted front wheel above the ground.

    ``2 h |sin theta2| cos(theta1 - phi/2)``: the thesis' eqs. 14-16 replaced by the exact
    result (both front wheels share the shaft direction, so their lowest points differ by
    the vertical component of the ``2 h`` shaft).

    Returns
    -------
    float or array
        ``>= 0``; the left wheel's for ``theta2 > 0``, the right one's for ``theta2 < 0``. # [m]

    """
    t2 = _check_swivel(p, theta2)
    s = np.abs(np.sin(t2))
    return _as_output(_lowest_height(p, s, _lift_from_s(p, s)), t2)


@dataclass(frozen=True)
class KinematicState:
    """
    Everything the kinematics gives for a swivel angle, computed in one pass.

    Fields are floats for a scalar ``theta2``, else arrays of its shape.
    """

    theta2: ArrayLike  # [rad] swivel angle
    theta1: ArrayLike  # [rad] lift angle, nose up
    steering: ArrayLike  # [rad] positive = left
    contact_x: ArrayLike  # [m] steering wheel ground contact, level base_link
    contact_y: ArrayLike  # [m]
    lifted_height: ArrayLike  # [m] lowest point of the lifted wheel above the ground


def kinematic_state(p: SwivelCarParams, theta2: ArrayLike) -> KinematicState:
    """Lift, steering, contact point and lifted-wheel clearance for ``theta2`` at once."""
    t2 = _check_swivel(p, theta2)
    s = np.abs(np.sin(t2))
    theta1 = _lift_from_s(p, s)
    x, y = _contact_xy(p, t2, s, theta1)
    return KinematicState(
        theta2=_as_output(t2, t2), theta1=_as_output(theta1, t2),
        steering=_as_output(_steering_from(p, theta1, t2, _NP), t2),
        contact_x=_as_output(x, t2), contact_y=_as_output(y, t2),
        lifted_height=_as_output(_lowest_height(p, s, theta1), t2))


def tip_over_margin(p: SwivelCarParams, theta1: ArrayLike) -> ArrayLike:
    """
    Return thesis eq. 72 as a margin: ``pi/2 - phi/2 - theta1`` [rad].

    The apex (mass point C_m) stays ahead of the rear axle while this is positive.
    """
    scalar = isinstance(theta1, float) and math.isfinite(theta1)  # per-call: skip numpy
    t1 = theta1 if scalar else _check_finite('theta1', theta1)
    margin = math.pi / 2.0 - p.phi / 2.0 - t1
    return margin if scalar else _as_output(margin, t1)


def interference_margin(p: SwivelCarParams, theta1: ArrayLike) -> ArrayLike:
    """
    Return thesis eq. 75 as a margin: ``l_p - h_p`` [m].

    ``l_p = 2 l cos(phi/2) cos(theta1)`` is the ground projection of the body (eq. 73) and
    ``h_p = h |sin(phi/2 - theta1)|`` the backward ground projection of the steering wheel's
    shaft at ``theta2 = pi/2`` (eq. 74 prints ``h sin pi/2 - phi``, which is neither
    dimensionally nor geometrically that projection; derived from the shaft direction). The
    steering wheel stays clear of the rear axle while this is positive.
    """
    t1 = _check_finite('theta1', theta1)
    l_p = 2.0 * p.l * math.cos(p.phi / 2.0) * np.cos(t1)
    h_p = p.h * np.abs(np.sin(p.phi / 2.0 - t1))
    return _as_output(l_p - h_p, t1)


@dataclass(frozen=True)
class _StepTable:
    theta2: np.ndarray  # [rad] increasing, up to the allowed maximum
    height: np.ndarray  # [m] strictly increasing


@functools.lru_cache(maxsize=32)
def _step_table(p: SwivelCarParams, respect_tip_over: bool) -> _StepTable:
    theta2 = np.linspace(0.0, p.max_swivel_angle, _TABLE_SIZE)
    theta1 = _lift_from_s(p, np.sin(theta2))
    height = _lowest_height(p, np.sin(theta2), theta1)
    allowed = np.ones_like(theta2, dtype=bool)
    if respect_tip_over:
        allowed = tip_over_margin(p, theta1) > 0.0
    rising = np.append(np.diff(height) > 0.0, False)
    stop = np.flatnonzero(~(allowed & rising))
    end = int(stop[0]) + 1 if stop.size else len(theta2)
    if not allowed[end - 1]:
        end -= 1
    return _StepTable(theta2[:end], height[:end])


def max_scalable_step(p: SwivelCarParams,
                      respect_tip_over: bool = True) -> tuple[float, float]:
    """
    Highest step the lifted front wheel can clear, and the swivel angle that does it.

    The lowest-point height rises with ``|theta2|`` until it peaks or the joint limit; with
    ``respect_tip_over`` it also stops where eq. 72 would be violated (the apex passing
    behind the rear axle).

    Returns
    -------
    (height [m], theta2 [rad])
        ``theta2 >= 0`` (lifts the left wheel; use ``-theta2`` for the right one).

    """
    table = _step_table(p, bool(respect_tip_over))
    if len(table.theta2) < 2:
        raise ValueError('the geometry cannot lift a wheel without tipping over')
    return float(table.height[-1]), float(table.theta2[-1])


def swivel_for_step(p: SwivelCarParams, step_height: ArrayLike,
                    respect_tip_over: bool = True) -> ArrayLike:
    """
    Smallest swivel angle whose lifted wheel clears ``step_height``.

    Parameters
    ----------
    p : SwivelCarParams
        The car's model parameters.
    step_height : float or array
        Step height above the ground, ``0 <= step_height <= max_scalable_step(p)[0]``. # [m]
    respect_tip_over : bool
        Stop the reachable range where eq. 72 would be violated (see
        :func:`max_scalable_step`).

    Returns
    -------
    float or array
        ``theta2 >= 0`` (lifts the left wheel; use ``-theta2`` for the right one). # [rad]

    Raises
    ------
    ValueError
        NaN / inf, negative, or a step out of reach.

    """
    heights = _check_finite('step_height', step_height)
    if np.any(heights < 0.0):
        raise ValueError(f'step_height must be >= 0, got {step_height!r}')
    table = _step_table(p, bool(respect_tip_over))
    reach = float(table.height[-1])
    if np.any(heights > reach):
        raise ValueError(
            f'step_height {float(np.max(heights))!r} m is out of reach: the maximum scalable '
            f'step is {reach!r} m')
    theta2 = np.interp(heights, table.height, table.theta2)
    slope = np.interp(theta2, table.theta2[1:], np.diff(table.height) / np.diff(table.theta2))
    for _ in range(3):
        error = lifted_wheel_lowest_height(p, theta2) - heights
        theta2 = np.clip(theta2 - error / slope, 0.0, table.theta2[-1])
    return _as_output(theta2, heights)


def dh_transform(theta: ArrayLike, d: ArrayLike, a: ArrayLike, alpha: ArrayLike) -> np.ndarray:
    """
    Return the standard Denavit-Hartenberg link transform ``Rz(theta) Tz(d) Tx(a) Rx(alpha)``.

    Returns an array of shape ``(..., 4, 4)`` broadcast over the inputs.
    """
    theta, d, a, alpha = np.broadcast_arrays(*(np.asarray(v, dtype=float)
                                               for v in (theta, d, a, alpha)))
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    zero, one = np.zeros_like(ct), np.ones_like(ct)
    rows = [[ct, -st * ca, st * sa, a * ct],
            [st, ct * ca, -ct * sa, a * st],
            [zero, sa, ca, d],
            [zero, zero, zero, one]]
    return np.stack([np.stack(row, axis=-1) for row in rows], axis=-2)


# Thesis frame O_0 -> level base_link. Table 1 as printed only gives the apex above the axles
# (phi > 0) if the thesis' y_0 points *down*: x_T = x, y_T = -z, z_T = y (right-handed), and the
# thesis' theta1 is then nose-down, theta1_T = -theta1.
_THESIS_TO_BASE = np.array([[1.0, 0.0, 0.0, 0.0],
                            [0.0, 0.0, 1.0, 0.0],
                            [0.0, -1.0, 0.0, 0.0],
                            [0.0, 0.0, 0.0, 1.0]])


@dataclass(frozen=True)
class DHFrames:
    """
    Frames of the thesis' Table 1 chain in the level base_link frame, each ``(..., 4, 4)``.

    ``o1``: foot of the perpendicular from the rear axle onto the swivel axis (z along the
    swivel axis, towards the front axle). ``o2``: front axle centre. ``o3``: centre of the right
    front wheel, z along its shaft pointing right-ish (the thesis' steering wheel for
    ``theta2 > 0``). ``o3_left``: centre of the left front wheel, same orientation.
    """

    o1: np.ndarray
    o2: np.ndarray
    o3: np.ndarray
    o3_left: np.ndarray


def forward_kinematics(p: SwivelCarParams, theta2: ArrayLike,
                       theta1: ArrayLike | None = None) -> DHFrames:
    """
    Forward kinematics through the DH chain of thesis Table 1.

    Table 1: joint 1 ``(theta_T1 + phi/2 - pi/2, 0, l sin phi, -pi/2)``, joint 2
    ``(theta2, l + l cos phi, 0, -pi/2)``, joint 3 ``(theta3, h, 0, 0)`` with
    ``theta_T1 = -theta1`` (see the frame mapping above) and ``theta3 = 0``.

    Parameters
    ----------
    p : SwivelCarParams
        The car's model parameters.
    theta2 : float or array
        Swivel angle. # [rad]
    theta1 : float or array, optional
        Lift angle (nose up); default: the lift constraint's :func:`lift_angle`. # [rad]

    """
    t2 = _check_swivel(p, theta2)
    t1 = lift_angle(p, t2) if theta1 is None else _check_finite('theta1', theta1)
    t1, t2 = np.broadcast_arrays(np.asarray(t1, dtype=float), t2)
    phi = p.phi
    a1 = dh_transform(-t1 + phi / 2.0 - math.pi / 2.0, 0.0, p.l * math.sin(phi), -math.pi / 2.0)
    a2 = dh_transform(t2, p.l + p.l * math.cos(phi), 0.0, -math.pi / 2.0)
    a3 = dh_transform(0.0, p.h, 0.0, 0.0)
    left = dh_transform(0.0, -p.h, 0.0, 0.0)
    t01 = _THESIS_TO_BASE @ a1
    t02 = t01 @ a2
    return DHFrames(o1=t01, o2=t02, o3=t02 @ a3, o3_left=t02 @ left)
