"""
In-process node tests: real rclpy, the nodes' topics and services.

Driven by hand-made joint_states (no sim), each test on a fresh ROS domain.
"""

import math
import os

from builtin_interfaces.msg import Time
from geometry_msgs.msg import Twist, TwistStamped
from nav_msgs.msg import Odometry
import pytest
import rclpy
from rclpy.experimental import EventsExecutor
from rclpy.parameter import Parameter
from sensor_msgs.msg import JointState
from std_msgs.msg import Header
from std_srvs.srv import Empty
from swivel_car_control.controller_node import ControllerNode
from swivel_car_control.odometry_node import OdometryNode
from swivel_car_msgs.msg import ActuatorCommand, SwivelCommand, SwivelControllerState
from swivel_car_msgs.srv import SetPose2D
from swivel_car_testing import next_domain_id, spin_until
from tf2_msgs.msg import TFMessage

JOINTS = ['swivel_joint', 'rear_left_wheel_joint', 'rear_right_wheel_joint',
          'front_left_wheel_joint', 'front_right_wheel_joint']


class Harness:
    """A node under test plus a probe node that publishes inputs and records outputs."""

    def __init__(self, node_class, parameters):
        os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
        args = ['--ros-args'] + [a for k, v in parameters.items() for a in ('-p', f'{k}:={v}')]
        rclpy.init(args=args, domain_id=next_domain_id())
        self.node = node_class()
        self.probe = rclpy.create_node('probe')
        self.executor = EventsExecutor()
        self.executor.add_node(self.node)
        self.executor.add_node(self.probe)
        self.received = {}

    def record(self, msg_type, topic):
        self.received[topic] = []
        self.probe.create_subscription(msg_type, topic, self.received[topic].append, 10)
        return self.received[topic]

    def wait_connected(self, publisher):
        spin_until(self.executor, lambda: publisher.get_subscription_count() > 0, 10.0,
                   'subscription')

    def close(self):
        self.executor.shutdown()
        self.probe.destroy_node()
        self.node.destroy_node()
        rclpy.try_shutdown()


def joint_state(t, swivel=0.0, swivel_rate=0.0, wheel_rate=0.0, names=JOINTS):
    msg = JointState()
    msg.header.stamp = Time(sec=int(t), nanosec=int(round((t - int(t)) * 1e9)))
    values = {'swivel_joint': (swivel, swivel_rate)}
    msg.name = list(names)
    msg.position = [values.get(n, (0.0, 0.0))[0] for n in names]
    msg.velocity = [values.get(n, (0.0, wheel_rate))[1] for n in names]
    return msg


@pytest.fixture
def controller():
    harness = Harness(ControllerNode, {'cmd_vel_timeout': 0.5})
    harness.record(ActuatorCommand, 'actuator_command')
    harness.record(SwivelControllerState, 'controller/controller_state')
    harness.record(TwistStamped, 'controller/cmd_vel_out')
    harness.joints = harness.probe.create_publisher(JointState, 'joint_states', 10)
    harness.cmd_vel = harness.probe.create_publisher(TwistStamped, 'cmd_vel', 10)
    harness.swivel = harness.probe.create_publisher(SwivelCommand, 'swivel_command', 10)
    for publisher in (harness.joints, harness.cmd_vel, harness.swivel):
        harness.wait_connected(publisher)
    spin_until(harness.executor, lambda: all(
        harness.probe.count_publishers(topic) for topic in harness.received), 10.0, 'publishers')
    yield harness
    harness.close()


def step(harness, t, **joint):
    """Publish joint_states at t; wait for the command stamped t (the lockstep contract)."""
    commands = harness.received['actuator_command']
    count = len(commands)
    harness.joints.publish(joint_state(t, **joint))
    spin_until(harness.executor, lambda: len(commands) > count, 10.0, f'command at {t}')
    command = commands[-1]
    assert command.header.stamp == joint_state(t).header.stamp
    return command


def send_cmd_vel(harness, v, omega, t):
    msg = TwistStamped()
    msg.header.stamp = joint_state(t).header.stamp
    msg.twist.linear.x = v
    msg.twist.angular.z = omega
    harness.cmd_vel.publish(msg)
    # Spin until the controller has it (nothing to observe but time): a few spins suffice.
    for _ in range(20):
        harness.executor.spin_once(timeout_sec=0.01)


def test_one_command_per_joint_state_with_its_stamp(controller):
    for k in range(5):
        command = step(controller, 1.0 + 0.01 * k, swivel=0.1)
        assert math.isfinite(command.swivel_torque)
    spin_until(controller.executor,
               lambda: len(controller.received['controller/controller_state']) >= 5, 10.0, 'state')
    state = controller.received['controller/controller_state'][-1]
    assert state.source == 'hold'
    assert state.measured == pytest.approx(0.1)
    assert state.set_point == pytest.approx(0.1)


def test_cmd_vel_drives_and_nan_is_rejected(controller):
    t = 1.0
    step(controller, t)
    send_cmd_vel(controller, 0.3, 0.0, t)
    for k in range(1, 50):
        command = step(controller, t + 0.01 * k)
    send_cmd_vel(controller, 0.3, 0.0, t + 0.45)
    assert command.drive_speed == pytest.approx(0.3 / 0.075)
    send_cmd_vel(controller, math.nan, 0.0, t + 0.49)
    for k in range(50, 60):
        command = step(controller, t + 0.01 * k)
    assert command.drive_speed == pytest.approx(0.3 / 0.075)
    spin_until(controller.executor,
               lambda: controller.received['controller/cmd_vel_out'], 10.0, 'cmd_vel_out')
    assert controller.received['controller/cmd_vel_out'][-1].twist.linear.x == pytest.approx(0.3)
    # The deadman: no new command for 0.5 s of joint_states time stops the drive.
    for k in range(60, 95):
        command = step(controller, t + 0.01 * k)
    assert command.drive_speed == pytest.approx(0.3 / 0.075)
    for k in range(100, 200):
        command = step(controller, t + 0.01 * k)
    assert command.drive_speed == 0.0


def test_turn_on_the_spot_command_steers_to_the_limit(controller):
    step(controller, 1.0)
    send_cmd_vel(controller, 0.0, 1.0, 1.0)
    states = controller.received['controller/controller_state']
    for k in range(1, 50):
        step(controller, 1.0 + 0.01 * k)
        spin_until(controller.executor, lambda: len(states) > k, 10.0, 'state')
        if states[-1].source == 'cmd_vel':
            break
    assert states[-1].source == 'cmd_vel'
    assert states[-1].target == pytest.approx(-1.4)  # left turn: negative swivel, phi > 0


def test_missing_swivel_joint_gives_a_safe_command(controller):
    step(controller, 1.0)
    send_cmd_vel(controller, 0.3, 0.0, 1.0)
    driving = step(controller, 1.01, swivel=0.1)  # the command before: not a safe one
    assert driving.swivel_torque != 0.0 and driving.drive_speed > 0.0
    commands = controller.received['actuator_command']
    controller.joints.publish(joint_state(1.02, names=['rear_left_wheel_joint']))
    spin_until(controller.executor, lambda: len(commands) > 2, 10.0, 'command')
    assert commands[-1].header.stamp == joint_state(1.02).header.stamp
    assert (commands[-1].swivel_torque, commands[-1].drive_speed) == (0.0, 0.0)


def test_swivel_command_and_refusal(controller):
    step(controller, 1.0)
    refused = SwivelCommand(angle=3.0, hold=True)
    controller.swivel.publish(refused)
    step(controller, 1.01)
    accepted = SwivelCommand(angle=0.5, max_rate=0.0, drive_speed=1.0, hold=True)
    controller.swivel.publish(accepted)
    states = controller.received['controller/controller_state']
    spin_until(controller.executor, lambda: states, 10.0, 'state')
    assert states[-1].source == 'hold'
    for k in range(2, 10):
        step(controller, 1.0 + 0.01 * k, swivel=0.5)
    spin_until(controller.executor,
               lambda: states[-1].source == 'swivel_command', 10.0, 'swivel_command source')
    assert states[-1].target == 0.5


def test_a_sim_reset_event_restarts_the_controller_from_the_state_after_it(controller):
    """
    Check a sim reset event restarts the controller from the state after it.

    Found by the soak: sim/reset put the car back with the swivel at 0; the controller went on
    holding the 0.5 rad it held before and turned the swivel back to it.
    """
    reset = controller.probe.create_publisher(Header, 'sim/reset_event', 10)
    controller.wait_connected(reset)
    step(controller, 1.0)
    command = stamped_swivel_command(1.0, 0.5)
    command.drive_speed = 1.0
    controller.swivel.publish(command)
    for k in range(1, 10):
        step(controller, 1.0 + 0.01 * k, swivel=0.5)
    controller.swivel.publish(SwivelCommand(hold=False))
    held = step(controller, 1.1, swivel=0.5)
    reset.publish(Header(stamp=joint_state(1.12).header.stamp, frame_id='world'))
    before = step(controller, 1.11, swivel=0.5)  # a state of the old world, still answered
    assert before.swivel_torque == held.swivel_torque
    states = controller.received['controller/controller_state']
    for k in range(12, 30):
        command = step(controller, 0.01 * k + 1.0)
        assert abs(command.swivel_torque) < 1e-9 and command.drive_speed == 0.0
    spin_until(controller.executor, lambda: states[-1].header.stamp == joint_state(1.29)
               .header.stamp, 10.0, 'the last state')
    assert states[-1].source == 'hold' and states[-1].target == 0.0
    assert states[-1].swivel_command_stamp == Time()  # the old world's command: forgotten


def stamped_swivel_command(t, angle, hold=True):
    msg = SwivelCommand(angle=angle, hold=hold)
    msg.header.stamp = joint_state(t).header.stamp
    return msg


class PlannerChain:
    """A controller chained to a planner (the probe's stamped swivel_command)."""

    def __init__(self, lockstep_wait):
        self.harness = harness = Harness(ControllerNode, {
            'lockstep_swivel_command': True, 'lockstep_wait': lockstep_wait})
        self.commands = harness.record(ActuatorCommand, 'actuator_command')
        self.states = harness.record(SwivelControllerState, 'controller/controller_state')
        harness.joints = harness.probe.create_publisher(JointState, 'joint_states', 10)
        self.swivel = harness.probe.create_publisher(SwivelCommand, 'swivel_command', 10)
        for publisher in (harness.joints, self.swivel):
            harness.wait_connected(publisher)
        spin_until(harness.executor, lambda: all(
            harness.probe.count_publishers(topic) for topic in harness.received), 10.0,
            'publishers')

    def state_of(self, t, timeout=10.0):
        stamp = joint_state(t).header.stamp
        states = self.states
        spin_until(self.harness.executor,
                   lambda: states and states[-1].header.stamp == stamp, timeout,
                   f'the state of {t}')
        return states[-1]

    def spin(self):
        """Spin long enough for a message to arrive, as nothing else shows it (0.2 s)."""
        for _ in range(20):
            self.harness.executor.spin_once(timeout_sec=0.01)


def test_lockstep_waits_for_the_planners_command_of_the_previous_state():
    chain = PlannerChain(lockstep_wait=3.0)  # never reached: the planner always answers
    harness, states = chain.harness, chain.states
    try:
        step(harness, 1.0)  # nothing held: no wait
        chain.swivel.publish(stamped_swivel_command(1.0, 0.3))
        chain.spin()  # the first command is taken whenever it comes
        step(harness, 1.01)
        state = chain.state_of(1.01)
        assert state.target == pytest.approx(0.3)
        # It says which command it heard: the planner's sign that the chain holds.
        assert state.swivel_command_stamp == joint_state(1.0).header.stamp

        # The command answering 1.01 has not come: 1.02 waits for it, then takes it.
        harness.joints.publish(joint_state(1.02))
        chain.spin()
        assert chain.commands[-1].header.stamp == joint_state(1.01).header.stamp
        chain.swivel.publish(stamped_swivel_command(1.01, 0.4))
        assert chain.state_of(1.02).target == pytest.approx(0.4)

        # A release ends the wait.
        harness.joints.publish(joint_state(1.03))
        chain.spin()
        assert states[-1].header.stamp == joint_state(1.02).header.stamp
        chain.swivel.publish(stamped_swivel_command(1.02, 0.0, hold=False))
        assert chain.state_of(1.03).source == 'hold'
        step(harness, 1.04)  # released: no wait

        # A command with a zero stamp (a hand-made one, not the planner's) is held without
        # any wait.
        chain.swivel.publish(SwivelCommand(angle=0.2, hold=True))
        chain.spin()
        for t in (1.05, 1.06):
            harness.joints.publish(joint_state(t))
            state = chain.state_of(t, 1.5)  # well within lockstep_wait: no wait
        assert state.target == pytest.approx(0.2)
        assert state.swivel_command_stamp == joint_state(1.02).header.stamp  # zero: not one
    finally:
        harness.close()


def test_a_state_republished_after_its_answer_gets_the_same_command_and_no_new_state():
    """
    The lockstep sim republishes a state whose answer is late; a copy crossing the answer.

    The planner's command for the next state may have come meanwhile: answered afresh, the
    copy published a second controller state of that moment (target 0.4 against 0.3), which
    the planner could tick on.
    """
    chain = PlannerChain(lockstep_wait=3.0)
    harness, states = chain.harness, chain.states
    try:
        step(harness, 1.0)
        chain.swivel.publish(stamped_swivel_command(1.0, 0.3))
        chain.spin()
        first = step(harness, 1.01, swivel=0.05)
        assert chain.state_of(1.01).target == pytest.approx(0.3)
        chain.swivel.publish(stamped_swivel_command(1.01, 0.4))  # the answer to 1.01
        chain.spin()
        again = step(harness, 1.01, swivel=0.05)  # the copy
        assert again.swivel_torque == first.swivel_torque
        assert again.drive_speed == first.drive_speed
        chain.spin()
        stamp = joint_state(1.01).header.stamp
        assert [s.target for s in states if s.header.stamp == stamp] == [pytest.approx(0.3)]
        step(harness, 1.02, swivel=0.05)  # the next state goes on
        assert chain.state_of(1.02).target == pytest.approx(0.4)
    finally:
        harness.close()


def test_after_lockstep_wait_the_controller_answers_without_the_planners_command():
    chain = PlannerChain(lockstep_wait=0.1)
    harness = chain.harness
    try:
        step(harness, 1.0)
        chain.swivel.publish(stamped_swivel_command(1.0, 0.3))
        chain.spin()
        step(harness, 1.01)
        # No answer to 1.01: 1.02 is answered after lockstep_wait, with the command in force.
        step(harness, 1.02)
        assert chain.state_of(1.02).target == pytest.approx(0.3)
        # The planner's next command is taken again (the wait it re-arms: test_lockstep.py).
        chain.swivel.publish(stamped_swivel_command(1.02, 0.5))
        chain.spin()
        harness.joints.publish(joint_state(1.03))
        assert chain.state_of(1.03).target == pytest.approx(0.5)
        assert chain.state_of(1.03).swivel_command_stamp == joint_state(1.02).header.stamp
    finally:
        harness.close()


def test_lockstep_cmd_vel_waits_for_the_drivers_cmd_vel_of_the_previous_state():
    harness = Harness(ControllerNode, {'lockstep_cmd_vel': True, 'lockstep_wait': 3.0})
    try:
        commands = harness.record(ActuatorCommand, 'actuator_command')
        harness.joints = harness.probe.create_publisher(JointState, 'joint_states', 10)
        harness.cmd_vel = harness.probe.create_publisher(TwistStamped, 'cmd_vel', 10)
        for publisher in (harness.joints, harness.cmd_vel):
            harness.wait_connected(publisher)
        spin_until(harness.executor, lambda: harness.probe.count_publishers('actuator_command'),
                   10.0, 'publishers')

        step(harness, 1.0)  # no driver yet: no wait
        send_cmd_vel(harness, 0.2, 0.0, 1.0)  # a cmd_vel answering 1.0: the driver is chained
        step(harness, 1.01)
        harness.joints.publish(joint_state(1.02))
        for _ in range(20):
            harness.executor.spin_once(timeout_sec=0.01)
        assert commands[-1].header.stamp == joint_state(1.01).header.stamp  # 1.02 waits
        send_cmd_vel(harness, 0.2, 0.0, 1.01)
        spin_until(harness.executor,
                   lambda: commands[-1].header.stamp == joint_state(1.02).header.stamp, 10.0,
                   'the answer to 1.02')

        # An unstamped cmd_vel (a teleop's) leaves the chain: 1.03 is answered at once.
        harness.cmd_vel.publish(TwistStamped())
        for _ in range(20):
            harness.executor.spin_once(timeout_sec=0.01)
        harness.joints.publish(joint_state(1.03))
        spin_until(harness.executor,
                   lambda: commands[-1].header.stamp == joint_state(1.03).header.stamp, 1.5,
                   'the answer to 1.03 well within lockstep_wait')
    finally:
        harness.close()


@pytest.mark.parametrize('wait', [0.0, -1.0, math.nan])
def test_bad_lockstep_wait_is_a_clear_error_at_start(wait):
    harness = None
    try:
        with pytest.raises(ValueError, match='lockstep_wait'):
            harness = Harness(ControllerNode, {'lockstep_wait': wait})
    finally:
        rclpy.try_shutdown()
    assert harness is None


def test_plain_twist_parameter():
    harness = Harness(ControllerNode, {'use_stamped': False, 'cmd_vel_timeout': 0.0})
    try:
        harness.record(ActuatorCommand, 'actuator_command')
        harness.joints = harness.probe.create_publisher(JointState, 'joint_states', 10)
        cmd_vel = harness.probe.create_publisher(Twist, 'cmd_vel', 10)
        for publisher in (harness.joints, cmd_vel):
            harness.wait_connected(publisher)
        spin_until(harness.executor, lambda: harness.probe.count_publishers(
            'actuator_command'), 10.0, 'publisher')
        step(harness, 1.0)
        twist = Twist()
        twist.linear.x = 0.2
        cmd_vel.publish(twist)
        for k in range(1, 100):
            command = step(harness, 1.0 + 0.01 * k)
            if command.drive_speed > 0.0:
                break
        assert command.drive_speed > 0.0
    finally:
        harness.close()


@pytest.fixture
def odometry():
    harness = Harness(OdometryNode, {'publish_rate': 100.0, 'tf_frame_prefix': 'robot1'})
    harness.record(Odometry, 'odom')
    harness.joints = harness.probe.create_publisher(JointState, 'joint_states', 10)
    harness.wait_connected(harness.joints)
    yield harness
    harness.close()


def feed(harness, t0, seconds, **joint):
    for k in range(int(round(seconds / 0.01)) + 1):
        harness.joints.publish(joint_state(t0 + 0.01 * k, **joint))
        harness.executor.spin_once(timeout_sec=0.005)
    spin_until(harness.executor, lambda: harness.received['odom'] and harness.received['odom'][
        -1].header.stamp == joint_state(t0 + seconds).header.stamp, 10.0, 'odom of last input')
    return harness.received['odom'][-1]


def call(harness, service_type, name, request):
    client = harness.probe.create_client(service_type, name)
    assert client.wait_for_service(timeout_sec=10.0)
    future = client.call_async(request)
    spin_until(harness.executor, future.done, 10.0, name)
    return future.result()


def test_odometry_straight_frames_reset_and_set_pose(odometry):
    odom = feed(odometry, 1.0, 1.0, wheel_rate=2.0)
    assert odom.header.frame_id == 'robot1/odom'
    assert odom.child_frame_id == 'robot1/base_link'
    assert odom.pose.pose.position.x == pytest.approx(2.0 * 0.075 * 1.0, rel=1e-6)
    assert odom.twist.twist.linear.x == pytest.approx(0.15)
    assert odom.pose.covariance[0] == 0.001
    call(odometry, Empty, 'odometry/reset', Empty.Request())
    odom = feed(odometry, 2.01, 0.5)
    assert odom.pose.pose.position.x == pytest.approx(0.0, abs=1e-9)
    response = call(odometry, SetPose2D, 'odometry/set_pose', SetPose2D.Request(
        x=1.0, y=2.0, yaw=math.pi / 2))
    assert response.success
    odom = feed(odometry, 2.52, 0.2)
    assert (odom.pose.pose.position.x, odom.pose.pose.position.y) == pytest.approx((1.0, 2.0))
    assert odom.pose.pose.orientation.z == pytest.approx(math.sin(math.pi / 4))
    bad = call(odometry, SetPose2D, 'odometry/set_pose', SetPose2D.Request(x=math.nan))
    assert not bad.success and 'finite' in bad.message
    odom = feed(odometry, 2.73, 0.1)
    assert odom.pose.pose.position.x == pytest.approx(1.0)


def test_odometry_tf_is_its_odom_pose_in_the_prefixed_frames(odometry):
    tf = odometry.record(TFMessage, '/tf')
    spin_until(odometry.executor, lambda: odometry.node.count_subscribers('/tf') > 0, 10.0,
               '/tf matched')
    odom = feed(odometry, 1.0, 1.0, wheel_rate=2.0, swivel=0.3)
    spin_until(odometry.executor, lambda: tf and tf[-1].transforms[0].header.stamp
               == odom.header.stamp, 10.0, '/tf of the last odom')
    (transform,) = tf[-1].transforms
    assert (transform.header.frame_id, transform.child_frame_id) == (
        'robot1/odom', 'robot1/base_link')
    p, q = transform.transform.translation, transform.transform.rotation
    pose = odom.pose.pose
    assert (p.x, p.y, p.z) == (pose.position.x, pose.position.y, pose.position.z)
    assert (q.x, q.y, q.z, q.w) == (pose.orientation.x, pose.orientation.y,
                                    pose.orientation.z, pose.orientation.w)
    assert pose.position.y != 0.0  # the swivel turned the car: every field was written


def test_odometry_covariances_set_live_reach_the_next_odom(odometry):
    assert feed(odometry, 1.0, 0.0).pose.covariance[0] == 0.001
    odometry.node.set_parameters([Parameter('pose_covariance_diagonal', value=[0.5] * 6)])
    odom = feed(odometry, 1.01, 0.0)
    assert (odom.pose.covariance[0], odom.pose.covariance[35]) == (0.5, 0.5)
    assert odom.twist.covariance[0] == 0.001


def test_odometry_without_velocities_differences_wrapped_positions(odometry):
    msgs = []
    for k in range(101):
        t = 1.0 + 0.01 * k
        angle = math.remainder(10.0 * (t - 1.0), 2 * math.pi)  # wraps at +-pi
        msg = joint_state(t)
        msg.position = [0.0, angle, angle, 0.0, 0.0]
        msg.velocity = []
        msgs.append(msg)
    for msg in msgs:
        odometry.joints.publish(msg)
        odometry.executor.spin_once(timeout_sec=0.005)
    spin_until(odometry.executor, lambda: odometry.received['odom'] and odometry.received[
        'odom'][-1].header.stamp == msgs[-1].header.stamp, 10.0, 'odom')
    assert odometry.received['odom'][-1].pose.pose.position.x == pytest.approx(
        9.9 * 0.075, rel=1e-6)  # the first message has nothing to difference against


def test_odometry_publishes_at_its_rate_by_joint_states_time():
    harness = Harness(OdometryNode, {'publish_rate': 40.0})
    try:
        odom = harness.record(Odometry, 'odom')
        harness.joints = harness.probe.create_publisher(JointState, 'joint_states', 10)
        harness.wait_connected(harness.joints)
        for k in range(101):
            harness.joints.publish(joint_state(1.0 + 0.01 * k, wheel_rate=1.0))
            # Every state must reach the node: the executor also delivers the odom.
            for _ in range(4):
                harness.executor.spin_once(timeout_sec=0.002)
        spin_until(harness.executor, lambda: odom and odom[-1].header.stamp == joint_state(
            2.0).header.stamp, 10.0, 'odom of the last state')
        stamps = [m.header.stamp.sec * 1000 + round(m.header.stamp.nanosec / 1e6)
                  for m in odom]  # [ms]
        # 40 Hz from 100 Hz states: every 2.5 states on average, each on a state's stamp.
        assert stamps[0] == 1000 and stamps[-1] == 2000
        assert len(stamps) == 41
        assert all(b - a in (20, 30) for a, b in zip(stamps, stamps[1:])), str(stamps)
    finally:
        harness.close()


def test_cmd_vel_out_is_in_the_base_frame_id():
    harness = Harness(ControllerNode, {'base_frame_id': 'robot1/base_link'})
    try:
        out = harness.record(TwistStamped, 'controller/cmd_vel_out')
        harness.joints = harness.probe.create_publisher(JointState, 'joint_states', 10)
        harness.cmd_vel = harness.probe.create_publisher(TwistStamped, 'cmd_vel', 10)
        harness.wait_connected(harness.joints)
        harness.wait_connected(harness.cmd_vel)
        send_cmd_vel(harness, 0.2, 0.0, 1.0)
        harness.joints.publish(joint_state(1.0))
        spin_until(harness.executor, lambda: out, 10.0, 'cmd_vel_out')
        assert out[-1].header.frame_id == 'robot1/base_link'
    finally:
        harness.close()


def test_an_empty_base_frame_id_is_refused_naming_it():
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=next_domain_id())
    try:
        with pytest.raises(ValueError, match='base_frame_id'):
            ControllerNode(context=context,
                           parameter_overrides=[Parameter('base_frame_id', value='')])
    finally:
        rclpy.try_shutdown(context=context)
