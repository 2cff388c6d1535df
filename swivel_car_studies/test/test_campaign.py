"""
The campaign command, from its sweep file to real trials on a two-node Ray cluster.

The sweep file's validation, the grid and its requests, resuming from the results file (no
Ray), the installed command, and real trials through --address. Its throughput and a
kill-and-resume of a whole campaign are ``python -m swivel_car_studies.campaign_benchmark``.
"""

from __future__ import annotations

import csv
import io
import math
import subprocess
import sys

import pytest
from swivel_car_planner.core import ErrorCode
from swivel_car_studies.campaign import (
    finished_keys, main, parse_sweep, plan_trials, record, result_cells, SweepError)
from swivel_car_studies.climb_benchmark import Trial
from swivel_car_testing import executable_path
import yaml

HEIGHTS = {'heights': [0.02]}


def _write(tmp_path, data) -> str:
    path = tmp_path / 'sweep.yaml'
    path.write_text(yaml.safe_dump(data))
    return str(path)


@pytest.mark.parametrize('data, field', [
    (None, 'trials.heights'),
    ({'desing': {'l': 0.3}, 'trials': HEIGHTS}, 'desing'),
    ({'design': {'body_ofset': 0.05}, 'trials': HEIGHTS}, 'body_ofset'),
    ({'design': {'rear_axle_mass': [3.2, -1.0]}, 'trials': HEIGHTS},
     'rear_axle_mass must be > 0'),
    ({'design': {'front_differential': 'welded'}, 'trials': HEIGHTS}, 'front_differential'),
    ({'design': {'body_offset': [0.0, 0.3]}, 'trials': HEIGHTS}, 'body_offset must be within'),
    ({'design': {'body_offset': []}, 'trials': HEIGHTS}, 'design.body_offset'),
    ({'procedure': {'rear_sped': 7.0}, 'trials': HEIGHTS}, 'rear_sped'),
    ({'procedure': {'rear_speed': 'fast'}, 'trials': HEIGHTS}, 'rear_speed'),
    ({'trials': {'heights': []}}, 'trials.heights'),
    ({'trials': {'heights': [0.02], 'count': 0}}, 'trials.count'),
    ({'trials': {'heights': [0.02], 'heigth': 0.03}}, 'heigth'),
    ({'trials': {'heights': [-0.02]}}, 'step_height'),
    ({'trials': {'heights': [0.02], 'max_distance': 5.0}}, 'step_distance'),
    ({'trials': {'heights': [0.02], 'min_width': 3.0}}, 'min_width')])
def test_a_bad_sweep_ends_in_one_line_naming_the_field_before_ray_starts(
        tmp_path, capsys, data, field):
    out = tmp_path / 'results.csv'
    with pytest.raises(SystemExit) as exit_:
        main([_write(tmp_path, data), '--out', str(out)])
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith('campaign: error: ') and err.count('\n') == 1, err
    assert field in err
    assert not out.exists()  # written only once everything is checked


def test_the_grid_is_every_combination_and_each_point_meets_the_same_requests():
    sweep = parse_sweep({
        'design': {'body_offset': [0.0, 0.05], 'rear_differential': ['open', 'locked'],
                   'wheel_friction': 0.9},
        'procedure': {'rear_speed': 7},
        'trials': {'heights': [0.04, 0.06], 'count': 3, 'seed': 4}})
    trials = plan_trials(sweep)
    assert len(trials) == 2 * 2 * 2 * 3
    points = {}
    for spec in trials:
        points.setdefault(spec.point, []).append(
            (spec.height, spec.distance, spec.yaw, spec.width, spec.offset))
        assert spec.config.robot.wheel_friction == 0.9
        assert spec.config.planner.rear_speed == 7.0
        assert spec.config.whole_car_limit == math.inf  # no capability table: every height
        assert dict(spec.point)['body_offset'] == spec.config.robot.body_offset
    assert set(points) == {(('body_offset', offset), ('rear_differential', diff))
                           for offset in (0.0, 0.05) for diff in ('open', 'locked')}
    requests = list(points.values())
    assert all(r == requests[0] for r in requests) and len(set(requests[0])) == 6
    assert len({spec.key() for spec in trials}) == len(trials)
    # More trials per point later only add trials.
    more = plan_trials(parse_sweep({
        'design': {'body_offset': [0.0, 0.05], 'rear_differential': ['open', 'locked'],
                   'wheel_friction': 0.9},
        'procedure': {'rear_speed': 7.0},
        'trials': {'heights': [0.04, 0.06], 'count': 5, 'seed': 4}}))
    assert {spec.key() for spec in trials} < {spec.key() for spec in more}
    with pytest.raises(SweepError, match='repeats a trial'):
        plan_trials(parse_sweep({'design': {'body_offset': [0.0, 0.0]}, 'trials': HEIGHTS}))


def _climbed(spec, code=ErrorCode.NONE):
    """
    Return the result columns of a trial as a climb would give them, without the physics.

    The bookkeeping is under test here.
    """
    trial = Trial(spec.height, spec.distance, spec.yaw, spec.width, spec.offset, code,
                  'done', True, True, 12.0, 30.0, 11.0, 29.0, 0, 4.0, 0.0, True, 9.5)
    return result_cells(trial, 2.5)


@pytest.fixture
def four_trials():
    return plan_trials(parse_sweep({'design': {'rear_axle_mass': [3.2, 6.0]},
                                    'trials': {'heights': [0.02], 'count': 2}}))


def test_a_second_run_runs_only_the_trials_not_in_the_file(tmp_path, four_trials):
    out = tmp_path / 'results.csv'
    progress = io.StringIO()
    assert record(((spec, _climbed(spec)) for spec in four_trials[:3]), out, 3,
                  progress) == 0
    assert progress.getvalue().count('\n') == 3 and '[3/3]' in progress.getvalue()
    finished = finished_keys(out)
    assert [spec for spec in four_trials if spec.key() not in finished] == four_trials[3:]
    rows = list(csv.DictReader(out.open(newline='')))
    assert [float(row['design.rear_axle_mass']) for row in rows] == [3.2, 3.2, 6.0]
    assert rows[0]['error_code'] == 'NONE' and rows[0]['four_wheels_on_top'] == 'True'
    assert float(rows[0]['distance']) == four_trials[0].distance
    assert rows[0]['git_revision']
    record([(four_trials[3], _climbed(four_trials[3]))], out, 1, io.StringIO())
    assert finished_keys(out) == {spec.key() for spec in four_trials}
    assert out.read_text().count('design.l') == 1  # one header


def test_a_row_cut_short_by_a_kill_is_dropped_and_its_trial_runs_again(tmp_path, four_trials):
    out = tmp_path / 'results.csv'
    record(((spec, _climbed(spec)) for spec in four_trials[:2]), out, 2, io.StringIO())
    whole = out.read_text()
    with out.open('a') as file:
        file.write(whole.splitlines()[-1][:60])  # killed while writing the third row
    assert finished_keys(out) == {spec.key() for spec in four_trials[:2]}
    assert out.read_text() == whole


def test_a_trial_that_raises_is_reported_and_not_written(tmp_path, four_trials):
    out = tmp_path / 'results.csv'
    progress = io.StringIO()
    failed = record([(four_trials[0], RuntimeError('worker died')),
                     (four_trials[1], _climbed(four_trials[1]))], out, 2, progress)
    assert failed == 1 and 'RAISED, not written: worker died' in progress.getvalue()
    assert finished_keys(out) == {four_trials[1].key()}


def test_a_results_file_of_other_columns_is_refused(tmp_path, capsys):
    out = tmp_path / 'results.csv'
    out.write_text('height,trial,success\n0.02,0,True\n')
    with pytest.raises(SystemExit) as exit_:
        main([_write(tmp_path, {'trials': HEIGHTS}), '--out', str(out)])
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert err.count('\n') == 1 and 'other columns' in err and '--out' in err
    assert out.read_text() == 'height,trial,success\n0.02,0,True\n'


def test_the_installed_command_refuses_a_bad_sweep_in_one_line(tmp_path):
    done = subprocess.run(
        [sys.executable, str(executable_path('swivel_car_studies', 'campaign')),
         _write(tmp_path, {'design': {'body_ofset': 0.05}, 'trials': HEIGHTS}),
         '--out', str(tmp_path / 'results.csv')], capture_output=True, text=True, timeout=60)
    assert done.returncode == 2
    # pybullet prints its build time on import, in every program that loads the sim.
    lines = [line for line in done.stderr.splitlines()
             if not line.startswith('pybullet build time')]
    assert lines == ['campaign: error: design body_ofset=0.05: unknown robot description '
                     'parameter(s): body_ofset'], done.stderr


def test_trials_run_on_a_two_node_ray_cluster_through_address(tmp_path, capsys):
    from ray.cluster_utils import Cluster
    sweep = _write(tmp_path, {'trials': {
        'heights': [0.02], 'count': 2, 'min_distance': 0.9, 'max_distance': 1.0,
        'max_yaw': 0.05, 'min_width': 1.8, 'max_width': 2.0}})
    out = tmp_path / 'results.csv'
    node = {'num_cpus': 1, 'object_store_memory': 100 * 10 ** 6}
    cluster = Cluster(initialize_head=True, head_node_args={**node, 'include_dashboard': False})
    try:
        cluster.add_node(**node)
        main([sweep, '--out', str(out), '--address', cluster.address])
    finally:
        cluster.shutdown()
    rows = list(csv.DictReader(out.open(newline='')))
    assert len(rows) == 2
    assert len({row['ray_node'] for row in rows}) == 2  # one trial on each node
    for row in rows:  # a 2 cm step from about 1 m: the sim's ground truth has it climbed
        assert row['four_wheels_on_top'] == 'True', row['message']
        assert row['error_code'] in ErrorCode.__members__
    capsys.readouterr()
    main([sweep, '--out', str(out)])  # everything is in the file: Ray is not even started
    assert 'campaign: 2 trials, 2 already in' in capsys.readouterr().err
    assert len(list(csv.DictReader(out.open(newline='')))) == 2
