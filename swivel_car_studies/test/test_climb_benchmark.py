"""The climbing benchmark's own arithmetic, and the shipped tables of the designs."""

from pathlib import Path

from ament_index_python.packages import get_package_share_directory
import numpy as np
import pytest
from swivel_car_model.description import CarDescription
from swivel_car_planner.core.capability import CapabilityTable
from swivel_car_studies.climb_benchmark import design_values, heights, main, sign_changes


def test_sign_changes_ignore_the_band_around_zero():
    assert sign_changes(np.array([5.0, 0.5, -0.5, 4.0, -3.0, -2.0, 0.0, 6.0])) == 2
    assert sign_changes(np.array([0.2, -0.3, 0.9])) == 0
    assert sign_changes(np.array([])) == 0


def test_heights_are_whole_increments_from_start_to_stop():
    assert heights(0.02, 0.05, 0.01) == [0.02, 0.03, 0.04, 0.05]


def test_each_shipped_design_has_a_table_measured_on_it():
    planner = Path(get_package_share_directory('swivel_car_planner'))
    default = CapabilityTable.load(planner / 'config' / 'capability.yaml')
    assert default.matches(CarDescription())
    assert default.limit >= 0.07
    model = Path(get_package_share_directory('swivel_car_model'))
    thesis_inertia = CarDescription().replace(
        **design_values(model / 'config' / 'designs' / 'thesis_inertia.yaml'))
    table = CapabilityTable.load(planner / 'config' / 'capability_thesis_inertia.yaml')
    assert table.matches(thesis_inertia)
    assert not table.matches(CarDescription())
    assert table.limit == pytest.approx(0.06)


@pytest.mark.parametrize('option, message', [
    ('--set=bogus=2', 'unknown robot description parameter'),
    ('--set=body_mass=heavy', 'body_mass'),
    ('--controller=bogus=1', 'unknown controller parameter'),
    ('--planner=rear_speed=-1', 'rear_speed must be >= 0'),
    ('--phi-negative-heights=0.05,-0.05', 'must be a finite height > 0 m, got -0.05'),
    ('--max-height=inf', 'must be a finite height > 0 m, got inf'),
    ('--step=0', 'must be a finite height > 0 m, got 0'),
    ('--sensor-profiles=ideal,noisy', 'sensor_profile must be one of ideal, realistic')])
def test_a_bad_override_is_a_usage_error_before_any_climb(option, message, capsys):
    with pytest.raises(SystemExit) as exit_:
        main(['--heights', '0.02', '--trials', '1', '--skip-car-like', option])
    assert exit_.value.code == 2
    out, err = capsys.readouterr()
    assert message in err and 'attempted climbs' not in out
