import pytest

from swivel_car_model.description import CarDescription

from swivel_car_planner.core.capability import CapabilityTable, description_values


def table(successes, trials=8, description=None):
    heights = tuple(round(0.02 + 0.01 * i, 2) for i in range(len(successes)))
    return CapabilityTable(heights, (trials,) * len(successes), tuple(successes),
                           description_values(description or CarDescription()))


def test_limit_is_the_top_of_the_unbroken_reliable_run():
    assert table([8, 8, 8, 7, 8, 2]).limit == pytest.approx(0.04)  # 7/8 = 88 % breaks it
    assert table([8, 8, 8, 8, 8, 0]).limit == pytest.approx(0.06)
    assert table([5, 8]).limit == 0.0


def test_the_table_round_trips_through_its_file(tmp_path):
    original = table([8, 8, 4])
    original.save(tmp_path / 'capability.yaml', header='made by a test')
    loaded = CapabilityTable.load(tmp_path / 'capability.yaml')
    assert loaded == original
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
