"""
Dynamics of the swivel car: swivel torque, car-like baseline, planar nonholonomic model.

Three models (thesis II.C, IV.A and II.D), each derived again, one module each; corrections
to the thesis are listed in docs/thesis_reproduction.md.

1. :mod:`.swivel_move`: the steering mechanism with its PID (eqs. 17-26), the swivel torque
   and energy of a move and of climbing a step.
2. :mod:`.car_like`: the car-like robot climbing a step as an offset slider-crank (eqs.
   101-110, Table 4), the baseline.
3. :mod:`.planar_motion`: the planar model with nonholonomic constraints (eqs. 29-44), the
   pose drift of a swivel move and free coasting.

Their public names are available here, ``dynamics.climb_torque_energy(...)``.
"""

from swivel_car_model.dynamics._common import GRAVITY
from swivel_car_model.dynamics.car_like import (CarLikeParams, CrankClimbResult,
                                                simulate_car_like_climb)
from swivel_car_model.dynamics.planar_motion import (PlanarResult, simulate_planar_coast,
                                                     simulate_planar_swivel, swivel_pose_drift)
from swivel_car_model.dynamics.swivel_move import (climb_torque_energy, front_swivel_inertia,
                                                   simulate_swivel_move,
                                                   swivel_generalized_inertia,
                                                   swivel_gravity_torque, SwivelMoveResult)

__all__ = ['CarLikeParams', 'climb_torque_energy', 'CrankClimbResult', 'front_swivel_inertia',
           'GRAVITY', 'PlanarResult', 'simulate_car_like_climb', 'simulate_planar_coast',
           'simulate_planar_swivel', 'simulate_swivel_move', 'swivel_generalized_inertia',
           'swivel_gravity_torque', 'swivel_pose_drift', 'SwivelMoveResult']
