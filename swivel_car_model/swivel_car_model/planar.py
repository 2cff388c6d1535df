"""
Planar motion of the swivel car: a tricycle with a variable offset steering wheel.

Thesis II.E (eqs. 45-71) models the car seen from above as a tricycle whose single steering
wheel sits at an offset contact point that moves with the swivel angle. The printed equations
are garbled, so this module derives the model again; corrections to the thesis:

* the generalized coordinates are counted as "five" for a list of seven (x, y, theta_r,
  theta_f, psi, a, b);
* eq. 50 misplaces the parentheses: ``l2 = (-sin(phi_car + psi), cos(phi_car + psi))``;
* eq. 60 mixes wheel *rates* and *speeds* (``theta_f_dot h2`` against ``r theta_r_dot h0``)
  and eq. 62 prints ``b b`` for ``b b_dot``; eqs. 63/64 are not the solutions of eq. 60:
  they carry ``sin(phi_car)``, i.e. depend on the world heading, which no body-frame
  relation can, and name ``alpha_car`` what eq. 54 calls ``alpha_com``;
* eq. 65, the rear wheels' no-skid constraint, has the wrong sign on ``x_dot``: it is
  ``-x_dot sin(phi_car) + y_dot cos(phi_car) = 0`` (as eq. 66 writes it for the front);
* eqs. 67/68 are the plain unicycle relations: the steering wheel's constraint and its offset
  never reach the pose; we use that constraint for the yaw rate (below);
* eqs. 69-71 integrate with explicit Euler; we integrate exact arcs with the mean of the
  twists at both ends of the step (second order).

Derivation. ``base_link`` is the middle of the rear axle; it moves with speed ``v`` along its x
axis (the rear wheels do not skid sideways) and turns at ``omega``. The steering wheel touches
the ground at ``(a, b)`` in base_link, rolls in the direction ``delta`` (the steering angle)
and does not skid sideways. Its contact point moves, seen from the ground, with

    c_dot = (v - omega b + a_dot,  omega a + b_dot)     (in base_link axes)

where ``(a_dot, b_dot)`` is the contact point's motion relative to the body as the swivel
turns. No lateral skid: ``c_dot . (-sin delta, cos delta) = 0``, so

    omega (a cos delta + b sin delta) = (v + a_dot) sin delta - b_dot cos delta.

With ``a_dot = b_dot = 0`` this is the steady curvature ``kappa = omega / v =
sin delta / (a cos delta + b sin delta)``: the centre of rotation lies on the rear axle line at
``y = 1 / kappa``, where the steering wheel's axle line crosses it. For an ordinary tricycle
(``b = 0``) it reduces to ``omega = v tan(delta) / a``.

The rear axle speed is ``v = r * mean(rear wheel rates)`` (open differential), corrected for
the body's pitch: the wheel joints measure wheel rotation relative to the body, and the body
pitches about the rear axle by the lift angle ``theta1(theta2)`` as the swivel turns, so the
rolling rate on the ground is the joint rate minus ``d theta1 / dt``.

The contact point jumps from one front wheel to the other as theta2 crosses zero; that jump is
no motion of any wheel, so ``(a_dot, b_dot)`` is always the derivative for the wheel in contact
(taken at |theta2| and mirrored with the car's symmetry).
"""

from __future__ import annotations

import bisect
import functools
import math

import numpy as np

from swivel_car_model import kinematics
from swivel_car_model.params import SwivelCarParams

_DERIVATIVE_STEP = 1e-6  # [rad] finite-difference step for the contact point's derivative
_SINGULAR = 1e-9  # [m] smallest lever |a cos delta + b sin delta| that determines omega
# The curvature is unbounded at theta2 = pi/2 (the centre of rotation reaches base_link), so
# the default range of swivel_for_curvature stops this far short of it.
_SINGULAR_GAP = 1e-3  # [rad]
_TABLE_SIZE = 4001  # samples of the curvature table over the swivel range
# Samples of TabulatedModel's table over [0, max_swivel_angle] (2.6 MB of floats): enough
# for the accuracy its docstring states, which test_planar.py checks.
_FAST_TABLE_SIZE = 8193
_LIMIT_SLACK = 1e-6  # [rad] TabulatedModel's inverse may pass a swivel limit by its error


def _finite(name: str, value: float) -> float:
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f'{name} must be finite, got {value!r}')
    return value


def offset_tricycle_yaw_rate(v: float, a: float, b: float, a_dot: float, b_dot: float,
                             delta: float) -> float:
    """
    Yaw rate of a tricycle whose steering wheel touches the ground at a moving offset point.

    Parameters
    ----------
    v : float
        Speed of base_link (middle of the rear axle) along its x axis. # [m/s]
    a, b : float
        Steering wheel's ground contact in base_link. # [m]
    a_dot, b_dot : float
        Motion of that contact point relative to base_link. # [m/s]
    delta : float
        Rolling direction of the steering wheel in base_link, positive to the left. # [rad]

    Returns
    -------
    float
        Yaw rate omega, positive counter-clockwise seen from above. # [rad/s]

    Raises
    ------
    ValueError
        An input is not finite, or the steering wheel rolls straight towards (or away from)
        the rear axle middle, where its constraint does not fix omega.

    """
    for name, value in (('v', v), ('a', a), ('b', b), ('a_dot', a_dot), ('b_dot', b_dot),
                        ('delta', delta)):
        _finite(name, value)
    return _yaw_rate(v, a, b, a_dot, b_dot, delta)


def _yaw_rate(v: float, a: float, b: float, a_dot: float, b_dot: float, delta: float) -> float:
    """``offset_tricycle_yaw_rate`` on inputs known to be finite."""
    lever = a * math.cos(delta) + b * math.sin(delta)
    if abs(lever) < _SINGULAR:
        raise ValueError(
            f'steering wheel at ({a!r}, {b!r}) rolling at {delta!r} rad passes through '
            'base_link: the yaw rate is not determined')
    return ((v + a_dot) * math.sin(delta) - b_dot * math.cos(delta)) / lever


def _geometry_arrays(p: SwivelCarParams, u: np.ndarray) -> tuple[np.ndarray, ...]:
    """
    Return (a, b, delta, da/dtheta2, db/dtheta2, dtheta1/dtheta2) at swivel angles ``u >= 0``.

    The derivatives are taken for the wheel in contact at ``u``: differences on the positive
    side (where the model's contact point is one wheel's up to and including zero), so no
    difference ever straddles the change of wheel; ``_geometry`` mirrors them to negative
    angles with the car's symmetry (a and theta1 even, b and delta odd in theta2).
    """
    n = len(u)
    lo = np.maximum(u - _DERIVATIVE_STEP, 0.0)
    hi = np.minimum(u + _DERIVATIVE_STEP, p.max_swivel_angle)
    xs, ys = kinematics.contact_point(p, np.concatenate([u, lo, hi]))
    lift = kinematics.lift_angle(p, np.concatenate([lo, hi]))
    delta = kinematics.steering_angle(p, u)
    width = hi - lo
    return (xs[:n], ys[:n], delta, (xs[2 * n:] - xs[n:2 * n]) / width,
            (ys[2 * n:] - ys[n:2 * n]) / width, (lift[n:] - lift[:n]) / width)


def _geometry(p: SwivelCarParams,
              theta2: float) -> tuple[float, float, float, float, float, float]:
    """
    Return (a, b, delta, da/dtheta2, db/dtheta2, dtheta1/dtheta2) at ``theta2``.

    See ``_geometry_arrays``.
    """
    sign = -1.0 if theta2 < 0.0 else 1.0
    a, b, delta, da, db, dlift = (float(column[0]) for column in
                                  _geometry_arrays(p, np.array([abs(theta2)])))
    return a, sign * b, sign * delta, sign * da, db, sign * dlift


def _check_swivel(p: SwivelCarParams, theta2: float) -> float:
    theta2 = _finite('theta2', theta2)
    if abs(theta2) > p.max_swivel_angle:
        raise ValueError(
            f'theta2 must be within +-{p.max_swivel_angle!r} rad, got {theta2!r}')
    return theta2


def body_twist(p: SwivelCarParams, theta2: float, theta2_rate: float,
               rear_wheel_rate: float) -> tuple[float, float]:
    """
    Return the planar twist of base_link from the measured joints.

    Parameters
    ----------
    p : SwivelCarParams
        The car's model parameters.
    theta2 : float
        Swivel angle. # [rad]
    theta2_rate : float
        Swivel rate. # [rad/s]
    rear_wheel_rate : float
        Mean of the two rear wheel joint rates (relative to the body). # [rad/s]

    Returns
    -------
    (v, omega) : tuple of float
        Forward speed of base_link # [m/s] and its yaw rate # [rad/s].

    Raises
    ------
    ValueError
        Non-finite input, theta2 beyond the joint limit, or the singular swivel angle at which
        the steering wheel's axle line passes through base_link.

    """
    theta2 = _check_swivel(p, theta2)
    theta2_rate = _finite('theta2_rate', theta2_rate)
    rear_wheel_rate = _finite('rear_wheel_rate', rear_wheel_rate)
    a, b, delta, da, db, dlift = _geometry(p, theta2)
    v = p.r * (rear_wheel_rate - dlift * theta2_rate)
    omega = offset_tricycle_yaw_rate(v, a, b, da * theta2_rate, db * theta2_rate, delta)
    return v, omega


def curvature_for_swivel(p: SwivelCarParams, theta2: float) -> float:
    """
    Steady path curvature of base_link, omega / v, at a constant swivel angle.

    Returns
    -------
    float
        Curvature, positive turning left. # [1/m]

    """
    theta2 = _check_swivel(p, theta2)
    a, b, delta, _, _, _ = _geometry(p, theta2)
    return offset_tricycle_yaw_rate(1.0, a, b, 0.0, 0.0, delta)


@functools.lru_cache(maxsize=16)
def _curvature_table(p: SwivelCarParams, limit: float) -> tuple[np.ndarray, np.ndarray, bool]:
    """
    Tabulate |curvature| over [0, limit] (strictly increasing) for inverting it fast.

    Also returns whether positive swivel angles turn left (from the geometry, not a guess).
    """
    angles = np.linspace(0.0, limit, _TABLE_SIZE)
    xs, ys = kinematics.contact_point(p, angles)
    delta = np.asarray(kinematics.steering_angle(p, angles))
    lever = xs * np.cos(delta) + ys * np.sin(delta)
    if np.any(np.abs(lever) < _SINGULAR):
        raise ValueError(f'the curvature is unbounded within +-{limit!r} rad')
    curvature = np.sin(delta) / lever
    magnitude = np.abs(curvature)
    if np.any(np.diff(magnitude) <= 0.0):
        raise ValueError('the curvature does not grow monotonically with |theta2| for this '
                         'geometry; swivel_for_curvature needs it to')
    return angles, magnitude, bool(curvature[-1] > 0.0)


def max_curvature(p: SwivelCarParams, swivel_limit: float) -> float:
    """
    Return the largest |curvature| reachable with ``|theta2| <= swivel_limit`` [1/m].

    The curvature grows monotonically with |theta2|, so it is the curvature at the limit.
    """
    swivel_limit = _check_swivel(p, swivel_limit)
    if swivel_limit <= 0.0:
        raise ValueError(f'swivel_limit must be > 0, got {swivel_limit!r}')
    return abs(curvature_for_swivel(p, swivel_limit))


def swivel_for_curvature(p: SwivelCarParams, curvature: float,
                         swivel_limit: float | None = None) -> float:
    """
    Swivel angle that makes base_link follow a path of the given curvature.

    Interpolation in a cached table of the curvature (per parameters and limit), then one
    Newton step on the exact relation: accurate to ~1e-12 rad at the cost of one evaluation,
    fast enough for every control period.

    Parameters
    ----------
    p : SwivelCarParams
        The car's model parameters.
    curvature : float
        Wanted curvature, positive turning left. # [1/m]
    swivel_limit : float, optional
        Largest |theta2| allowed; default ``p.max_swivel_angle``, but at most
        ``pi/2 - 1e-3`` where the curvature is finite. # [rad]

    Returns
    -------
    float
        theta2 # [rad]; the swivel turns right-handed for a right turn (negative curvature).

    Raises
    ------
    ValueError
        Non-finite curvature, or one beyond ``max_curvature(p, swivel_limit)``.

    """
    curvature = _finite('curvature', curvature)
    if swivel_limit is None:
        limit = min(p.max_swivel_angle, math.pi / 2 - _SINGULAR_GAP)
    else:
        limit = float(_check_swivel(p, swivel_limit))
    if curvature == 0.0:
        return 0.0
    angles, magnitudes, positive_turns_left = _curvature_table(p, limit)
    wanted = abs(curvature)
    if wanted > magnitudes[-1]:
        raise ValueError(
            f'curvature {curvature!r} 1/m is beyond the reachable +-{magnitudes[-1]!r} 1/m '
            f'(swivel limit {limit!r} rad)')
    i = int(np.clip(np.searchsorted(magnitudes, wanted), 1, len(angles) - 1))
    slope = (magnitudes[i] - magnitudes[i - 1]) / (angles[i] - angles[i - 1])
    guess = float(angles[i - 1] + (wanted - magnitudes[i - 1]) / slope)
    magnitude = guess + (wanted - abs(curvature_for_swivel(p, guess))) / slope
    magnitude = min(max(magnitude, 0.0), limit)
    return float(magnitude if (curvature > 0.0) == positive_turns_left else -magnitude)


class TabulatedModel:
    """
    The planar model for the control cores: per-call scalars in a few microseconds.

    The exact functions above solve the lift constraint by Newton iterations in numpy on
    every call, a few hundred microseconds each; the controller and the odometry call them
    every control period. This samples the exact geometry (``_geometry_arrays``, derivatives
    included) and the lift angle once, on a uniform grid of |theta2|, and interpolates
    linearly in plain floats. Build one per parameter set with :func:`tabulated_model`.

    Against the exact functions over the whole swivel range, default geometry (bounds
    checked by test_planar.py): contact point within 1e-8 m, lift angle 1e-8 rad, steering
    angle 1e-7 rad, their derivatives 1e-6, so the twist within 3e-6 of |v| + |omega| and
    the curvature within 5e-6 relative where |curvature| > 1e-3 1/m (measured over 12,000
    angles up to |theta2| = 1.55 rad with random rates; the curvature is singular at pi/2),
    and ``swivel_for_curvature`` within 1e-7 rad. The odometry's own error on the benchmark
    routes is 0.04-0.7 % of the distance, more than 100 times that.

    Parameters
    ----------
    p : SwivelCarParams

    """

    def __init__(self, p: SwivelCarParams) -> None:
        self.p = p
        self._limit = p.max_swivel_angle  # [rad]
        grid = np.linspace(0.0, p.max_swivel_angle, _FAST_TABLE_SIZE)
        columns = _geometry_arrays(p, grid)
        self._rows = list(zip(*(column.tolist() for column in columns)))
        self._lift = np.asarray(kinematics.lift_angle(p, grid)).tolist()
        self._scale = (_FAST_TABLE_SIZE - 1) / p.max_swivel_angle  # [1/rad]
        self._last = _FAST_TABLE_SIZE - 2  # index of the last interval
        # |curvature| at the samples short of the singularity, as far as it grows: the
        # table swivel_for_curvature inverts.
        a, b, delta = columns[:3]
        usable = grid <= math.pi / 2 - _SINGULAR_GAP
        curvature = (np.sin(delta) / (a * np.cos(delta) + b * np.sin(delta)))[usable]
        rising = np.diff(np.abs(curvature)) > 0.0
        end = len(curvature) if np.all(rising) else int(np.argmin(rising)) + 1
        self._magnitudes = np.abs(curvature[:end]).tolist()
        self._positive_turns_left = bool(curvature[end - 1] > 0.0)

    def _locate(self, theta2: float) -> tuple[int, float]:
        """Interval index and fraction of |theta2| in it; raises for theta2 out of range."""
        u = abs(theta2)
        if not u <= self._limit:  # NaN too
            raise ValueError(f'theta2 must be finite and within +-{self._limit!r} rad, got '
                             f'{theta2!r}')
        x = u * self._scale
        i = min(int(x), self._last)
        return i, x - i

    def lift_angle(self, theta2: float) -> float:
        """Return ``kinematics.lift_angle`` [rad] for one swivel angle theta2 [rad]."""
        i, f = self._locate(theta2)
        lift = self._lift
        return lift[i] + f * (lift[i + 1] - lift[i])

    def geometry(self, theta2: float) -> tuple[float, float, float, float, float, float]:
        """
        Return (a, b, delta, da/dtheta2, db/dtheta2, dtheta1/dtheta2) at ``theta2``.

        As ``_geometry``. # [m], [m], [rad], [m/rad], [m/rad], [1] from theta2 [rad]
        """
        i, f = self._locate(theta2)
        a0, b0, d0, da0, db0, dl0 = self._rows[i]
        a1, b1, d1, da1, db1, dl1 = self._rows[i + 1]
        a, b, delta = a0 + f * (a1 - a0), b0 + f * (b1 - b0), d0 + f * (d1 - d0)
        da, db, dlift = da0 + f * (da1 - da0), db0 + f * (db1 - db0), dl0 + f * (dl1 - dl0)
        if theta2 < 0.0:
            return a, -b, -delta, -da, db, -dlift
        return a, b, delta, da, db, dlift

    def curvature(self, theta2: float) -> float:
        """Return ``curvature_for_swivel`` [1/m] for one swivel angle theta2 [rad]."""
        a, b, delta, _, _, _ = self.geometry(theta2)
        return _yaw_rate(1.0, a, b, 0.0, 0.0, delta)

    def body_twist(self, theta2: float, theta2_rate: float,
                   rear_wheel_rate: float) -> tuple[float, float]:
        """
        Return ``body_twist``: (v [m/s], omega [rad/s]).

        From theta2 [rad], theta2_rate [rad/s] and the mean rear wheel joint rate [rad/s];
        raises ``ValueError`` as ``body_twist`` does.
        """
        a, b, delta, da, db, dlift = self.geometry(theta2)
        theta2_rate = _finite('theta2_rate', theta2_rate)
        rear_wheel_rate = _finite('rear_wheel_rate', rear_wheel_rate)
        v = self.p.r * (rear_wheel_rate - dlift * theta2_rate)
        omega = _yaw_rate(v, a, b, da * theta2_rate, db * theta2_rate, delta)
        if not (math.isfinite(v) and math.isfinite(omega)):
            raise ValueError(f'the twist from theta2_rate {theta2_rate!r} rad/s and '
                             f'rear_wheel_rate {rear_wheel_rate!r} rad/s overflows')
        return v, omega

    def swivel_for_curvature(self, curvature: float, swivel_limit: float) -> float:
        """
        Return the swivel angle [rad] for a path curvature [1/m], positive turning left.

        As ``swivel_for_curvature(p, curvature, swivel_limit)``.

        Raises
        ------
        ValueError
            Non-finite curvature, or one beyond the curvature at ``swivel_limit`` [rad].

        """
        curvature = _finite('curvature', curvature)
        if curvature == 0.0:
            return 0.0
        wanted = abs(curvature)
        magnitudes = self._magnitudes
        if wanted > magnitudes[-1]:
            raise ValueError(f'curvature {curvature!r} 1/m is beyond the reachable '
                             f'+-{magnitudes[-1]!r} 1/m')
        i = bisect.bisect_left(magnitudes, wanted)  # magnitudes[0] = 0 < wanted: i >= 1
        slope = (magnitudes[i] - magnitudes[i - 1]) * self._scale  # [1/(m rad)]
        guess = (i - 1) / self._scale + (wanted - magnitudes[i - 1]) / slope
        magnitude = guess + (wanted - abs(self.curvature(guess))) / slope
        if magnitude > swivel_limit + _LIMIT_SLACK:
            raise ValueError(f'curvature {curvature!r} 1/m is beyond the reachable one at the '
                             f'swivel limit {swivel_limit!r} rad')
        magnitude = min(max(magnitude, 0.0), swivel_limit)
        return magnitude if (curvature > 0.0) == self._positive_turns_left else -magnitude


@functools.lru_cache(maxsize=8)
def tabulated_model(p: SwivelCarParams) -> TabulatedModel:
    """Return the :class:`TabulatedModel` of ``p``, built once per parameter set (tens of ms)."""
    return TabulatedModel(p)


def wheel_rate_for_speed(p: SwivelCarParams, v: float) -> float:
    """
    Return the drive rate at the wheels for a forward speed of base_link [rad/s].

    The single drive motor turns both axles' differential carriers at the same rate, the mean
    of each axle's wheel rates; the rear carrier rate times r is base_link's speed.
    """
    return _finite('v', v) / p.r


class OffsetTricycleOdometry:
    """
    Pose of base_link in the odometry frame, integrated from the measured joints.

    Each ``update`` computes the body twist from the new measurement (``body_twist``, from
    the parameters' :class:`TabulatedModel`), then moves along the exact arc of the mean of
    the previous and the new twist (second order, exact on circles driven at constant speed).

    Parameters
    ----------
    p : SwivelCarParams

    """

    def __init__(self, p: SwivelCarParams) -> None:
        self._p = p
        self._model = tabulated_model(p)
        self.reset()

    def reset(self) -> None:
        """Pose to zero and forget the last twist."""
        self.x = 0.0  # [m]
        self.y = 0.0  # [m]
        self.yaw = 0.0  # [rad], wrapped to (-pi, pi]
        self.v = 0.0  # [m/s]
        self.omega = 0.0  # [rad/s]
        self._have_twist = False

    def set_pose(self, x: float, y: float, yaw: float) -> None:
        """Set the pose (x [m], y [m], yaw [rad]); the twist is kept."""
        x, y, yaw = _finite('x', x), _finite('y', y), _finite('yaw', yaw)
        self.x, self.y, self.yaw = x, y, _wrap(yaw)

    def update(self, theta2: float, theta2_rate: float, rear_wheel_rate: float,
               dt: float, rear_wheel_rate_difference: float | None = None
               ) -> tuple[float, float]:
        """
        Advance by ``dt`` with a new joint measurement.

        Parameters
        ----------
        theta2, theta2_rate, rear_wheel_rate : float
            As for ``body_twist``. # [rad], [rad/s], [rad/s]
        dt : float
            Time since the previous measurement, >= 0. # [s]
        rear_wheel_rate_difference : float, optional
            Right minus left rear wheel rate. # [rad/s]
            If given, the yaw rate comes from the rear axle, ``r * difference / (2 h)`` (the
            rear wheels roll without skidding on either side of base_link), instead of from
            the steering wheel's constraint; the speed still comes from ``body_twist``.

        Returns
        -------
        (v, omega) : the new twist. # [m/s], [rad/s]

        Raises
        ------
        ValueError
            Bad input (see ``body_twist``) or a negative or non-finite dt; the state is
            unchanged.

        """
        dt = _finite('dt', dt)
        if dt < 0.0:
            raise ValueError(f'dt must be >= 0, got {dt!r}')
        v, omega = self._model.body_twist(theta2, theta2_rate, rear_wheel_rate)
        if rear_wheel_rate_difference is not None:
            omega = self._p.r * _finite('rear_wheel_rate_difference',
                                        rear_wheel_rate_difference) / (2.0 * self._p.h)
        if self._have_twist:
            v_mean, omega_mean = 0.5 * (v + self.v), 0.5 * (omega + self.omega)
        else:
            v_mean, omega_mean = v, omega
        dx, dy, dyaw = arc_step(v_mean, omega_mean, self.yaw, dt)
        self.x += dx
        self.y += dy
        self.yaw = _wrap(self.yaw + dyaw)
        self.v, self.omega, self._have_twist = v, omega, True
        return v, omega


def arc_step(v: float, omega: float, yaw: float, dt: float) -> tuple[float, float, float]:
    """
    Displacement (dx, dy, dyaw) in the fixed frame along the exact arc of a constant twist.

    # [m], [m], [rad] from v [m/s], omega [rad/s], yaw [rad], dt [s]
    """
    dyaw = omega * dt
    if abs(dyaw) < 1e-9:
        # Second-order series of the arc: a straight line turned by half the heading change.
        mid = yaw + 0.5 * dyaw
        return v * dt * math.cos(mid), v * dt * math.sin(mid), dyaw
    radius = v / omega
    return (radius * (math.sin(yaw + dyaw) - math.sin(yaw)),
            -radius * (math.cos(yaw + dyaw) - math.cos(yaw)), dyaw)


def _wrap(angle: float) -> float:
    """Wrap an angle to (-pi, pi] [rad]."""
    wrapped = math.remainder(angle, 2.0 * math.pi)
    return math.pi if wrapped == -math.pi else wrapped
