"""Dataclass fields as parameters: each of its field's type, read as a user writes it."""

from __future__ import annotations

from dataclasses import dataclass
import os

import pytest
import rclpy
from rclpy.exceptions import ParameterException
from rclpy.node import Node
from rclpy.parameter import Parameter
from swivel_car_model.checks import check_number
from swivel_car_model.description import described
from swivel_car_ros.ros_params import declare_dataclass
from swivel_car_testing import next_domain_id


@dataclass(frozen=True)
class Settings:
    """One field of each kind a node's config has."""

    gain: float = described(2.0, 'a number [1]')
    count: int = described(3, 'a whole number [1]')
    enabled: bool = described(True, 'a switch')
    frame: str = described('base_link', 'a name')
    diagonal: tuple = described((0.5, 0.5), 'numbers [m^2]')

    def __post_init__(self) -> None:
        check_number('gain', self.gain, above=0.0)


TYPES = {'gain': Parameter.Type.DOUBLE, 'count': Parameter.Type.INTEGER,
         'enabled': Parameter.Type.BOOL, 'frame': Parameter.Type.STRING,
         'diagonal': Parameter.Type.DOUBLE_ARRAY}


@pytest.fixture(scope='module')
def context():
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=next_domain_id())
    yield context
    rclpy.try_shutdown(context=context)


def declare(context, *arguments: str) -> tuple[Settings, dict]:
    """Declare ``Settings`` on a node started with ``-p`` ``arguments``; return it, the types."""
    node = Node('settings', context=context,
                cli_args=['--ros-args', *(a for p in arguments for a in ('-p', p))])
    try:
        settings = declare_dataclass(node, Settings)
        return settings, {name: node.get_parameter(name).type_ for name in TYPES}
    finally:
        node.destroy_node()


def test_each_field_is_a_parameter_of_its_type(context):
    settings, types = declare(context)
    assert settings == Settings()
    assert types == TYPES


def test_a_whole_number_is_an_integer_and_an_integer_where_a_number_is_due_passes(context):
    settings, types = declare(context, 'count:=7', 'gain:=19', 'diagonal:=[1, 2]')
    assert (settings.count, types['count']) == (7, Parameter.Type.INTEGER)
    assert settings.gain == 19 and settings.diagonal == (1, 2)


@pytest.mark.parametrize('argument', ['count:=2.5', 'enabled:=7', 'frame:=[1]'])
def test_a_value_of_another_type_is_refused_naming_it(context, argument):
    with pytest.raises(ParameterException, match=argument.split(':=')[0]):
        declare(context, argument)


def test_a_bad_number_is_refused_by_the_dataclass(context):
    with pytest.raises(ValueError, match='gain must be a finite number > 0'):
        declare(context, 'gain:=-1')
