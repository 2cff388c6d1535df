"""
The model's input checks, as properties (issue 12).

A bad value of any field (not finite, not a number, out of range) is refused with one
ValueError naming the field, and nothing changes; a good one is accepted.
"""

from dataclasses import fields
import math

from bad_values import assert_refusal_names, at_most, NOT_A_FINITE_NUMBER
from hypothesis import given, strategies as st
import pytest
from swivel_car_model.checks import check_finite_number, check_nonempty_string, check_number
from swivel_car_model.description import CarDescription
from swivel_car_model.params import SwivelCarParams

PARAMS_FIELDS = [item.name for item in fields(SwivelCarParams)]
DESCRIPTION_NUMBERS = [item.name for item in fields(CarDescription)
                       if isinstance(item.default, float)]
# Fields that must be > 0 (the others: kp, ki, kd >= 0; phi, body_offset either sign).
SIGNED = ('phi', 'body_offset', 'kp', 'ki', 'kd')


@given(bad=NOT_A_FINITE_NUMBER, name=st.sampled_from(['mass', 'time_step']))
def test_check_finite_number_refuses_naming_the_field(bad, name):
    with pytest.raises(ValueError) as error:
        check_finite_number(name, bad)
    assert_refusal_names(error.value, name)


@given(good=st.integers(-10**6, 10**6) | st.floats(allow_nan=False, allow_infinity=False))
def test_check_finite_number_takes_any_finite_int_or_float(good):
    check_finite_number('mass', good)


@given(bad=NOT_A_FINITE_NUMBER | at_most(0.0) | st.just(10**400),
       bound=st.sampled_from([{'above': 0.0}, {'at_least': 1e-300}]))
def test_check_number_refuses_a_bad_value_in_one_line_naming_the_field(bad, bound):
    with pytest.raises(ValueError) as error:
        check_number('publish_rate', bad, unit='Hz', **bound)
    assert_refusal_names(error.value, 'publish_rate')
    assert 'Hz, got' in str(error.value)


@given(good=st.integers(1, 10**6) | st.floats(min_value=1e-300, allow_nan=False))
def test_check_number_with_allow_inf_takes_inf_and_returns_a_float(good):
    value = check_number('integral_band', good, above=0.0, allow_inf=True)
    assert value == good and type(value) is float


@pytest.mark.parametrize('bad', ['', None, 0, b'base_link', ['base_link']])
def test_check_nonempty_string_refuses_anything_but_a_nonempty_str(bad):
    with pytest.raises(ValueError, match='^base_frame_id must be a non-empty string$'):
        check_nonempty_string('base_frame_id', bad)
    check_nonempty_string('base_frame_id', 'base_link')


@given(name=st.sampled_from(PARAMS_FIELDS), bad=NOT_A_FINITE_NUMBER)
def test_params_refuse_a_field_that_is_not_a_finite_number(name, bad):
    with pytest.raises(ValueError) as error:
        SwivelCarParams(**{name: bad})
    assert_refusal_names(error.value, name)


@given(name=st.sampled_from([n for n in PARAMS_FIELDS if n not in SIGNED]),
       bad=at_most(0.0))
def test_params_refuse_a_size_mass_or_limit_that_is_not_positive(name, bad):
    with pytest.raises(ValueError) as error:
        SwivelCarParams(**{name: bad})
    assert_refusal_names(error.value, name)


@given(name=st.sampled_from(['kp', 'ki', 'kd']),
       bad=st.floats(max_value=-1e-9, allow_infinity=False))
def test_params_refuse_a_negative_gain(name, bad):
    with pytest.raises(ValueError) as error:
        SwivelCarParams(**{name: bad})
    assert_refusal_names(error.value, name)


@given(bad=st.sampled_from([0.0, -0.0]) | st.floats(math.pi / 2, 1e6)
       | st.floats(-1e6, -math.pi / 2))
def test_params_refuse_phi_outside_its_open_range(bad):
    with pytest.raises(ValueError) as error:
        SwivelCarParams(phi=bad)
    assert_refusal_names(error.value, 'phi')


@given(kp=st.floats(0.0, 1e3), ki=st.floats(0.0, 1e3), kd=st.floats(0.0, 1e2),
       phi=st.floats(0.05, 1.5).map(lambda v: v if v > 0.8 else -v),
       mass=st.floats(2.1, 100.0))
def test_params_take_good_values(kp, ki, kd, phi, mass):
    p = SwivelCarParams(kp=kp, ki=ki, kd=kd, phi=phi, mass=mass)
    assert (p.kp, p.ki, p.kd, p.phi, p.mass) == (kp, ki, kd, phi, mass)


@given(name=st.sampled_from(DESCRIPTION_NUMBERS), bad=NOT_A_FINITE_NUMBER)
def test_description_refuses_a_number_field_of_the_wrong_kind_and_keeps_itself(name, bad):
    car = CarDescription()
    with pytest.raises(ValueError) as error:
        car.replace(**{name: bad})
    assert_refusal_names(error.value, name)
    assert car == CarDescription()


@given(name=st.sampled_from([n for n in DESCRIPTION_NUMBERS if n not in SIGNED]),
       bad=at_most(0.0))
def test_description_refuses_a_size_mass_or_limit_that_is_not_positive(name, bad):
    with pytest.raises(ValueError) as error:
        CarDescription.from_values({name: bad})
    assert_refusal_names(error.value, name)


@given(name=st.sampled_from(['front_differential', 'rear_differential']),
       bad=st.text(max_size=8).filter(lambda s: s not in ('open', 'locked'))
       | st.sampled_from([None, 1, True]))
def test_description_refuses_an_unknown_differential(name, bad):
    with pytest.raises(ValueError) as error:
        CarDescription.from_values({name: bad})
    assert_refusal_names(error.value, name)


@given(name=st.text('abcdefghijklmnopqrstuvwxyz_', min_size=1, max_size=12).filter(
    lambda s: s not in {item.name for item in fields(CarDescription)}))
def test_description_refuses_an_unknown_parameter_naming_it(name):
    with pytest.raises(ValueError) as error:
        CarDescription.from_values({name: 1.0})
    assert_refusal_names(error.value, name)


@given(mass=st.integers(1, 50), kp=st.integers(0, 500),
       differential=st.sampled_from(['open', 'locked']))
def test_description_takes_integers_as_floats_and_known_differentials(mass, kp, differential):
    car = CarDescription.from_values({'body_mass': mass, 'kp': kp,
                                      'rear_differential': differential})
    assert car.body_mass == float(mass) and isinstance(car.body_mass, float)
    assert car.kp == float(kp) and isinstance(car.kp, float)
    assert car.rear_differential == differential
