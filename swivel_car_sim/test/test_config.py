import math

from bad_values import assert_refusal_names, at_most, NON_FINITE, NOT_A_FINITE_NUMBER, NOT_NUMERIC
from hypothesis import given, strategies as st
import pytest
from swivel_car_model import description
from swivel_car_model.description import CarDescription

from swivel_car_sim.config import PARAMETERS, SimNodeConfig
from swivel_car_sim.world import StepSpec

GOOD_STEP = {'name': 'step', 'height': 0.05, 'depth': 1.0, 'width': 1.5, 'distance': 0.5,
             'yaw': 0.0, 'friction': 1.0}


def test_defaults_give_the_architecture_timing():
    cfg = SimNodeConfig.from_values({})
    assert cfg.physics.time_step == 0.002
    assert cfg.control_period == 0.01
    assert cfg.steps_per_period == 5
    assert cfg.imu_every == cfg.ground_truth_every == 1
    assert cfg.clock_every == 10  # 10 Hz, as gazebo_ros publishes /clock
    assert not cfg.lockstep
    assert cfg.physics.description == CarDescription()


def test_rates_and_geometry_overrides():
    cfg = SimNodeConfig.from_values({'ground_truth_rate': 20.0, 'imu_rate': 50.0,
                                     'clock_rate': 50.0,
                                     'phi': -0.5, 'body_mass': 10, 'time_step': 0.001,
                                     'rear_differential': 'locked'})
    assert cfg.ground_truth_every == 5 and cfg.imu_every == 2 and cfg.clock_every == 2
    assert cfg.steps_per_period == 10
    assert cfg.physics.description.phi == -0.5
    assert cfg.physics.description.body_mass == 10.0
    assert isinstance(cfg.physics.description.body_mass, float)
    assert cfg.physics.description.rear_differential == 'locked'


@pytest.mark.parametrize('values, message', [
    ({'control_period': 0.005 + 0.001}, 'control_period'),
    ({'control_period': 0.001}, 'control_period'),
    ({'control_period': 1e306}, 'control_period'),
    ({'world_frame_id': ''}, 'world_frame_id'),
    ({'base_frame_id': 3}, 'base_frame_id'),
    ({'imu_rate': 0.0}, 'imu_rate'),
    ({'clock_rate': 30.0}, 'clock_rate'),
    ({'clock_rate': 'fast'}, 'clock_rate'),
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


# --- properties (issue 12): any bad value refused naming it, a good one taken ------------

NUMBERS = [name for name, (default, _) in PARAMETERS.items()
           if isinstance(default, float) and name not in description.PARAMETERS]
FLAGS = [name for name, (default, _) in PARAMETERS.items() if isinstance(default, bool)]


@given(name=st.sampled_from(NUMBERS), bad=NOT_A_FINITE_NUMBER)
def test_property_a_number_parameter_of_the_wrong_kind_is_refused_naming_it(name, bad):
    with pytest.raises(ValueError) as error:
        SimNodeConfig.from_values({name: bad})
    assert_refusal_names(error.value, name)


@given(name=st.sampled_from(['time_step', 'control_period', 'imu_rate', 'ground_truth_rate',
                             'real_time_factor', 'lockstep_timeout',
                             'lockstep_real_time_factor', 'watchdog_timeout',
                             'ground_friction']), bad=st.floats(-1e6, -1e-9))
def test_property_a_negative_rate_period_or_timeout_is_refused_naming_it(name, bad):
    with pytest.raises(ValueError) as error:
        SimNodeConfig.from_values({name: bad})
    assert_refusal_names(error.value, name)


@given(name=st.sampled_from(FLAGS), bad=st.sampled_from([0, 1, 'true', 'maybe', None, 1.0]))
def test_property_a_flag_that_is_not_a_bool_is_refused_naming_it(name, bad):
    with pytest.raises(ValueError) as error:
        SimNodeConfig.from_values({name: bad})
    assert_refusal_names(error.value, name)


@given(bad=st.text(max_size=10).filter(lambda s: s not in ('swivel', 'car_like'))
       | st.sampled_from([None, 1, True]))
def test_property_an_unknown_robot_variant_is_refused_naming_it(bad):
    with pytest.raises(ValueError) as error:
        SimNodeConfig.from_values({'robot_variant': bad})
    assert_refusal_names(error.value, 'robot_variant')


@given(steps=st.integers(1, 10), every=st.integers(1, 10), x=st.floats(-50.0, 50.0),
       factor=st.floats(0.0, 100.0), lockstep=st.booleans())
def test_property_good_values_are_taken(steps, every, x, factor, lockstep):
    rate = 1.0 / (0.002 * steps * every)  # [Hz]
    config = SimNodeConfig.from_values({
        'control_period': 0.002 * steps, 'imu_rate': rate, 'ground_truth_rate': rate,
        'clock_rate': rate, 'initial_x': x, 'real_time_factor': factor, 'lockstep': lockstep})
    assert config.steps_per_period == steps and config.imu_every == every
    assert config.clock_every == every
    assert config.initial_pose[0] == x and config.real_time_factor == factor
    assert config.lockstep is lockstep


@given(name=st.sampled_from(['height', 'depth', 'width', 'distance', 'yaw', 'friction']),
       bad=NON_FINITE | NOT_NUMERIC)
def test_property_a_step_field_of_the_wrong_kind_is_refused_naming_it(name, bad):
    spec = StepSpec(**{**GOOD_STEP, name: bad})
    with pytest.raises(ValueError) as error:
        spec.validate()
    assert_refusal_names(error.value, name)


@given(st.one_of(at_most(0.0).map(lambda v: ('height', v)),
                 st.floats(1.0, 1e9, exclude_min=True).map(lambda v: ('height', v)),
                 at_most(0.0).map(lambda v: ('depth', v)),
                 st.floats(20.0, 1e9, exclude_min=True).map(lambda v: ('width', v)),
                 at_most(-1e-9).map(lambda v: ('distance', v)),
                 st.floats(math.pi / 2, 1e9).map(lambda v: ('yaw', v)),
                 st.floats(10.0, 1e9, exclude_min=True).map(lambda v: ('friction', v))))
def test_property_a_step_field_out_of_range_is_refused_naming_it(bad):
    name, value = bad
    with pytest.raises(ValueError) as error:
        StepSpec(**{**GOOD_STEP, name: value}).validate()
    assert_refusal_names(error.value, name)
