import dataclasses

import pytest
from scipy.stats import beta

from swivel_car_model.description import CarDescription

from swivel_car_planner.core.capability import (
    CapabilityTable, description_values, lower_bound)


def table(successes, trials=8, description=None):
    heights = tuple(round(0.02 + 0.01 * i, 2) for i in range(len(successes)))
    return CapabilityTable(heights, (trials,) * len(successes), tuple(successes),
                           description_values(description or CarDescription()))


def test_limit_is_the_top_of_the_unbroken_reliable_run():
    assert table([8, 8, 8, 7, 8, 2]).limit == pytest.approx(0.04)  # 7/8 = 88 % breaks it
    assert table([8, 8, 8, 8, 8, 0]).limit == pytest.approx(0.06)
    assert table([5, 8]).limit == 0.0


def test_with_a_confidence_the_limit_is_where_the_lower_bound_stays_reliable():
    heights = (0.02, 0.03, 0.04, 0.05)
    bounded = CapabilityTable(heights, (40, 40, 40, 40), (40, 38, 37, 40),
                              description_values(CarDescription()), reliable=0.85,
                              confidence=0.9)
    # Clopper-Pearson, one-sided 90 %: 40/40 -> 0.1 ** (1 / 40) = 0.944; 37/40 -> 0.83.
    assert bounded.lower_bounds[0.02] == pytest.approx(0.1 ** (1.0 / 40.0))
    assert 0.85 < bounded.lower_bounds[0.03] < 38 / 40
    assert bounded.lower_bounds[0.04] < 0.85 < 37 / 40
    assert bounded.limit == pytest.approx(0.03)
    # 8 of 8 bound the rate only at 0.75: no statement of 85 % from so few trials.
    assert table([8, 8], description=None).limit == pytest.approx(0.03)
    few = CapabilityTable((0.02,), (8,), (8,), description_values(CarDescription()),
                          reliable=0.85, confidence=0.9)
    assert few.limit == 0.0


@pytest.mark.parametrize('successes, trials', [(1, 1), (1, 8), (7, 8), (8, 8), (37, 40),
                                               (199, 200)])
@pytest.mark.parametrize('confidence', [0.5, 0.9, 0.99])
def test_the_lower_bound_is_the_beta_quantile_of_clopper_pearson(successes, trials, confidence):
    # Two routes to one number (the regularized incomplete beta function's inverse): equal
    # to a few units in the last place, far inside any use of the bound.
    assert lower_bound(successes, trials, confidence) == pytest.approx(
        beta.ppf(1.0 - confidence, successes, trials - successes + 1), rel=1e-12)
    assert lower_bound(0, trials, confidence) == 0.0


def test_the_table_round_trips_through_its_file(tmp_path):
    original = table([8, 8, 4])
    original.save(tmp_path / 'capability.yaml', header='made by a test')
    loaded = CapabilityTable.load(tmp_path / 'capability.yaml')
    assert loaded == original
    bounded = dataclasses.replace(original, reliable=0.85, confidence=0.9)
    bounded.save(tmp_path / 'bounded.yaml')
    assert CapabilityTable.load(tmp_path / 'bounded.yaml') == bounded
    assert (tmp_path / 'capability.yaml').read_text().startswith('# made by a test')


def test_the_table_knows_the_robot_it_was_measured_on():
    assert table([8]).matches(CarDescription())
    assert not table([8]).matches(CarDescription(body_mass=9.0))


@pytest.mark.parametrize('content', ['heights: [0.02]', ': not yaml :', 'heights: [1]\n'
                                     'trials: [2]\nsuccesses: [3]\ndescription: {}'])
def test_a_bad_file_is_refused_naming_it(tmp_path, content):
    path = tmp_path / 'bad.yaml'
    path.write_text(content)
    with pytest.raises(ValueError, match='bad.yaml'):
        CapabilityTable.load(path)
    with pytest.raises(ValueError, match='missing.yaml'):
        CapabilityTable.load(tmp_path / 'missing.yaml')
