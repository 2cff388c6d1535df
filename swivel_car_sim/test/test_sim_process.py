"""The installed sim_node executable as its own process, as `ros2 run` starts it."""

import os

import rclpy
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from swivel_car_msgs.msg import ActuatorCommand
from swivel_car_msgs.srv import StepSimulation
from swivel_car_testing import next_domain_id, NodeProcess, spin_until

TIMEOUT = 30.0  # [s] wall guard against a hang


def test_installed_sim_node_runs_lockstep_with_a_controller_and_exits_cleanly():
    # A namespace of its own: other test runs on this machine may share the ROS domain.
    namespace = f'/sim_process_test_{os.getpid()}'
    domain = next_domain_id()
    sim = NodeProcess('swivel_car_sim', 'sim_node', domain,
                      parameters={'lockstep': True, 'lockstep_timeout': 0.0},
                      extra_args=['--ros-args', '-r', f'__ns:={namespace}'])
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=domain)
    node = Node('fake_controller', namespace=namespace, context=context)
    executor = EventsExecutor(context=context)
    executor.add_node(node)
    try:
        commands = node.create_publisher(ActuatorCommand, 'actuator_command', 10)
        states, clock = [], []

        def answer(msg: JointState) -> None:
            states.append(msg)
            command = ActuatorCommand(drive_speed=4.0)
            command.header.stamp = msg.header.stamp
            commands.publish(command)
        node.create_subscription(JointState, 'joint_states', answer, 10)
        node.create_subscription(Clock, '/clock', clock.append, 10)  # global, may be shared
        # (the first state may come twice: it is republished until answered)
        spin_until(executor, lambda: states and states[-1].header.stamp.sec >= 1, TIMEOUT,
                   f'100 lockstep periods; sim output:\n{sim.output()}')
        stamps = [m.header.stamp.sec * 10 ** 9 + m.header.stamp.nanosec for m in states]
        assert sorted(set(stamps)) == [i * 10_000_000 for i in range(101)]
        assert states[-1].velocity[1] > 1.0
        assert clock

        step = node.create_client(StepSimulation, 'sim/step')
        spin_until(executor, step.service_is_ready, TIMEOUT, 'sim/step')
        future = step.call_async(StepSimulation.Request(steps=0))
        spin_until(executor, future.done, TIMEOUT, 'step response')
        assert not future.result().success
        assert sim.running()
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown(context=context)
        code = sim.stop()
    assert code == 0, sim.output()


def test_installed_sim_node_refuses_bad_parameters_with_a_message():
    sim = NodeProcess('swivel_car_sim', 'sim_node', next_domain_id(),
                      parameters={'control_period': 0.003})
    try:
        assert sim.process.wait(TIMEOUT) == 1
    finally:
        sim.stop()
    assert 'control_period (0.003) must be a whole multiple' in sim.output()
