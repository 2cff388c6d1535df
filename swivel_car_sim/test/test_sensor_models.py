"""The sensor and transport models (swivel_car_sim.sensor_models): pure, seeded, fast."""

import math

import numpy as np
import pytest
from swivel_car_sim.robot_state import RobotState
from swivel_car_sim.sensor_models import (
    AbsoluteEncoder, DelayedCommands, FIGURES, FusedImu, QuadratureEncoder,
    rotation_quaternion, SensorProfile, SensorSuite, shipped_profile, yaw_of)
import yaml

DT = 0.01  # [s] the sim's control period: one sample each
G = 9.81  # [m/s^2] the sim's gravity
LEVEL = np.array([0.0, 0.0, 0.0, 1.0])
NAMES = ('swivel_joint', 'rear_left_wheel_joint', 'rear_right_wheel_joint',
         'front_left_wheel_joint', 'front_right_wheel_joint')


def state(time, positions=(0.0,) * 5, orientation=LEVEL, rate=(0.0, 0.0, 0.0),
          force=(0.0, 0.0, G)):
    return RobotState(time=time, joint_names=NAMES, positions=np.array(positions, float),
                      velocities=np.zeros(5), efforts=np.zeros(5), position=np.zeros(3),
                      orientation=np.asarray(orientation, float), linear_velocity=np.zeros(3),
                      angular_velocity=np.array(rate, float),
                      linear_acceleration=np.array(force, float))


@pytest.fixture(scope='module')
def realistic():
    return SensorProfile.load('realistic')


def shipped_data():
    return yaml.safe_load(shipped_profile('realistic').read_text())


def test_ideal_has_no_figures_and_no_models():
    profile = SensorProfile.load('ideal')
    assert profile.ideal
    with pytest.raises(ValueError, match='no sensor models'):
        SensorSuite(profile, 0, state(0.0))


def test_realistic_figures_in_si_units_with_their_parts(realistic):
    assert not realistic.ideal
    assert realistic['imu', 'gyro_noise_density'] == pytest.approx(0.014 * math.pi / 180.0)
    assert realistic['imu', 'gyro_bias_instability'] == pytest.approx(
        2.0 * math.pi / 180.0 / 3600.0)
    assert realistic['imu', 'accel_noise_density'] == pytest.approx(175e-6 * 9.80665)
    assert realistic['transport', 'state_latency'] == pytest.approx(0.002)
    assert 'BMI088' in realistic.parts['imu'] and 'AS5048A' in realistic.parts['swivel_encoder']
    assert set(realistic.parts) == set(FIGURES)


def test_a_yaml_path_loads_like_the_shipped_name(tmp_path, realistic):
    path = tmp_path / 'mine.yaml'
    path.write_text(yaml.safe_dump(shipped_data()))
    assert SensorProfile.load(str(path)).figures == realistic.figures


@pytest.mark.parametrize('section, figure, value, message', [
    ('imu', 'gyro_noise_density', None, 'imu.gyro_noise_density is missing'),
    ('transport', 'jitter', -1.0, 'transport.jitter must be >= 0'),
    ('wheel_encoder', 'gear_ratio', 0.0, 'wheel_encoder.gear_ratio must be > 0'),
    ('imu', 'accel_bias', 'high', 'imu.accel_bias must be a finite number'),
    ('imu', 'accel_bias', float('nan'), 'imu.accel_bias must be a finite number'),
    ('transport', 'drop_rate', 1.0, 'transport.drop_rate must be < 1'),
    ('imu', 'part', None, 'imu.part is missing'),
])
def test_a_bad_figure_is_refused_with_one_line(tmp_path, section, figure, value, message):
    data = shipped_data()
    if value is None:
        del data[section][figure]
    else:
        data[section][figure] = value
    path = tmp_path / 'bad.yaml'
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(ValueError, match=message) as error:
        SensorProfile.load(str(path))
    assert '\n' not in str(error.value)


@pytest.mark.parametrize('value, message', [
    ('noisy', 'sensor_profile must be one of ideal, realistic or a .yaml file path'),
    ('/nonexistent/profile.yaml', 'cannot read'),
])
def test_an_unknown_profile_is_refused(value, message):
    with pytest.raises(ValueError, match=message) as error:
        SensorProfile.load(value)
    assert '\n' not in str(error.value)


def test_a_missing_section_is_refused(tmp_path):
    data = shipped_data()
    del data['transport']
    path = tmp_path / 'bad.yaml'
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(ValueError, match='transport is missing'):
        SensorProfile.load(str(path))


def test_quadrature_encoder_counts_whole_ticks_and_its_rates_sum_to_the_count():
    encoder = QuadratureEncoder(1920.0, 0.3, 0.0)
    angles = np.cumsum(np.random.default_rng(1).uniform(0.0, 0.2, 500))  # [rad]
    positions = np.array([encoder.position(a) for a in angles])
    # A count lags the angle by less than one tick, plus the power-on phase (< one tick).
    assert np.all(np.abs(positions - angles) < 2.0 * encoder.tick)
    ticks = positions / encoder.tick
    assert np.allclose(ticks, np.round(ticks), atol=1e-9)
    rates = np.diff(positions) / DT
    assert np.sum(rates) * DT == pytest.approx(positions[-1] - positions[0], abs=1e-9)


def test_absolute_encoder_rounds_to_its_resolution():
    encoder = AbsoluteEncoder(14)
    assert encoder.tick == pytest.approx(2.0 * math.pi / 16384)
    for angle in np.linspace(-1.5, 1.5, 1001):
        assert abs(encoder.position(angle) - angle) <= 0.5 * encoder.tick + 1e-12


def test_the_suite_is_seeded_and_follows_sim_time_only(realistic):
    def run(seed, republish):
        suite = SensorSuite(realistic, seed, state(0.0))
        out = []
        for k in range(1, 200):
            s = state(k * DT, positions=(0.3 * k * DT,) + (2.0 * k * DT,) * 4)
            sample = suite.sample(s)
            if republish:
                assert suite.sample(s) is sample  # the same state again: no new draws
            out.append(np.concatenate([sample.positions, sample.velocities,
                                       sample.orientation, [sample.lost]]))
        return np.array(out)

    assert np.array_equal(run(7, False), run(7, True))
    assert not np.array_equal(run(7, False), run(8, False))


def test_wheel_rates_are_tick_differences(realistic):
    suite = SensorSuite(realistic, 3, state(0.0))
    tick = 2.0 * math.pi / 1920.0  # [rad] 64 counts x 30:1
    for k in range(1, 50):
        sample = suite.sample(state(k * DT, positions=(0.0,) + (5.0 * k * DT,) * 4))
        # 5 rad/s turns 0.05 rad = 15.3 ticks per sample: a rate of 15 or 16 ticks.
        assert sample.velocities[1] * DT / tick == pytest.approx(
            round(sample.velocities[1] * DT / tick), abs=1e-6)
        assert abs(sample.velocities[1] - 5.0) <= tick / DT


def yaw_drift_bound(profile, duration):
    """5 sigma of the yaw error after ``duration`` [s] at rest (residual bias + ARW + wander)."""
    density = profile['imu', 'gyro_noise_density']
    residual = density / math.sqrt(profile['imu', 'calibration_time'])  # [rad/s] 1 sigma
    sigma = math.sqrt((residual * duration) ** 2 + density ** 2 * duration
                      + (profile['imu', 'gyro_bias_instability'] * duration) ** 2)
    return 5.0 * sigma


def test_imu_yaw_drifts_within_the_datasheet_figures_while_tilt_follows_gravity(realistic):
    duration = 60.0  # [s] at rest
    accel_bias = realistic['imu', 'accel_bias']
    drifts = []
    for seed in range(8):
        imu = FusedImu(realistic, np.random.default_rng(seed), LEVEL)
        for k in range(int(duration / DT)):
            orientation, _, _ = imu.update(LEVEL, np.zeros(3), np.array([0.0, 0.0, G]), DT)
        drifts.append(yaw_of(orientation))
        x, y, z, w = orientation
        tilt = 2.0 * math.asin(math.hypot(x, y))
        # Gravity holds the tilt at the accelerometer's offset's angle (two axes), plus noise.
        assert tilt < math.atan2(math.sqrt(2.0) * accel_bias, G) + 0.002
    drifts = np.abs(drifts)
    assert np.all(drifts < yaw_drift_bound(realistic, duration))
    # It does drift: the residual bias alone is ~0.02 rad a minute (1 sigma).
    assert np.max(drifts) > 0.002


def test_the_fusion_corrects_a_wrong_tilt_at_its_gain(realistic):
    imu = FusedImu(realistic, np.random.default_rng(0), LEVEL)
    imu.orientation = rotation_quaternion(np.array([0.0, 0.2, 0.0]))  # 0.2 rad off in pitch
    for _ in range(int(5.0 / DT)):  # 5 time constants of 1 / fusion_gain
        orientation, _, _ = imu.update(LEVEL, np.zeros(3), np.array([0.0, 0.0, G]), DT)
    tilt = 2.0 * math.asin(math.hypot(orientation[0], orientation[1]))
    bias_tilt = math.atan2(math.sqrt(2.0) * realistic['imu', 'accel_bias'], G)
    assert tilt < 0.2 * math.exp(-5.0) + bias_tilt + 0.002


def test_the_imu_follows_a_turn_and_reports_relative_to_power_on(realistic):
    start = rotation_quaternion(np.array([0.0, 0.0, 1.0]))  # heading 1 rad at power on
    imu = FusedImu(realistic, np.random.default_rng(2), start)
    assert yaw_of(imu.orientation) == pytest.approx(0.0, abs=1e-12)
    rate = 0.5  # [rad/s]
    for k in range(1, 201):  # 2 s of turning
        truth = rotation_quaternion(np.array([0.0, 0.0, 1.0 + rate * k * DT]))
        orientation, gyro, _ = imu.update(truth, np.array([0.0, 0.0, rate]),
                                          np.array([0.0, 0.0, G]), DT)
    assert yaw_of(orientation) == pytest.approx(1.0, abs=yaw_drift_bound(realistic, 2.0))
    assert gyro[2] == pytest.approx(rate, abs=0.01)  # noise 5 sigma 0.012 rad/s at 100 Hz


def test_transport_loses_its_rate_and_delays_within_its_figures(realistic):
    suite = SensorSuite(realistic, 5, state(0.0))
    n = 100_000
    lost = sum(suite.transport.lost() for _ in range(n))
    p = realistic['transport', 'drop_rate']
    assert abs(lost - n * p) < 5.0 * math.sqrt(n * p * (1.0 - p))  # binomial, 5 sigma
    latency = realistic['transport', 'state_latency'] + realistic['transport', 'command_latency']
    delays = [suite.transport.command_delay() for _ in range(1000)]
    assert latency <= min(delays) and max(delays) <= latency + 2.0 * realistic[
        'transport', 'jitter']


def test_delayed_commands_keep_their_order_at_whole_steps():
    queue = DelayedCommands(0.002)
    queue.push(10, 0.0049, (1.0, 0.0))  # 2.45 steps: step 12
    queue.push(11, 0.0001, (2.0, 0.0))  # would be step 11: not before the first
    assert queue.next_step() == 12
    assert queue.due(11) == []
    assert queue.due(12) == [(1.0, 0.0), (2.0, 0.0)]
    assert queue.next_step() is None
    queue.push(20, 0.004, (3.0, 1.0))
    queue.clear()
    assert queue.due(100) == []
