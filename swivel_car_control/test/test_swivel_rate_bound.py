"""The swivel's glitch bound against the fastest the real joint turns, in the sim."""

import pytest
from swivel_car_control.core.joint_states import check_swivel_reading, MAX_SWIVEL_RATE
from swivel_car_sim.config import SimParameters
from swivel_car_sim.physics import SwivelCarSim

# [1] physics steps in a control period, as sim_node runs them
STEPS_PER_PERIOD = round(SimParameters().control_period / SimParameters().time_step)


@pytest.fixture(scope='module')
def sim():
    sim = SwivelCarSim()
    yield sim
    sim.close()


@pytest.mark.parametrize('direction', [1.0, -1.0])
@pytest.mark.parametrize('drive_speed', [0.0, 15.0])  # [rad/s] standing, or the drive's limit
def test_full_torque_from_stop_to_stop_is_a_reading_the_controller_takes(
        sim, direction, drive_speed):
    """
    Each control period's reading, as pybullet and as an encoder difference would give it.

    The controller once refused these as glitches (then at 30 rad/s) and commanded zero
    torque: a controller starved of CPU holds a saturated command, the swivel is slung from
    stop to stop, and the car dropped the swivel it was holding up.
    """
    torque = sim.description.swivel_torque_limit  # [N m]
    limit = sim.description.max_swivel_angle  # [rad]
    sim.reset()
    sim.set_command(-direction * torque, drive_speed)
    sim.step(100 * STEPS_PER_PERIOD)  # against the first stop
    fastest = 0.0  # [rad/s]
    last = sim.state().positions[0]  # [rad]
    for _ in range(60):  # 0.6 s: to the other stop and on it
        sim.set_command(direction * torque, drive_speed)
        sim.step(STEPS_PER_PERIOD)
        state = sim.state()
        angle, rate = state.positions[0], state.velocities[0]
        differenced = (angle - last) / (STEPS_PER_PERIOD * sim.config.time_step)  # [rad/s]
        last = angle
        for reading in (rate, differenced):
            check_swivel_reading('swivel', ['swivel'], [angle], [reading], limit)
            fastest = max(fastest, abs(reading))
    # With its margin: measured 31-65 rad/s across these cases (65 standing).
    assert fastest < 0.6 * MAX_SWIVEL_RATE
