"""CDR bytes read and rewritten in place against rclpy's own serialization."""

from functools import reduce
from itertools import count

from hypothesis import given, settings, strategies as st
from nav_msgs.msg import Odometry
import pytest
from rclpy.serialization import deserialize_message, serialize_message
from sensor_msgs.msg import Imu, JointState
import swivel_car_msgs.msg
from swivel_car_msgs.msg import ActuatorCommand
from swivel_car_ros.serialized import (
    MessageReader, read_header, read_joint_state, read_logged, SerializedMessage,
    STAMP_FORMAT)

_NAMES = st.text(st.characters(codec='utf-8', exclude_characters='\x00'), max_size=9)
_VALUES = st.lists(st.floats(allow_nan=False), max_size=6)


@settings(max_examples=300, deadline=None)
@given(frame_id=_NAMES, names=st.lists(_NAMES, max_size=6), position=_VALUES,
       velocity=_VALUES, effort=_VALUES, sec=st.integers(-2**31, 2**31 - 1),
       nanosec=st.integers(0, 999_999_999))
def test_a_joint_state_reads_as_rclpy_deserializes_it(
        frame_id, names, position, velocity, effort, sec, nanosec):
    # Names and frame ids of every length put the arrays at every alignment; any lengths of
    # the arrays, the empty velocity of a driver that reports none among them.
    msg = JointState(name=names, position=position, velocity=velocity, effort=effort)
    msg.header.frame_id = frame_id
    msg.header.stamp.sec, msg.header.stamp.nanosec = sec, nanosec
    view = read_joint_state(serialize_message(msg))
    expected = deserialize_message(serialize_message(msg), JointState)
    assert view.stamp == expected.header.stamp
    assert view.name == tuple(expected.name)
    assert view.position == tuple(expected.position)
    assert view.velocity == tuple(expected.velocity)


def test_another_encoding_or_a_cut_message_is_refused():
    data = serialize_message(JointState(name=['swivel_joint'], position=[0.5], velocity=[1.0]))
    with pytest.raises(ValueError, match='encapsulation 0000'):
        read_joint_state(b'\x00\x00' + data[2:])  # big-endian
    with pytest.raises(ValueError, match='malformed JointState'):
        read_joint_state(data[:40])  # within the name


def test_a_message_read_in_error_is_logged_and_ignored():
    lines = []

    class Logger:

        def error(self, line, throttle_duration_sec):
            lines.append((line, throttle_duration_sec))

    data = serialize_message(JointState(name=['swivel_joint'], position=[0.5]))
    assert read_logged(Logger(), read_joint_state, data, 'joint_states').position == (0.5,)
    big_endian = b'\x00\x00' + data[2:]
    assert read_logged(Logger(), read_joint_state, big_endian, 'joint_states') is None
    assert lines == [
        ('joint_states ignored: not little-endian plain CDR: encapsulation 0000', 5.0)]
    # A reader of a few fields at their offsets, on a message cut before them.
    assert read_logged(Logger(), read_header, data[:8], 'odom') is None
    assert lines[1][0].startswith('odom ignored: unpack_from requires a buffer'), lines


def test_a_rewritten_message_is_the_message_built_field_by_field():
    command = SerializedMessage(ActuatorCommand(), (
        (STAMP_FORMAT, ('header.stamp.sec', 'header.stamp.nanosec')),
        ('<2d', ('swivel_torque', 'drive_speed'))))
    for sec, nanosec, torque, speed in ((3, 10_000_000, -1.5, 2.25), (0, 0, 0.0, 0.0)):
        command.pack(0, sec, nanosec)
        command.pack(1, torque, speed)
        expected = ActuatorCommand(swivel_torque=torque, drive_speed=speed)
        expected.header.stamp.sec, expected.header.stamp.nanosec = sec, nanosec
        assert deserialize_message(command.serialized(), ActuatorCommand) == expected


def test_fields_apart_in_the_serialized_message_are_refused():
    with pytest.raises(ValueError, match='not consecutive'):
        SerializedMessage(Odometry(), (('<2d', ('pose.pose.position.x',
                                                'twist.twist.linear.x')),))


def _filled(msg, numbers, prefix=''):
    """
    Set every field of ``msg`` to a value of its own; return the paths a reader can read.

    Strings and sequences of every length modulo 8 (by ``numbers``' start) put the fields
    after them at every alignment.
    """
    paths = []
    for name, kind in msg.get_fields_and_field_types().items():
        value, n = getattr(msg, name), next(numbers)
        if hasattr(value, 'get_fields_and_field_types'):
            paths += _filled(value, numbers, f'{prefix}{name}.')
            continue
        element = kind.removeprefix('sequence<').partition('[')[0].split(',')[0].rstrip('>')
        if element.startswith('string'):
            item = 'abcdefgh'[:n % 8]
        elif element == 'boolean':
            item = True
        elif element in ('float', 'double'):
            item = n + 0.25
        else:
            item = n % 100
        if kind.startswith('sequence<'):
            item = [item] * (n % 4)
        elif kind.endswith(']'):
            setattr(msg, name, [item] * len(value))
            continue  # an array: a reader reads its elements from a message of them
        setattr(msg, name, item)
        paths.append(prefix + name)
    return paths


_MESSAGES = [getattr(swivel_car_msgs.msg, name) for name in dir(swivel_car_msgs.msg)
             if hasattr(getattr(swivel_car_msgs.msg, name), 'get_fields_and_field_types')]


@pytest.mark.parametrize('message_type', _MESSAGES + [Odometry, Imu, JointState],
                         ids=lambda message_type: message_type.__name__)
@pytest.mark.parametrize('start', range(8))
def test_a_reader_reads_every_field_of_the_message_definitions(message_type, start):
    # Every field, as the .msg defines it now, set and read back: a field added to a .msg
    # before the ones a reader reads moves them, and a type the reader cannot lay out fails.
    msg = message_type()
    paths = _filled(msg, count(start))
    values = MessageReader(message_type, tuple(paths))(serialize_message(msg))
    for path, value in zip(paths, values, strict=True):
        expected = reduce(getattr, path.split('.'), msg)
        if not isinstance(expected, (bool, int, float, str)):
            expected = tuple(expected)
        assert value == expected, path


def test_a_reader_refuses_unknown_or_unordered_fields():
    with pytest.raises(ValueError, match='has no field'):
        MessageReader(ActuatorCommand, ('swivel_torque', 'brake'))
    with pytest.raises(ValueError, match='in the order of its fields'):
        MessageReader(ActuatorCommand, ('drive_speed', 'swivel_torque'))
    with pytest.raises(ValueError, match='an array'):
        MessageReader(Imu, ('orientation_covariance',))
    with pytest.raises(ValueError, match='malformed ActuatorCommand'):
        MessageReader(ActuatorCommand, ('drive_speed',))(
            serialize_message(ActuatorCommand())[:20])
