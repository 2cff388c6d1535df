"""
The campaign's sweep checks, as properties (issue 12).

Any bad value in a sweep file (a design, procedure or trials field that is not finite, of the
wrong kind or out of range, anywhere in a swept list) ends in one SweepError naming the field,
before any trial runs; a good sweep plans its trials.
"""

from dataclasses import fields

from bad_values import assert_refusal_names, at_most, NON_FINITE, NOT_NUMERIC
from hypothesis import given, settings, strategies as st
import pytest
from swivel_car_model.description import CarDescription
from swivel_car_planner.core.config import PlannerConfig
from swivel_car_studies.campaign import parse_sweep, plan_trials, SweepError

HEIGHTS = [0.02]
# Description fields that must be > 0 (phi, body_offset and the gains may be <= 0).
DESIGN_POSITIVE = [item.name for item in fields(CarDescription)
                   if isinstance(item.default, float)
                   and item.name not in ('phi', 'body_offset', 'kp', 'ki', 'kd')]
PROCEDURE = [item.name for item in fields(PlannerConfig)]
BAD_NUMBER = NON_FINITE | NOT_NUMERIC | at_most(-1e-9)
# A field's value on its own: not a list, which a sweep file takes for a sweep of its values
# ([1.0] sweeps the good value 1.0).
BAD_VALUE = BAD_NUMBER.filter(lambda value: not isinstance(value, list))
# Checking a design builds the stack's installed configuration: tens of ms an example.
FEW = settings(max_examples=20)


def refused(data: dict) -> SweepError:
    with pytest.raises(SweepError) as error:
        plan_trials(parse_sweep(data))
    return error.value


@FEW
@given(name=st.sampled_from(DESIGN_POSITIVE), bad=BAD_NUMBER, at=st.integers(0, 2))
def test_a_bad_design_value_anywhere_in_its_list_is_refused_naming_it(name, bad, at):
    values = [getattr(CarDescription(), name) * k for k in (1.0, 1.1)]
    values.insert(at, bad)
    assert_refusal_names(refused({'design': {name: values}, 'trials': {'heights': HEIGHTS}}),
                         name)


@FEW
@given(name=st.sampled_from(PROCEDURE), bad=BAD_VALUE)
def test_a_bad_procedure_value_is_refused_naming_it(name, bad):
    assert_refusal_names(refused({'procedure': {name: bad}, 'trials': {'heights': HEIGHTS}}),
                         name)


@given(name=st.sampled_from(['count', 'seed']),
       bad=NON_FINITE | NOT_NUMERIC | st.booleans() | st.floats(-10.0, 10.0))
def test_a_count_or_seed_that_is_not_an_integer_is_refused_naming_it(name, bad):
    with pytest.raises(SweepError) as error:
        parse_sweep({'trials': {'heights': HEIGHTS, name: bad}})
    assert_refusal_names(error.value, f'trials.{name}')


@given(bad=NOT_NUMERIC | st.booleans() | st.just([]))
def test_heights_that_are_not_a_list_of_numbers_are_refused_naming_them(bad):
    with pytest.raises(SweepError) as error:
        parse_sweep({'trials': {'heights': bad if bad == [] else [0.02, bad]}})
    assert_refusal_names(error.value, 'trials.heights')


@FEW
@given(bad=NON_FINITE | at_most(0.0))
def test_a_height_that_is_not_a_step_is_refused_naming_the_request_field(bad):
    assert_refusal_names(refused({'trials': {'heights': [0.02, bad]}}), 'step_height')


@FEW
@given(count=st.integers(1, 3), seed=st.integers(-10**6, 10**6),
       offsets=st.lists(st.floats(-0.05, 0.05), min_size=1, max_size=2, unique=True))
def test_a_good_sweep_plans_every_trial(count, seed, offsets):
    trials = plan_trials(parse_sweep({'design': {'body_offset': offsets},
                                      'trials': {'heights': HEIGHTS, 'count': count,
                                                 'seed': seed}}))
    assert len(trials) == len(offsets) * count
