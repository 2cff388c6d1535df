"""Unit tests of the slew limiter and the steering-error speed scale."""

import math

from hypothesis import given, strategies as st
import pytest

from swivel_car_control.core.limits import SlewLimiter, steering_speed_scale


def test_slew_limiter_limits_value_and_rate():
    limiter = SlewLimiter(max_value=1.0, max_rate=2.0)
    assert limiter.step(5.0, 0.1) == pytest.approx(0.2)
    for _ in range(10):
        limiter.step(5.0, 0.1)
    assert limiter.value == 1.0
    assert limiter.step(-1.0, 0.1) == pytest.approx(0.8)
    assert limiter.step(-1.0, 0.1, max_rate=0.5) == pytest.approx(0.75)
    limiter.reset(-3.0)
    assert limiter.value == -1.0


@given(targets=st.lists(st.floats(-10, 10), min_size=1, max_size=30),
       dt=st.floats(0.0, 0.1))
def test_slew_limiter_never_exceeds_its_limits(targets, dt):
    limiter = SlewLimiter(max_value=1.5, max_rate=3.0)
    previous = limiter.value
    for target in targets:
        value = limiter.step(target, dt)
        assert abs(value) <= 1.5
        assert abs(value - previous) <= 3.0 * dt + 1e-12
        previous = value


def test_slew_limiter_rejects_bad_input():
    with pytest.raises(ValueError):
        SlewLimiter(0.0, 1.0)
    with pytest.raises(ValueError):
        SlewLimiter(1.0, math.nan)
    limiter = SlewLimiter(1.0, 1.0)
    with pytest.raises(ValueError):
        limiter.step(math.nan, 0.1)
    with pytest.raises(ValueError):
        limiter.step(0.5, -0.1)
    assert limiter.value == 0.0
    assert SlewLimiter(math.inf, math.inf).step(7.0, 0.01) == 7.0
    assert SlewLimiter(math.inf, math.inf).step(7.0, 0.0) == 0.0


def test_speed_scale():
    assert steering_speed_scale(0.1, 0.2, 0.8) == 1.0
    assert steering_speed_scale(-0.5, 0.2, 0.8) == pytest.approx(math.cos(0.5))
    assert steering_speed_scale(0.9, 0.2, 0.8) == 0.0
