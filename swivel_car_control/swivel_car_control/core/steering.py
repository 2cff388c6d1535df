"""
Velocity command (v, omega) to swivel angle and drive speed, through the model's inverse.

What "turn on the spot" means for this drive train: one motor drives both axles through open
differentials, so base_link's speed ``v`` is set by the drive and the only other input is the
swivel angle, which fixes the path curvature ``kappa(theta2)`` (``swivel_car_model.planar``).
With v = 0 the car cannot turn (the single ground-contact front wheel rolls freely, nothing
drives a rotation), and the centre of rotation reaches base_link only at theta2 = +-pi/2,
where the curvature is singular. The honest best is the tightest turn the swivel limit allows:
a command whose curvature |omega / v| exceeds ``kappa_max`` is met with the swivel at its limit
and ``v = omega / kappa_max``, keeping the asked yaw rate. The car then turns about a point
``1 / kappa_max`` beside base_link on the rear axle line (0.24 m with the default geometry and
a 1.4 rad swivel limit; the inner rear wheel is at 0.15 m), base_link moving forward on that
small circle.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np
from swivel_car_model import kinematics, planar
from swivel_car_model.checks import check_number
from swivel_car_model.params import SwivelCarParams


def tip_safe_swivel_limit(p: SwivelCarParams, swivel_limit: float, margin: float,
                          samples: int = 2001) -> float:
    """
    Largest swivel limit up to ``swivel_limit`` at which thesis eq. 72 holds with a margin.

    Eq. 72, ``phi/2 + theta1 < pi/2``, with the lift angle ``theta1(theta2)`` from the model,
    must hold with ``tip_over_margin(p, theta1) >= margin`` for every |theta2| up to the limit.

    Raises
    ------
    ValueError
        Bad arguments, or not even theta2 = 0 satisfies the rule.

    """
    check_number('swivel_limit', swivel_limit, above=0.0, unit='rad')
    if swivel_limit > p.max_swivel_angle:
        raise ValueError(f'swivel_limit must be in (0, {p.max_swivel_angle!r}], '
                         f'got {swivel_limit!r}')
    check_number('margin', margin, at_least=0.0, unit='rad')
    angles = np.linspace(0.0, swivel_limit, samples)
    ok = np.ones(samples, dtype=bool)
    for side in (1.0, -1.0):
        theta1 = kinematics.lift_angle(p, side * angles)
        ok &= np.asarray(kinematics.tip_over_margin(p, theta1)) >= margin
    if not ok[0]:
        raise ValueError(f'the tip-over rule fails with margin {margin!r} rad even at theta2 = 0')
    bad = np.flatnonzero(~ok)
    return float(swivel_limit if bad.size == 0 else angles[bad[0] - 1])


def swivel_is_tip_safe(model: planar.TabulatedModel, theta2: float, margin: float) -> bool:
    """
    Tell whether eq. 72 holds with ``margin`` [rad] at swivel angle theta2 [rad].

    By the tabulated lift angle.
    """
    return kinematics.tip_over_margin(model.p, model.lift_angle(theta2)) >= margin


@dataclass(frozen=True)
class SteeringCommand:
    """
    A velocity command resolved for the swivel car.

    ``swivel`` is None when the command is a standstill: the swivel then holds where it is.
    ``tightest`` marks a command beyond the reachable curvature (turn on the spot): its speed
    only serves the yaw rate, so the controller may adapt it to the measured swivel.
    """

    swivel: float | None  # [rad]
    v: float  # [m/s] forward speed of base_link
    omega: float  # [rad/s] yaw rate the car will have once the swivel is there
    tightest: bool = False


class SteeringMap:
    """
    Maps (v, omega) to a swivel angle and a forward speed.

    The swivel angle comes from the parameters' tabulated model (``model``,
    ``swivel_car_model.planar.TabulatedModel``), within 1e-7 rad of the exact inverse.

    Parameters
    ----------
    p : SwivelCarParams
    swivel_limit : float
        Largest |theta2| steering may use (already tip-safe). # [rad]
    max_speed : float
        Largest |v|. # [m/s]

    """

    def __init__(self, p: SwivelCarParams, swivel_limit: float, max_speed: float) -> None:
        check_number('swivel_limit', swivel_limit, above=0.0, unit='rad')
        check_number('max_speed', max_speed, above=0.0, unit='m/s')
        self.p = p
        self.swivel_limit = swivel_limit
        self.max_speed = max_speed
        self.max_curvature = planar.max_curvature(p, swivel_limit)  # [1/m]
        self.model = planar.tabulated_model(p)

    def resolve(self, v: float, omega: float) -> SteeringCommand:
        """Return the swivel angle and speed for a wanted (v [m/s], omega [rad/s])."""
        if not (math.isfinite(v) and math.isfinite(omega)):
            raise ValueError(f'v and omega must be finite, got {v!r}, {omega!r}')
        if v == 0.0 and omega == 0.0:
            return SteeringCommand(None, 0.0, 0.0)
        tightest = abs(omega) > self.max_curvature * abs(v)
        if not tightest:
            curvature = omega / v
        else:
            # Too tight (or on the spot): the tightest turn, at the asked yaw rate.
            direction = -1.0 if v < 0.0 else 1.0
            curvature = math.copysign(self.max_curvature, omega * direction)
            v = direction * abs(omega) / self.max_curvature
        if abs(v) > self.max_speed:
            v = math.copysign(self.max_speed, v)
        swivel = self.model.swivel_for_curvature(curvature, self.swivel_limit)
        return SteeringCommand(swivel, v, curvature * v, tightest)
