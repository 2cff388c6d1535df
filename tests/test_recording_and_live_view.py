"""
A Jazzy user's tools (issue 16), through the installed executables.

A recorded run read back by an independent MCAP reader, the robot model on the graph for a
late subscriber, the live Foxglove view through a WebSocket client, and a bag that survives a
full disk.
"""

from __future__ import annotations

import asyncio
import json
import re
import shutil
import socket
import struct
import subprocess
import sys
import textwrap
import time
import xml.etree.ElementTree as ElementTree

from geometry_msgs.msg import TwistStamped
from mcap.reader import make_reader
from mcap_ros2._dynamic import generate_dynamic
from mcap_ros2.decoder import DecoderFactory
import pytest
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import JointState
from std_msgs.msg import String
from swivel_car_msgs.srv import StepSimulation
from swivel_car_testing import INSTALL_DIR, NodeProcess, spin_until
import websockets
import yaml

PERIODS = 40  # control periods the recorded run steps
STEPS_PER_PERIOD = 5  # physics steps per control period (sim_node.yaml: 0.01 s / 0.002 s)
CLOCK_PERIOD = 100_000_000  # [ns] of sim time between /clock messages (sim_node.yaml: 10 Hz)
LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)


def _stamp(msg) -> int:
    return msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec  # [ns]


def _start(domain_id: int, *nodes: tuple[str, str, dict]) -> list[NodeProcess]:
    processes = []
    for package, executable, parameters in nodes:
        config = INSTALL_DIR / package / 'share' / package / 'config' / f'{executable}.yaml'
        processes.append(NodeProcess(package, executable, domain_id,
                                     {'use_sim_time': True, **parameters},
                                     params_file=config if config.is_file() else None))
    return processes


def _stop(processes: list[NodeProcess]) -> dict[str, int]:
    return {p.name: p.stop() for p in processes}


def _urdf_joints(urdf: str) -> dict[str, str]:
    return {joint.get('name'): joint.get('type')
            for joint in ElementTree.fromstring(urdf).findall('joint')}


class Probe(Node):
    """The test's node: hears joint_states, publishes cmd_vel."""

    def __init__(self, context) -> None:
        super().__init__('probe', context=context)
        self.joint_states: list[JointState] = []
        self.create_subscription(JointState, 'joint_states', self.joint_states.append, 1000)
        self.cmd_vel = self.create_publisher(TwistStamped, 'cmd_vel', 100)

    def subscribed_by(self, node_name: str, topics: list[str]) -> bool:
        return all(any(info.node_name == node_name
                       for info in self.get_subscriptions_info_by_topic(topic))
                   for topic in topics)


def test_a_recorded_run_reads_back_with_an_independent_reader(ros_domain, tmp_path):
    domain_id, context = ros_domain
    bag = tmp_path / 'run'
    stack = _start(domain_id, ('swivel_car_sim', 'sim_node', {'start_paused': True}),
                   ('swivel_car_control', 'odometry_node', {}),
                   ('swivel_car_telemetry', 'robot_description_node', {}))
    recorder = _start(domain_id, ('swivel_car_telemetry', 'recorder_node',
                                  {'output': str(bag), 'discovery_period': 0.2}))[0]
    probe = Probe(context)
    executor = EventsExecutor(context=context)
    executor.add_node(probe)
    step = probe.create_client(StepSimulation, 'sim/step')
    topics = ['/clock', '/joint_states', '/imu', '/ground_truth/odom', '/odom',
              '/robot_description', '/cmd_vel']
    try:
        spin_until(executor, lambda: recorder.running() and probe.subscribed_by(
            'recorder', topics) and step.service_is_ready(), 60.0,
            f'the recorder to subscribe to {topics}:\n{recorder.output()}')
        # Subscriptions show on the graph a moment before every publisher has matched them.
        spin_until(executor, lambda: probe.cmd_vel.get_subscription_count() > 0, 10.0,
                   'cmd_vel to match')
        time.sleep(1.0)
        before = len(probe.joint_states)
        sent = [0.01 * (i + 1) for i in range(10)]
        for speed in sent:
            msg = TwistStamped()
            msg.twist.linear.x = speed
            probe.cmd_vel.publish(msg)
        # One period per call, as a lockstep controller paces the sim: a burst of all of them
        # at once can outrun the sim's publisher queue (depth 10) on a loaded machine.
        for _ in range(PERIODS):
            future = step.call_async(StepSimulation.Request(steps=STEPS_PER_PERIOD))
            spin_until(executor, future.done, 60.0, 'a step')
            assert future.result().success, future.result().message
        spin_until(executor, lambda: len(probe.joint_states) >= before + PERIODS, 60.0,
                   'the states of the steps')
        stepped = probe.joint_states[before:]
        # The last states reach the recorder, a subscriber of its own, a moment after the
        # probe (spin_once would return at the probe's next event, at once). Stopped, it
        # writes all it has received (recorder_node's drain), not what is still on the way.
        time.sleep(1.0)
    finally:
        executor.shutdown()
        probe.destroy_node()
        assert recorder.stop() == 0, recorder.output()
        _stop(stack)

    metadata = yaml.safe_load((bag / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    assert metadata['storage_identifier'] == 'mcap'
    counts = {t['topic_metadata']['name']: t['message_count']
              for t in metadata['topics_with_message_count']}
    assert set(topics) <= set(counts)
    messages: dict[str, list] = {}
    with open(bag / metadata['relative_file_paths'][0], 'rb') as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        summary = reader.get_summary()
        for schema in summary.schemas.values():
            assert schema.encoding == 'ros2msg' and schema.data, schema.name
        for _, channel, message, decoded in reader.iter_decoded_messages():
            messages.setdefault(channel.topic, []).append((message.log_time, decoded))
    # A topic discovered but silent (a stray node's) is listed with no messages.
    assert {topic: len(found) for topic, found in messages.items()} == {
        topic: count for topic, count in counts.items() if count}

    # Every command sent, once, with its value.
    assert [m.twist.linear.x for _, m in messages['/cmd_vel']] == sent
    # Every state the sim published while stepping, with the values it sent, stamped on
    # receipt in sim time (not the wall clock's ~1.8e18 ns): the recorder's clock, at the
    # last /clock, is at most a clock period behind the state.
    recorded = {_stamp(m): (t, m) for t, m in messages['/joint_states']}
    for state in stepped:
        log_time, msg = recorded[_stamp(state)]
        assert list(msg.name) == list(state.name)
        assert list(msg.position) == list(state.position)
        assert -CLOCK_PERIOD <= log_time - _stamp(state) < 1_000_000_000
    assert max(recorded) == _stamp(stepped[-1])
    clock = {t.clock.sec * 1_000_000_000 + t.clock.nanosec for _, t in messages['/clock']}
    stamps = {_stamp(s) for s in stepped}
    assert clock & stamps == {t for t in stamps if t % CLOCK_PERIOD == 0}
    # The model travels with the data.
    (_, description), = messages['/robot_description']
    assert set(stepped[-1].name) <= set(_urdf_joints(description.data))


def test_robot_description_for_a_late_subscriber_matches_joint_states(ros_domain):
    domain_id, context = ros_domain
    stack = _start(domain_id, ('swivel_car_sim', 'sim_node', {}),
                   ('swivel_car_telemetry', 'robot_description_node', {}))
    probe = Probe(context)
    executor = EventsExecutor(context=context)
    executor.add_node(probe)
    try:
        spin_until(executor, lambda: len(probe.joint_states) > 10, 60.0, 'joint_states')
        spin_until(executor, lambda: 'robot_description' in probe.get_node_names(), 30.0,
                   'robot_description_node')
        descriptions: list[String] = []
        probe.create_subscription(String, 'robot_description', descriptions.append, LATCHED)
        spin_until(executor, lambda: descriptions, 30.0, 'robot_description')
    finally:
        executor.shutdown()
        probe.destroy_node()
        codes = _stop(stack)
    assert set(codes.values()) == {0}, codes
    joints = _urdf_joints(descriptions[0].data)
    moving = {name for name, kind in joints.items() if kind != 'fixed'}
    assert moving == set(probe.joint_states[-1].name)


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(('127.0.0.1', 0))
        return probe.getsockname()[1]


async def _subscribe(connection, channel_ids: list[int]) -> None:
    await connection.send(json.dumps({'op': 'subscribe', 'subscriptions': [
        {'id': i, 'channelId': i} for i in channel_ids]}))


async def _foxglove_messages(port: int, topics: set[str], deadline: float) -> dict:
    """Subscribe to ``topics`` on the bridge; the first message of each, decoded."""
    while True:
        try:
            connection = await websockets.connect(f'ws://127.0.0.1:{port}',
                                                  subprotocols=['foxglove.sdk.v1'])
            break
        except OSError:
            if time.monotonic() > deadline:
                raise
            await asyncio.sleep(0.2)
    channels: dict[int, dict] = {}
    decoded: dict[str, object] = {}
    async with connection:
        while set(decoded) != topics:
            frame = await asyncio.wait_for(connection.recv(), deadline - time.monotonic())
            if isinstance(frame, str):
                message = json.loads(frame)
                if message['op'] == 'advertise':
                    wanted = [c for c in message['channels'] if c['topic'] in topics]
                    for channel in wanted:
                        channels[channel['id']] = channel
                    await _subscribe(connection, [c['id'] for c in wanted])
                elif message['op'] == 'status':
                    # foxglove-sdk sends an advertisement before it records the channel for
                    # subscriptions: one that overtakes it is refused, as a client must retry.
                    refused = re.fullmatch(r'Unknown channel ID: (\d+)', message['message'])
                    if refused and int(refused[1]) in channels:
                        await asyncio.sleep(0.05)
                        await _subscribe(connection, [int(refused[1])])
            elif frame[0] == 1:  # message data: subscription id, log time, payload
                subscription, = struct.unpack_from('<I', frame, 1)
                channel = channels[subscription]
                decoder = generate_dynamic(channel['schemaName'], channel['schema'])[
                    channel['schemaName']]
                decoded.setdefault(channel['topic'], decoder(frame[13:]))
    return decoded


def test_the_live_view_serves_decodable_joint_states_odom_and_tf(ros_domain):
    domain_id, _ = ros_domain
    port = _free_port()
    stack = _start(domain_id, ('swivel_car_sim', 'sim_node', {}),
                   ('swivel_car_control', 'odometry_node', {}),
                   ('swivel_car_telemetry', 'robot_description_node', {}),
                   ('swivel_car_telemetry', 'foxglove_bridge_node', {'port': port}))
    try:
        decoded = asyncio.run(_foxglove_messages(
            port, {'/joint_states', '/odom', '/robot_description', '/tf', '/tf_static'},
            time.monotonic() + 60.0))
    finally:
        codes = _stop(stack)
    assert set(codes.values()) == {0}, codes
    assert 'swivel_joint' in decoded['/joint_states'].name
    assert len(decoded['/joint_states'].position) == len(decoded['/joint_states'].name)
    assert decoded['/odom'].child_frame_id == 'base_link'
    assert 'swivel_joint' in _urdf_joints(decoded['/robot_description'].data)
    # The car's frames as Foxglove's 3D panel reads them: the stack's /tf (the odometry's and
    # robot_description's) and /tf_static (latched: sent to a subscriber that comes later).
    assert decoded['/tf'].transforms and {t.child_frame_id for t in decoded['/tf'].transforms} <= {
        'base_link', 'front_t', 'rear_left_wheel', 'rear_right_wheel', 'front_left_wheel',
        'front_right_wheel'}
    assert type(decoded['/tf_static']).__name__ == 'TFMessage'


def test_a_bad_output_is_one_fatal_line(ros_domain, tmp_path):
    domain_id, _ = ros_domain
    recorder = NodeProcess('swivel_car_telemetry', 'recorder_node', domain_id,
                           {'output': str(tmp_path)})
    recorder.process.wait(60)
    output = recorder.output()
    assert recorder.stop() == 1, output
    assert 'Traceback' not in output
    fatal = [line for line in output.splitlines() if '[FATAL]' in line]
    assert len(fatal) == 1 and 'exists already' in fatal[0], output


# In a mount namespace of its own, on a 3 MB file system: write 100 kB messages until the
# writer stops, then read the bag back.
_FULL_DISK = textwrap.dedent("""
    import json, sys
    from pathlib import Path
    from ament_index_python.packages import get_package_share_directory
    from mcap.reader import make_reader
    from swivel_car_telemetry.bag import BagWriter, MessageDefinitions
    disk = Path(sys.argv[1])
    bag = BagWriter(disk / 'bag', MessageDefinitions(get_package_share_directory), 1_500_000)
    bag.create()
    bag.add_topic('/big', 'std_msgs/msg/String', [])
    data = b'\\x00\\x01\\x00\\x00' + (100_000).to_bytes(4, 'little') + b'x' * 99_999 + b'\\x00'
    written = 0
    while bag.write('/big', written, data):
        written += 1
    with open(disk / 'bag' / 'bag.mcap', 'rb') as stream:
        summary = make_reader(stream).get_summary()
    print(json.dumps({'written': written, 'stopped': bag.stopped,
                      'read': summary.statistics.message_count,
                      'metadata': (disk / 'bag' / 'metadata.yaml').is_file()}))
""")


def test_a_full_disk_stops_the_bag_closed_and_readable(tmp_path):
    unshare = shutil.which('unshare')
    if unshare is None or subprocess.run(
            [unshare, '--user', '--map-root-user', '--mount', 'true']).returncode != 0:
        pytest.skip('no unprivileged mount namespaces here to make a small disk in')
    disk = tmp_path / 'disk'
    disk.mkdir()
    done = subprocess.run(
        [unshare, '--user', '--map-root-user', '--mount', 'sh', '-c',
         f'mount -t tmpfs -o size=3m none {disk} && exec "$0" -c "$1" {disk}',
         sys.executable, _FULL_DISK], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    result = json.loads(done.stdout)
    assert 'left on the disk' in result['stopped']
    assert result['written'] > 0 and result['read'] == result['written']
    assert result['metadata']
