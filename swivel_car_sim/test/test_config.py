import math

import pytest

from swivel_car_model import description
from swivel_car_model.description import CarDescription

from swivel_car_sim.config import PARAMETERS, SimNodeConfig


def test_defaults_give_the_architecture_timing():
    cfg = SimNodeConfig.from_values({})
    assert cfg.physics.time_step == 0.002
    assert cfg.control_period == 0.01
    assert cfg.steps_per_period == 5
    assert cfg.imu_every == cfg.ground_truth_every == 1
    assert not cfg.lockstep
    assert cfg.physics.description == CarDescription()


def test_rates_and_geometry_overrides():
    cfg = SimNodeConfig.from_values({'ground_truth_rate': 20.0, 'imu_rate': 50.0,
                                     'phi': -0.5, 'body_mass': 10, 'time_step': 0.001,
                                     'rear_differential': 'locked'})
    assert cfg.ground_truth_every == 5 and cfg.imu_every == 2
    assert cfg.steps_per_period == 10
    assert cfg.physics.description.phi == -0.5
    assert cfg.physics.description.body_mass == 10.0
    assert isinstance(cfg.physics.description.body_mass, float)
    assert cfg.physics.description.rear_differential == 'locked'


@pytest.mark.parametrize('values, message', [
    ({'control_period': 0.005 + 0.001}, 'control_period'),
    ({'control_period': 0.001}, 'control_period'),
    ({'imu_rate': 0.0}, 'imu_rate'),
    ({'ground_truth_rate': 70.0}, 'ground_truth_rate'),
    ({'lockstep_timeout': -1.0}, 'lockstep_timeout'),
    ({'lockstep_real_time_factor': -0.5}, 'lockstep_real_time_factor'),
    ({'real_time_factor': math.inf}, 'real_time_factor'),
    ({'lockstep': 1}, 'lockstep'),
    ({'gui': 'yes'}, 'gui'),
    ({'body_collision': 1}, 'body_collision'),
    ({'r': -0.075}, 'r must be > 0'),
    ({'phi': 2.0}, 'phi'),
    ({'robot_variant': 3}, 'robot_variant'),
    ({'wheel_friction': 0.0}, 'wheel_friction'),
    ({'front_differential': 'welded'}, 'front_differential'),
    ({'body_mass': 'heavy'}, 'body_mass')])
def test_bad_values_are_refused_naming_the_parameter(values, message):
    with pytest.raises(ValueError, match=message):
        SimNodeConfig.from_values(values)


def test_installed_yaml_states_every_sim_parameter_with_its_default():
    # The robot's own parameters are stated once, in swivel_car_model.description: the
    # node's YAML does not repeat them.
    from pathlib import Path

    import yaml
    path = Path(__file__).resolve().parents[1] / 'config' / 'sim_node.yaml'
    values = yaml.safe_load(path.read_text())['/**']['sim']['ros__parameters']
    assert set(values) == set(PARAMETERS) - set(description.PARAMETERS)
    for name, value in values.items():
        assert value == pytest.approx(PARAMETERS[name][0]) if isinstance(value, float) \
            else value == PARAMETERS[name][0], name
    SimNodeConfig.from_values(values)
