"""
The controller core and the odometry against the real pybullet sim physics, in lockstep.

All in one process (deterministic: sim time only). The same behaviour through the ROS
executables is in test_system.py.
"""

import math

import numpy as np
import pytest

from swivel_car_control.benchmark import ClosedLoop, routes
from swivel_car_control.core.controller import ControllerConfig
from swivel_car_model.description import CarDescription
from swivel_car_sim.sensor_models import SensorProfile


@pytest.fixture
def loop():
    closed_loop = ClosedLoop(config=ControllerConfig(cmd_vel_timeout=0.5,
                                                     swivel_command_timeout=0.0))
    yield closed_loop
    closed_loop.close()


def drive(loop, seconds, v=None, omega=None):
    """Run ``seconds`` of sim time, sending cmd_vel every period if given."""
    for _ in range(int(round(seconds / 0.01))):
        if v is not None:
            loop.controller.set_cmd_vel(v, omega, loop.sim.time)
        loop.period()
    return loop.sim.state()


def test_straight(loop):
    start = loop.sim.state()
    drive(loop, 1.0, 0.3, 0.0)
    middle = loop.sim.state()
    end = drive(loop, 2.0, 0.3, 0.0)
    assert end.position[0] - middle.position[0] == pytest.approx(0.6, rel=0.02)
    assert abs(end.position[1] - start.position[1]) < 0.01
    assert abs(end.yaw) < 0.01


@pytest.mark.parametrize('v, omega', [(0.3, 0.4), (0.2, -0.6)])
def test_arc(loop, v, omega):
    drive(loop, 2.0, v, omega)
    before = loop.sim.state()
    after = drive(loop, 2.0, v, omega)
    assert after.linear_velocity[0] == pytest.approx(v, rel=0.05)
    assert (after.yaw - before.yaw) / 2.0 == pytest.approx(omega, rel=0.05)


@pytest.mark.parametrize('omega', [0.8, -0.8])
def test_turn_on_the_spot(loop, omega):
    """The tightest turn at the asked yaw rate: base_link stays on a small circle."""
    drive(loop, 2.0, 0.0, omega)
    before = loop.sim.state()
    positions = []
    for _ in range(200):
        positions.append(drive(loop, 0.01, 0.0, omega).position[:2])
    after = loop.sim.state()
    turned = math.remainder(after.yaw - before.yaw, 2 * math.pi)
    assert turned / 2.0 == pytest.approx(omega, rel=0.05)
    radius = 1.0 / loop.controller.steering.max_curvature
    centre = np.mean(positions, axis=0)
    assert np.max(np.linalg.norm(np.array(positions) - centre, axis=1)) < 1.5 * radius


def test_deadman_stops_the_drive_and_holds_the_swivel(loop):
    drive(loop, 2.0, 0.3, 0.5)
    held = loop.sim.state().positions[0]
    end = drive(loop, 2.0)  # no more commands
    assert abs(end.linear_velocity[0]) < 0.01
    assert end.positions[0] == pytest.approx(held, abs=0.02)


def test_non_finite_command_keeps_the_last_safe_state(loop):
    drive(loop, 1.5, 0.3, 0.0)
    for bad in (math.nan, math.inf):
        with pytest.raises(ValueError):
            loop.controller.set_cmd_vel(bad, 0.0, loop.sim.time)
    end = drive(loop, 0.3)
    assert end.linear_velocity[0] == pytest.approx(0.3, rel=0.05)
    assert abs(end.positions[0]) < 0.01


@pytest.mark.parametrize('start, target', [(0.0, 0.5), (0.0, 1.2), (1.2, -1.2)])
def test_swivel_step_response(loop, start, target):
    loop.controller.set_swivel_command(start, 0.0, 0.0, True, loop.sim.time)
    drive(loop, 2.0)
    loop.controller.set_swivel_command(target, 0.0, 0.0, True, loop.sim.time)
    t0 = loop.sim.time
    trace = []
    for _ in range(400):
        state, _ = loop.period()
        trace.append((state.time - t0, state.positions[0]))
    trace = np.array(trace)
    progress = (trace[:, 1] - start) / (target - start)
    overshoot = max(0.0, progress.max() - 1.0)
    outside = np.flatnonzero(np.abs(progress - 1.0) > 0.02)
    settling = trace[outside[-1] + 1, 0]
    print(f'swivel step {start} -> {target} rad: overshoot {100 * overshoot:.1f} %, '
          f'2 % settling time {settling:.2f} s (sim)')
    assert overshoot <= 0.10
    assert outside[-1] + 1 < len(trace), 'did not settle within 4 s of sim time'


ROUTES = list(routes(CarDescription().model_params()))


@pytest.mark.parametrize('name', ROUTES)
def test_odometry_on_standard_routes(name):
    """
    Check the odometry's end-pose error on every standard route, as a share of the distance.

    The offset model within 1.5 % (the sim's wheel slip in tight turns costs it up to ~1 %),
    with the rear-axle yaw rate too (the rear wheels carry 53 % of the weight and slip in a
    turn on the spot: 1.1 %), and the offset model's heading far better than the plain
    tricycle's where the swivel is large. The sweep at standstill moves base_link 11 cm, too
    little to divide by: with the weight forward the rear axle skids sideways as the swivel
    turns, which wheel encoders cannot see (4.8 cm measured). Through the executables:
    test_system_routes.py.
    """
    loop = ClosedLoop()
    try:
        result = loop.drive(name, routes(loop.p)[name])
    finally:
        loop.close()
    print(f'{name}: {result.distance:.3f} m, end error {result.ours[0]:.4f} m')
    if name == 'swivel_sweep_standstill':
        assert result.ours[0] < 0.06
        return
    assert result.distance > 1.0
    assert result.ours[0] / result.distance < 0.015
    assert result.rear[0] / result.distance < 0.015
    if name == 'turn_on_the_spot':
        assert result.ours[1] < 0.3 * result.plain[1]


@pytest.mark.parametrize('name', ['circle_swivel_1.1', 'turn_on_the_spot'])
def test_odometry_holds_with_the_realistic_sensors(name):
    """
    The odometry on quantised encoders, with lost states and late commands (seeded).

    The two routes where the odometry's error is largest with ideal sensors (0.69 % and
    0.63 %): with the realistic profile it must stay within the issue's 1 % of the distance
    (measured 0.67 % and 0.62 %: tick differences are exact over their interval).
    """
    loop = ClosedLoop(sensors=SensorProfile.load('realistic'), seed=0)
    try:
        result = loop.drive(name, routes(loop.p)[name])
    finally:
        loop.close()
    assert result.distance > 1.0
    assert result.ours[0] / result.distance < 0.01
