"""Unit tests of the swivel PID."""

import math

from hypothesis import given, strategies as st
import pytest

from swivel_car_control.core.pid import PidConfig, SwivelPid

CONFIG = PidConfig(kp=19.0, ki=11.45, kd=5.5, max_torque=20.0, max_integral_torque=10.0)


def test_derivative_damps_and_acts_on_the_measurement():
    pid = SwivelPid(CONFIG)
    moving_up = pid.step(0.0, 0.0, 1.0, 0.01)
    assert moving_up.d_term == pytest.approx(-5.5)
    assert moving_up.torque < 0.0
    # A set-point step gives no derivative kick: only the proportional part jumps.
    pid.reset()
    kick = pid.step(0.5, 0.0, 0.0, 0.01)
    assert kick.d_term == 0.0
    assert kick.p_term == pytest.approx(19.0 * 0.5)


def test_integral_accumulates_error():
    pid = SwivelPid(CONFIG)
    for _ in range(100):
        out = pid.step(0.1, 0.0, 0.0, 0.01)
    assert out.i_term == pytest.approx(11.45 * 0.1 * 1.0)
    pid.reset()
    assert pid.step(0.1, 0.0, 0.0, 0.0).i_term == 0.0


def test_output_clamp_and_anti_windup():
    pid = SwivelPid(CONFIG)
    for _ in range(1000):
        out = pid.step(3.0, 0.0, 0.0, 0.01)
        assert abs(out.torque) <= CONFIG.max_torque
    assert out.saturated
    assert out.torque == CONFIG.max_torque
    # Saturated by the P term alone: the integral never wound up.
    assert out.i_term == 0.0
    # Below saturation the integral is held to its own clamp.
    for _ in range(10000):
        out = pid.step(0.2, 0.0, 0.0, 0.01)
    assert out.i_term == pytest.approx(CONFIG.max_integral_torque)


@given(set_point=st.floats(-2, 2), measured=st.floats(-2, 2), rate=st.floats(-10, 10))
def test_torque_always_within_clamp(set_point, measured, rate):
    pid = SwivelPid(CONFIG)
    for _ in range(5):
        out = pid.step(set_point, measured, rate, 0.01)
        assert abs(out.torque) <= CONFIG.max_torque
        assert math.isfinite(out.torque)


def test_closed_loop_on_a_joint_settles_without_overshoot():
    """
    Check a swivel-like joint under the Table 2 gains reaches the set point.

    The joint has inertia, viscous friction and a gravity-like load; the integral removes the
    load's offset.
    """
    pid = SwivelPid(CONFIG)
    inertia, friction, load = 0.05, 0.5, 2.0  # [kg m^2], [N m s/rad], [N m]
    angle = rate = 0.0
    dt = 0.002
    peak = 0.0
    for _ in range(int(20.0 / dt)):
        torque = pid.step(0.5, angle, rate, dt).torque
        rate += (torque - friction * rate - load) / inertia * dt
        angle += rate * dt
        peak = max(peak, angle)
    assert angle == pytest.approx(0.5, abs=1e-3)
    assert peak < 0.55


def test_rejects_bad_input_and_config():
    pid = SwivelPid(CONFIG)
    for args in ((math.nan, 0, 0, 0.01), (0, math.inf, 0, 0.01), (0, 0, 0, -0.01)):
        with pytest.raises(ValueError):
            pid.step(*args)
    with pytest.raises(ValueError, match='kp'):
        PidConfig(kp=-1.0, ki=0.0, kd=0.0, max_torque=1.0, max_integral_torque=0.0)
    with pytest.raises(ValueError, match='max_torque'):
        PidConfig(kp=1.0, ki=0.0, kd=0.0, max_torque=0.0, max_integral_torque=0.0)
    with pytest.raises(ValueError, match='ki'):
        PidConfig(kp=1.0, ki=math.nan, kd=0.0, max_torque=1.0, max_integral_torque=0.0)


def test_integral_band_stops_integration_on_large_errors_while_the_set_point_moves():
    pid = SwivelPid(PidConfig(kp=1.0, ki=10.0, kd=0.0, max_torque=100.0,
                              max_integral_torque=100.0, integral_band=0.05))
    assert pid.step(0.5, 0.0, 0.0, 0.1, set_point_moving=True).i_term == 0.0
    assert pid.step(0.04, 0.0, 0.0, 0.1, set_point_moving=True).i_term == pytest.approx(0.04)
    # Resting, a load that holds the swivel outside the band is integrated away.
    assert pid.step(0.5, 0.0, 0.0, 0.1).i_term == pytest.approx(0.54)
    with pytest.raises(ValueError, match='integral_band'):
        PidConfig(kp=1.0, ki=0.0, kd=0.0, max_torque=1.0, max_integral_torque=0.0,
                  integral_band=0.0)
