"""
The trailing axle's climb by traction (not in the thesis, which lifts only the front).

The swivel lifts the wheels of the leading axle over a step; the trailing axle has no lift of
its own. Once the leading wheels stand on the top face, the trailing wheels meet the riser and
rise only if friction lifts them: the leading wheels pull, the riser pushes back on the
trailing wheels, and friction on the riser carries the trailing axle's load. This module is
the quasi-static side view of that moment, every wheel at the friction limit ``mu``:

* the leading wheels stand on the top face (height ``h``): normal ``N_f`` up, traction
  ``T_f <= mu N_f`` forward;
* the trailing wheels have just left the ground and touch the step: below the wheel radius at
  its edge, the contact normal through the wheel centre at ``beta`` above the horizontal
  (``sin beta = (r - h) / r``); from the radius up on the riser face (``beta = 0``); normal
  ``N``, friction ``F <= mu N`` along the rim, upwards;
* the car is pitched by ``theta`` (``sin theta = h / L``), its centre of mass a fraction ``c``
  of the wheelbase ``L`` ahead of the trailing axle and ``z_c`` above the axle line.

Horizontal balance ``T_f = N (cos beta - mu sin beta)``, vertical ``N_f + N (sin beta + mu cos
beta) = W`` and moments about the trailing contact give, at the friction limit, the smallest
``c`` for which the trailing wheels rise::

    c_min = ((D_f - mu (h - h_c)) / G + r cos beta + z_c sin theta) / (L cos theta)
    G = 1 + mu (sin beta + mu cos beta) / (cos beta - mu sin beta)

with ``D_f = L cos theta - r cos beta`` (trailing contact to leading contact, horizontally)
and ``h_c = min(h, r)`` (height of the trailing contact). Where ``cos beta <= mu sin beta``
the friction cone holds the vertical: a push alone rolls the wheel onto the edge, and any
``c`` will do. Momentum is left out: a car driven at the riser climbs a little higher.
"""

from __future__ import annotations

import math

from swivel_car_model.checks import check_number
from swivel_car_model.params import SwivelCarParams


def _check(name: str, value: float, low: float = 0.0) -> float:
    return check_number(name, value, at_least=low)


def trailing_axle_min_com(p: SwivelCarParams, step_height: float, com_height: float,
                          mu: float) -> float:
    """
    Return the smallest centre-of-mass position at which the trailing axle climbs by traction.

    The position runs along the wheelbase, 0 at the trailing axle, 1 at the leading one; the
    climb is the one the module docstring describes.

    Parameters
    ----------
    p : SwivelCarParams
        The car's model parameters.
    step_height : float
        In ``(0, L)``. # [m]
    com_height : float
        Centre of mass above the axle line. # [m]
    mu : float
        Tyre friction coefficient, the same on the ground, the top face and the riser. # [1]

    Returns
    -------
    float
        0 where a push alone rolls the trailing wheels onto the edge; above 1 where no mass
        layout lets them climb. # [1]

    """
    h = _check('step_height', step_height)
    z_c = _check('com_height', com_height, -math.inf)
    mu = _check('mu', mu)
    L, r = p.wheelbase, p.r
    if not 0.0 < h < L:
        raise ValueError(f'step_height must be in (0, {L:.3f}) m, got {step_height!r}')
    sin_beta = max(0.0, (r - h) / r)
    cos_beta = math.sqrt(1.0 - sin_beta ** 2)
    riser_lift = cos_beta - mu * sin_beta
    if riser_lift <= 0.0:
        return 0.0
    gain = 1.0 + mu * (sin_beta + mu * cos_beta) / riser_lift
    sin_theta = h / L
    cos_theta = math.sqrt(1.0 - sin_theta ** 2)
    leading = L * cos_theta - r * cos_beta  # [m] trailing contact to leading contact
    lever = (leading - mu * (h - min(h, r))) / gain + r * cos_beta + z_c * sin_theta  # [m]
    return max(0.0, lever / (L * cos_theta))


def trailing_axle_limit(p: SwivelCarParams, com_fraction: float, com_height: float,
                        mu: float, resolution: float = 0.001) -> float:
    """
    Return the highest step the trailing axle climbs by traction alone [m].

    With this mass layout, on a ``resolution`` grid (:func:`trailing_axle_min_com`).
    """
    c = _check('com_fraction', com_fraction)
    resolution = _check('resolution', resolution)
    if resolution == 0.0:
        raise ValueError('resolution must be > 0')
    height = resolution
    best = 0.0
    while height < p.wheelbase:
        if trailing_axle_min_com(p, height, com_height, mu) > c:
            break
        best = height
        height += resolution
    return round(best, 9)
