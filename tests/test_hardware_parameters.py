"""
The hardware mode's bad input: each refused at start with one line naming what is wrong.

An unknown clock_source or sensor_profile, a profile file with a missing or negative figure,
and lockstep with the system clock. The executable is started once (one [FATAL] line, exit
1); the rest go to the node class in this process, through the same arguments.
"""

import os
import subprocess

import pytest
from rclpy.parameter import Parameter
from swivel_car_sim.sensor_models import shipped_profile
from swivel_car_sim.sim_node import SimNode
from swivel_car_testing import next_domain_id, REPO_ROOT
import yaml

SIM_NODE = REPO_ROOT / 'ros2_ws' / 'install' / 'swivel_car_sim' / 'lib' / 'swivel_car_sim' \
    / 'sim_node'


def test_lockstep_with_the_wall_clock_is_one_fatal_line_and_exit_1():
    env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST',
               ROS_DOMAIN_ID=str(next_domain_id()))
    done = subprocess.run(
        [str(REPO_ROOT / 'scripts' / 'in_ws'), str(SIM_NODE), '--ros-args',
         '-p', 'clock_source:=wall', '-p', 'lockstep:=true'],
        env=env, capture_output=True, text=True, timeout=60)
    output = done.stdout + done.stderr
    assert done.returncode == 1, output
    assert 'Traceback' not in output
    fatal = [line for line in output.splitlines() if '[FATAL]' in line]
    assert len(fatal) == 1 and 'lockstep cannot run with clock_source wall' in fatal[0], output


def _profile(tmp_path, section, figure, value):
    """Write the shipped profile with ``section.figure`` = ``value`` (None: left out)."""
    data = yaml.safe_load(shipped_profile('realistic').read_text())
    data[section] = {**{k: v for k, v in data[section].items() if k != figure},
                     **({} if value is None else {figure: value})}
    (tmp_path / 'profile.yaml').write_text(yaml.safe_dump(data))
    return str(tmp_path / 'profile.yaml')


@pytest.mark.parametrize('case, message', [
    ({'clock_source': 'gps'}, "clock_source must be 'sim' or 'wall', got 'gps'"),
    ({'sensor_profile': 'noisy'}, 'sensor_profile must be one of ideal, realistic or a '
                                  ".yaml file path, got 'noisy'"),
    ({'clock_source': 'wall', 'lockstep': True}, 'lockstep cannot run with clock_source wall'),
    ({'clock_source': 'wall', 'real_time_factor': 0.0}, 'real_time_factor must be 1.0'),
    ({'sensor_seed': -3}, 'sensor_seed must be an integer >= 0'),
    ({'sensor_profile': ('imu', 'gyro_noise_density', None)},
     'imu.gyro_noise_density is missing'),
    ({'sensor_profile': ('transport', 'state_latency', -2.0)},
     r'transport.state_latency must be >= 0 \[ms\], got -2.0'),
], ids=['clock_source', 'profile', 'lockstep_wall', 'wall_pace', 'seed', 'missing_figure',
        'negative_figure'])
def test_bad_hardware_parameters_are_refused_with_one_line(ros_domain, tmp_path, case,
                                                           message):
    values = {name: (_profile(tmp_path, *value) if isinstance(value, tuple) else value)
              for name, value in case.items()}
    with pytest.raises(ValueError, match=message) as refused:
        SimNode(context=ros_domain[1], parameter_overrides=[
            Parameter(name, value=value) for name, value in values.items()])
    assert '\n' not in str(refused.value)
