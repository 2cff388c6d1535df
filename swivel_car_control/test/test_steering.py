"""Unit tests of the cmd_vel steering map and the tip-over guard."""

import math

from hypothesis import given, strategies as st
import pytest

from swivel_car_control.core.steering import (
    SteeringMap, swivel_is_tip_safe, tip_safe_swivel_limit)
from swivel_car_model import kinematics, planar
from swivel_car_model.params import SwivelCarParams

P = SwivelCarParams()
MAP = SteeringMap(P, swivel_limit=1.4, max_speed=0.5)


def test_straight_and_standstill():
    assert MAP.resolve(0.3, 0.0).swivel == 0.0
    standstill = MAP.resolve(0.0, 0.0)
    assert standstill.swivel is None and standstill.v == 0.0


@given(v=st.floats(0.05, 0.5), curvature_fraction=st.floats(-1.0, 1.0))
def test_reachable_arcs_are_met_exactly(v, curvature_fraction):
    omega = curvature_fraction * MAP.max_curvature * v
    command = MAP.resolve(v, omega)
    assert command.v == pytest.approx(v)
    assert command.omega == pytest.approx(omega, abs=1e-9)
    # The map inverts the tabulated model (within 1e-7 rad of the exact swivel angle), so the
    # exact curvature it gives is the asked one to 1e-6 relative.
    assert planar.curvature_for_swivel(P, command.swivel) * v == pytest.approx(
        omega, rel=1e-6, abs=1e-9)


def test_reverse_arc_steers_the_same_way_as_the_path_curvature():
    forward = MAP.resolve(0.2, 0.3)
    backward = MAP.resolve(-0.2, 0.3)
    assert backward.swivel == pytest.approx(-forward.swivel)
    assert backward.omega == pytest.approx(0.3)


@pytest.mark.parametrize('omega', [0.5, -1.0])
def test_turn_on_the_spot_is_the_tightest_turn_at_the_asked_rate(omega):
    command = MAP.resolve(0.0, omega)
    assert abs(command.swivel) == pytest.approx(1.4)
    assert command.omega == pytest.approx(omega)
    assert command.v == pytest.approx(abs(omega) / MAP.max_curvature)
    # The centre of rotation lies on the rear axle line, about one rear half-track away.
    assert 0.1 < 1.0 / MAP.max_curvature < 0.3


def test_speed_limit_keeps_the_curvature():
    command = MAP.resolve(2.0, 2.0)
    assert command.v == 0.5
    assert command.omega == pytest.approx(0.5)


def test_rejects_non_finite():
    with pytest.raises(ValueError):
        MAP.resolve(math.nan, 0.0)
    with pytest.raises(ValueError):
        MAP.resolve(0.0, -math.inf)


def test_tip_over_guard_follows_eq_72():
    assert tip_safe_swivel_limit(P, 1.4, 0.1) == 1.4
    peak_lift = max(kinematics.lift_angle(P, t) for t in (0.8, 1.0, 1.2, 1.4))
    # Ask for a margin the default car cannot keep at its peak lift: the limit shrinks.
    margin = (math.pi - P.phi) / 2 - 0.5 * peak_lift
    limit = tip_safe_swivel_limit(P, 1.4, margin)
    assert 0.0 < limit < 1.4
    assert swivel_is_tip_safe(MAP.model, limit, margin)
    assert not swivel_is_tip_safe(MAP.model, 1.2, margin)
    assert not swivel_is_tip_safe(MAP.model, -1.2, margin)
    with pytest.raises(ValueError, match='even at theta2 = 0'):
        tip_safe_swivel_limit(P, 1.4, math.pi)
    with pytest.raises(ValueError):
        tip_safe_swivel_limit(P, 2.0, 0.1)
