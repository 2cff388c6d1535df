"""
TF on every machine (issue 37): the robot's frames as a Jazzy user's tools expect them.

tf2_msgs is Jazzy's (type hash); the published link frames agree with pybullet's own link
poses; the running executables' /tf and /tf_static heard by an rclpy subscriber; and a bag the
real recorder wrote, decoded by Foxglove's own parsers (npm, ``tests/foxglove``), places every
link of the URDF.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
import re
import subprocess
import sys
import time
import xml.etree.ElementTree as ElementTree

from ament_index_python.packages import get_package_share_directory
from demo_report import FOXGLOVE_LAYOUT, READING_EXAMPLE
from mcap_ros2._dynamic import generate_dynamic
import numpy as np
import pybullet
import pytest
import rclpy
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rosbags.typesys import get_typestore, Stores
from scipy.spatial.transform import Rotation
from sensor_msgs.msg import JointState
from swivel_car_msgs.srv import StepSimulation
from swivel_car_sim.sim_node import SimNode
from swivel_car_telemetry.bag import MessageDefinitions
from swivel_car_telemetry.robot_description_node import RobotDescriptionNode
from swivel_car_telemetry.topics import message_class
from swivel_car_testing import next_domain_id, NodeProcess, REPO_ROOT, spin_until, start_node
from tf2_msgs.msg import TFMessage

# `ros2 topic info -v /tf` on a full Jazzy install (ros2/geometry2's tf2_msgs): the hash a tf2
# listener there matches our publishers by.
JAZZY_TFMESSAGE_HASH = 'RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087'
# The issue's bounds for the links' poses. Both sides are the URDF's joint transforms at the
# same joint positions (ideal sensors), so what parts them is rounding: measured 5e-8 m and
# 3e-7 rad at most, the single-precision rounding of pybullet's reported link frames.
POSITION_TOLERANCE = 1e-3  # [m]
ANGLE_TOLERANCE = 1e-3  # [rad]
LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)
TIMEOUT = 60.0  # [s] wall guard against a hang, not a measurement
# [ns] of joint_states time between robot_description's /tf of the moving links (its default
# publish_frequency, 20 Hz)
LINKS_PERIOD_NS = 50_000_000
FOXGLOVE = REPO_ROOT / 'tests' / 'foxglove'


def _ns(stamp) -> int:
    return stamp.sec * 1_000_000_000 + stamp.nanosec


def _links(urdf: str) -> set[str]:
    return {link.get('name') for link in ElementTree.fromstring(urdf).findall('link')}


def _pose_in(tree: dict[str, tuple[str, tuple, tuple]], link: str,
             root: str) -> tuple[np.ndarray, Rotation]:
    """Compose ``tree`` (child -> (parent, translation, quaternion xyzw)) from ``root`` to it."""
    position, orientation = np.zeros(3), Rotation.identity()
    while link != root:
        parent, translation, rotation = tree[link]
        rotation = Rotation.from_quat(rotation)
        position, orientation = np.add(translation, rotation.apply(position)), \
            rotation * orientation
        link = parent
    return position, orientation


def _relative(reference: tuple, pose: tuple) -> tuple[np.ndarray, Rotation]:
    """Return ``pose`` (position, quaternion xyzw in the world) in ``reference``'s frame."""
    inverse = Rotation.from_quat(reference[1]).inv()
    return (inverse.apply(np.subtract(pose[0], reference[0])),
            inverse * Rotation.from_quat(pose[1]))


def _tree(messages) -> dict[str, tuple[str, tuple, tuple]]:
    tree = {}
    for message in messages:
        for t in message.transforms:
            p, q = t.transform.translation, t.transform.rotation
            tree[t.child_frame_id] = (t.header.frame_id, (p.x, p.y, p.z), (q.x, q.y, q.z, q.w))
    return tree


def test_tf2_msgs_is_jazzys():
    share = Path(get_package_share_directory('tf2_msgs'))
    description = json.loads((share / 'msg' / 'TFMessage.json').read_text())
    hashes = {h['type_name']: h['hash_string'] for h in description['type_hashes']}
    assert hashes['tf2_msgs/msg/TFMessage'] == JAZZY_TFMESSAGE_HASH
    # rosbags' own copy of Jazzy's definitions (what the recorder writes into a bag) agrees.
    assert get_typestore(Stores.ROS2_JAZZY).hash_rihs01(
        'tf2_msgs/msg/TFMessage') == JAZZY_TFMESSAGE_HASH


class _Probe(Node):
    """Hears /tf, /tf_static (late: transient local) and joint_states."""

    def __init__(self, context, namespace: str = '/') -> None:
        super().__init__('tf_probe', context=context, namespace=namespace)
        self.tf: list[TFMessage] = []
        self.tf_static: list[TFMessage] = []
        self.joint_states: list[JointState] = []
        self.tf_subscription = self.create_subscription(TFMessage, '/tf', self.tf.append, 1000)
        self.create_subscription(TFMessage, '/tf_static', self.tf_static.append, LATCHED)
        self.create_subscription(JointState, 'joint_states', self.joint_states.append, 1000)


def test_link_frames_from_tf_agree_with_pybullet():
    """Each link's pose in base_link from /tf and /tf_static, and pybullet's, at each stamp."""
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=next_domain_id())
    # Ideal sensors: joint_states are pybullet's joint positions (the profile's parameter is
    # ignored by a sim that has none).
    sim_node = SimNode(context=context, parameter_overrides=[
        Parameter('start_paused', value=True), Parameter('sensor_profile', value='ideal')])
    frames_node = RobotDescriptionNode(context=context, parameter_overrides=[
        Parameter('publish_frequency', value=100.0)])
    probe = _Probe(context)
    executor = EventsExecutor(context=context)
    for node in (sim_node, frames_node, probe):
        executor.add_node(node)
    sim = sim_node.sim
    step = probe.create_client(StepSimulation, 'sim/step')
    truth: dict[int, dict[str, tuple]] = {}
    try:
        spin_until(executor, lambda: step.service_is_ready() and probe.tf_static
                   and probe.tf_subscription.get_publisher_count() > 0
                   and frames_node.count_publishers('joint_states') > 0
                   and sim_node.count_subscribers('joint_states') >= 2, TIMEOUT, 'the nodes')
        body, client = sim._body, sim._client
        links = {pybullet.getJointInfo(body, j, physicsClientId=client)[12].decode(): j
                 for j in range(pybullet.getNumJoints(body, physicsClientId=client))}
        kp, kd = sim.description.kp, sim.description.kd
        for period in range(30):
            # The swivel driven to 0.8 rad by a PD, the wheels turning: every joint moves.
            state = sim.state()
            sim.set_command(kp * (0.8 - state.positions[0]) - kd * state.velocities[0], 4.0)
            heard = len(probe.joint_states)
            future = step.call_async(StepSimulation.Request(steps=5))
            spin_until(executor, lambda: future.done() and len(probe.joint_states) > heard,
                       TIMEOUT, 'a step')
            assert future.result().success, future.result().message
            base = sim._base_pose()
            truth[_ns(probe.joint_states[-1].header.stamp)] = {
                name: _relative(base, pybullet.getLinkState(
                    body, j, computeForwardKinematics=1, physicsClientId=client)[4:6])
                for name, j in links.items()}
        spin_until(executor, lambda: {_ns(m.transforms[0].header.stamp) for m in probe.tf}
                   >= set(truth), TIMEOUT, '/tf of every step')
    finally:
        executor.shutdown()
        for node in (probe, frames_node, sim_node):
            node.destroy_node()
        rclpy.try_shutdown(context=context)
    assert abs(state.positions[0]) > 0.2  # the swivel turned (from rest: 0)
    static = _tree(probe.tf_static)
    worst = (0.0, 0.0)
    for stamp, poses in truth.items():
        tree = static | _tree(m for m in probe.tf if _ns(m.transforms[0].header.stamp) == stamp)
        assert set(tree) | {'base_link'} == _links(frames_node.urdf)
        for link, (position, orientation) in poses.items():
            placed = _pose_in(tree, link, 'base_link')
            error = (float(np.linalg.norm(placed[0] - position)),
                     (placed[1].inv() * orientation).magnitude())
            worst = max(worst[0], error[0]), max(worst[1], error[1])
    print(f'{len(truth)} stamps x {len(links)} links: worst {worst[0]:.2e} m, '
          f'{worst[1]:.2e} rad')
    assert worst[0] < POSITION_TOLERANCE and worst[1] < ANGLE_TOLERANCE, worst


def _foxglove_decode(mcap: Path, topics: list[str]) -> dict:
    """Decode ``mcap`` with Foxglove's parsers (tests/foxglove/decode_bag.mjs)."""
    if not (FOXGLOVE / 'node_modules').is_dir():
        raise RuntimeError(f'no {FOXGLOVE}/node_modules: `make test` installs them (npm ci)')
    done = subprocess.run(['node', str(FOXGLOVE / 'decode_bag.mjs'), str(mcap), *topics],
                          capture_output=True, text=True, timeout=TIMEOUT, check=False)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def _decoded_tree(messages: list[dict]) -> dict[str, str]:
    return {t['child_frame_id']: t['header']['frame_id']
            for m in messages for t in m['message']['transforms']}


def _as_dict(transform) -> dict:
    p, q = transform.transform.translation, transform.transform.rotation
    return {'header': {'frame_id': transform.header.frame_id,
                       'stamp': {'sec': transform.header.stamp.sec,
                                 'nanosec': transform.header.stamp.nanosec}},
            'child_frame_id': transform.child_frame_id,
            'transform': {'translation': {'x': p.x, 'y': p.y, 'z': p.z},
                          'rotation': {'x': q.x, 'y': q.y, 'z': q.z, 'w': q.w}}}


def _key(transform: dict) -> tuple:
    """Return a transform decoded by Foxglove (or ``_as_dict``) as a comparable tuple."""
    header, values = transform['header'], transform['transform']
    return (header['frame_id'], transform['child_frame_id'], header['stamp']['sec'],
            header['stamp']['nanosec'], *values['translation'].values(),
            *values['rotation'].values())


def _root(tree: dict[str, str], link: str) -> str:
    while link in tree:
        link = tree[link]
    return link


def test_live_tf_and_a_recorded_bag_place_every_link(ros_domain, tmp_path):
    """
    The installed executables' /tf and /tf_static, heard live and recorded.

    The sim, the odometry and robot_description_node with their shipped parameters; the real
    recorder's bag then decoded as Foxglove decodes it.
    """
    domain_id, context = ros_domain
    bag = tmp_path / 'bag'
    stack = [start_node('swivel_car_sim', 'sim_node', domain_id,
                        {'use_sim_time': True, 'start_paused': True}),
             start_node('swivel_car_control', 'odometry_node', domain_id, {'use_sim_time': True}),
             NodeProcess('swivel_car_telemetry', 'robot_description_node', domain_id,
                         {'use_sim_time': True}),
             NodeProcess('swivel_car_telemetry', 'recorder_node', domain_id,
                         {'use_sim_time': True, 'output': str(bag), 'discovery_period': 0.2})]
    probe = _Probe(context)
    executor = EventsExecutor(context=context)
    executor.add_node(probe)
    step = probe.create_client(StepSimulation, 'sim/step')

    def recording(topic: str) -> bool:
        return any(i.node_name == 'recorder' for i in probe.get_subscriptions_info_by_topic(topic))
    try:
        spin_until(executor, lambda: step.service_is_ready() and probe.tf_static and all(
            recording(topic) for topic in ('/tf', '/tf_static', '/joint_states'))
            and probe.tf_subscription.get_publisher_count() >= 2, TIMEOUT,
            'the nodes, /tf_static and the recorder')

        def step_once() -> int:
            heard = len(probe.joint_states)
            future = step.call_async(StepSimulation.Request(steps=5))
            spin_until(executor, lambda: future.done() and len(probe.joint_states) > heard,
                       TIMEOUT, 'a step')
            return _ns(probe.joint_states[-1].header.stamp)

        # Stepped until the odometry and robot_description answer (each hears the sim a moment
        # after the graph shows it); the recorder's subscriptions are as old, give them a
        # moment more to match.
        deadline = time.monotonic() + TIMEOUT
        first = step_once()
        while not {t.child_frame_id for m in probe.tf for t in m.transforms
                   if _ns(t.header.stamp) >= first} >= {'base_link', 'front_t'}:
            assert time.monotonic() < deadline, 'no /tf from the odometry and the links'
            step_once()
        time.sleep(1.0)
        before = len(probe.joint_states)
        for _ in range(40):
            step_once()
        last = _ns(probe.joint_states[-1].header.stamp)

        def heard_up_to_last() -> bool:
            # The odometry answers every state, robot_description every LINKS_PERIOD_NS:
            # each has answered the last step once its latest /tf is that recent.
            latest = {}
            for m in probe.tf:
                source = 'odom' if m.transforms[0].child_frame_id == 'base_link' else 'links'
                latest[source] = max(latest.get(source, 0), _ns(m.transforms[0].header.stamp))
            return latest.get('odom') == last and latest.get('links', 0) > last - LINKS_PERIOD_NS
        spin_until(executor, heard_up_to_last, TIMEOUT, '/tf of the last step')
        hashes = {(topic, i.node_name): str(i.topic_type_hash)
                  for topic in ('/tf', '/tf_static')
                  for i in probe.get_publishers_info_by_topic(topic)}
        time.sleep(1.0)  # the recorder hears the last messages a moment after the probe
    finally:
        executor.shutdown()
        probe.destroy_node()
        codes = {p.name: p.stop() for p in stack}
    assert set(codes.values()) == {0}, codes
    # On the wire: Jazzy's type, by its hash, from the odometry and the robot description.
    assert set(hashes) >= {('/tf', 'odometry'), ('/tf', 'robot_description'),
                           ('/tf_static', 'robot_description')}, hashes
    assert set(hashes.values()) == {JAZZY_TFMESSAGE_HASH}, hashes
    # Live: odom -> base_link with every state (publish_rate 100 Hz = the sim's 0.01 s period),
    # the moving links at robot_description's 20 Hz of joint_states time, the fixed ones once.
    stamps = [_ns(s.header.stamp) for s in probe.joint_states[before:]]
    tf = [m for m in probe.tf if _ns(m.transforms[0].header.stamp) >= stamps[0]]
    odom = [m for m in tf if m.transforms[0].child_frame_id == 'base_link']
    assert [(t.header.frame_id, _ns(t.header.stamp)) for m in odom for t in m.transforms] \
        == [('odom', stamp) for stamp in stamps]
    links = [_ns(m.transforms[0].header.stamp) for m in tf if m not in odom]
    assert np.diff(links).tolist() == [LINKS_PERIOD_NS] * (len(links) - 1)
    assert len(links) >= len(stamps) // 5 - 1
    live = {t.child_frame_id: t.header.frame_id for m in probe.tf_static + probe.tf
            for t in m.transforms}

    # The bag, as Foxglove reads it: every message decodes, and /tf_static plus /tf place
    # every link of the URDF the bag carries under odom.
    decoded = _foxglove_decode(bag / 'bag.mcap', ['/tf', '/tf_static', '/robot_description'])
    assert decoded['failures'] == []
    assert {decoded['topics'][t]['schema'] for t in ('/tf', '/tf_static')} == {
        'tf2_msgs/msg/TFMessage'}
    (description,) = decoded['messages']['/robot_description']
    urdf = _links(description['message']['data'])
    assert {link: _root(live, link) for link in urdf} == dict.fromkeys(urdf, 'odom')
    recorded = _decoded_tree(decoded['messages']['/tf_static'] + decoded['messages']['/tf'])
    assert recorded['base_link'] == 'odom'
    assert {link: _root(recorded, link) for link in urdf} == dict.fromkeys(urdf, 'odom')
    # The report's Python example reads the same bag and plots the swivel angle.
    (tmp_path / 'report').mkdir()
    (tmp_path / 'report' / 'bag').symlink_to(bag)
    example = subprocess.run([sys.executable, '-c', READING_EXAMPLE], cwd=tmp_path,
                             capture_output=True, text=True, timeout=TIMEOUT, check=False,
                             env={**os.environ, 'MPLBACKEND': 'Agg'})
    assert example.returncode == 0, example.stderr
    plotted = int(example.stdout.split()[0])
    assert plotted >= len(stamps) and (tmp_path / 'swivel_angle.png').stat().st_size > 0
    # Every transform of the 40 steps heard live is in the bag, with its stamp and values.
    assert {_key(t) for m in decoded['messages']['/tf'] for t in m['message']['transforms']} \
        >= {_key(_as_dict(t)) for m in tf for t in m.transforms}


def test_mcap_ros2_support_refuses_the_action_feedback_as_the_report_says():
    """The report steers Python readers to rosbags for this reason; a fixed parser fails this."""
    definition, _ = MessageDefinitions(get_package_share_directory).definition(
        'swivel_car_msgs/action/ClimbStep_FeedbackMessage')
    with pytest.raises(Exception, match="'ClimbStep_FeedbackMessage' is an invalid message name"):
        generate_dynamic('swivel_car_msgs/action/ClimbStep_FeedbackMessage', definition)


def _field_path_resolves(type_name: str, path: str) -> bool:
    """Whether a Foxglove message path's fields (after the topic) exist in the type."""
    value = message_class(type_name)()
    for segment in path.split('.'):
        if segment.startswith('@'):
            # Foxglove's quaternion to roll/pitch/yaw; what follows names one of the three.
            return segment == '@rpy' and type(value).__name__ == 'Quaternion'
        name, index = re.fullmatch(r'(\w+)(?:\[(\d+)\])?', segment).groups()
        if not hasattr(value, name):
            return False
        value = getattr(value, name)
        if index is not None:
            value = 0.0  # an element of a float64[] (joint positions, efforts)
    return isinstance(value, (float, int)) or hasattr(value, 'get_fields_and_field_types')


def test_the_foxglove_layout_shows_what_the_stack_publishes():
    layout = json.loads((REPO_ROOT / FOXGLOVE_LAYOUT).read_text())
    panels = layout['configById']
    (view,) = [c for name, c in panels.items() if name.startswith('3D!')]
    assert (view['followTf'], view['followMode']) == ('base_link', 'follow-pose')
    assert {(layer['layerId'], layer.get('topic')) for layer in view['layers'].values()} >= {
        ('foxglove.Urdf', '/robot_description')}
    # Topics and their types as the README's node tables (checked against the nodes) list them.
    readme = (REPO_ROOT / 'README.md').read_text()
    types = dict(re.findall(r'^\| publishes \| `(/[^`]+)` \| (\S+) \|$', readme, re.M))
    types |= {f'{topic}/_action/feedback': f'{action}_FeedbackMessage' for topic, action
              in re.findall(r'^\| action \| `(/[^`]+)` \| (\S+) \|$', readme, re.M)}
    paths = [p['value'] for c in panels.values() for p in c.get('paths', [])] + [
        c['topicPath'] for c in panels.values() if 'topicPath' in c]
    resolved = {}
    for path in paths:
        topic = max((t for t in types if path.startswith(t + '.')), key=len, default=None)
        resolved[path] = topic is not None and _field_path_resolves(
            types[topic], path[len(topic) + 1:])
    assert all(resolved.values()), resolved
    titles = ' '.join(c.get('title', '') for c in panels.values())
    assert all(word in titles for word in ('swivel angle', 'pitch', 'torque', 'climb'))
