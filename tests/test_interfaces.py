"""
Every swivel_car_msgs interface through real rclpy in this process.

Each message published and received, each service called and answered, the action goal with
feedback and result.
"""

from __future__ import annotations

import math

import pytest
from rclpy.action import ActionClient, ActionServer
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from swivel_car_msgs import action, msg, srv
from swivel_car_testing import spin_until

MESSAGE_TYPES = [msg.ActuatorCommand, msg.SwivelCommand, msg.SwivelControllerState,
                 msg.StepObstacle, msg.ClimbPlan, msg.ClimbOutcome, msg.DetectedStep]
SERVICE_TYPES = [srv.ClimbStep, srv.SpawnObstacle, srv.RemoveObstacle, srv.ResetSimulation,
                 srv.StepSimulation, srv.SetPose2D]


def _filled(message):
    """``message`` with every float field set to a distinct value, strings and bools set."""
    for index, (name, kind) in enumerate(message.get_fields_and_field_types().items()):
        if kind == 'double':
            setattr(message, name, 0.5 + index)
        elif kind == 'string':
            setattr(message, name, f'{name}-{index}')
        elif kind == 'boolean':
            setattr(message, name, True)
        elif kind in ('uint8', 'uint32'):
            setattr(message, name, 1)
    return message


@pytest.fixture
def node_and_executor(ros_domain):
    _, context = ros_domain
    node = Node('interface_test', context=context)
    executor = EventsExecutor(context=context)
    executor.add_node(node)
    yield node, executor
    executor.shutdown()
    node.destroy_node()


@pytest.mark.parametrize('message_type', MESSAGE_TYPES, ids=lambda t: t.__name__)
def test_message_round_trip(node_and_executor, message_type):
    node, executor = node_and_executor
    received = []
    node.create_subscription(message_type, 'roundtrip', received.append, 10)
    publisher = node.create_publisher(message_type, 'roundtrip', 10)
    sent = _filled(message_type())
    spin_until(executor, lambda: publisher.get_subscription_count() > 0, 10.0, 'discovery')
    publisher.publish(sent)
    spin_until(executor, lambda: received, 10.0, f'{message_type.__name__}')
    assert received[0] == sent


@pytest.mark.parametrize('service_type', SERVICE_TYPES, ids=lambda t: t.__name__)
def test_service_round_trip(node_and_executor, service_type):
    node, executor = node_and_executor
    requests = []

    def serve(request, response):
        requests.append(request)
        response.success = True
        response.message = 'served'
        return response

    node.create_service(service_type, 'roundtrip', serve)
    client = node.create_client(service_type, 'roundtrip')
    spin_until(executor, client.service_is_ready, 10.0, 'service')
    request = _filled(service_type.Request())
    future = client.call_async(request)
    spin_until(executor, future.done, 10.0, f'{service_type.__name__} response')
    assert requests == [request]
    assert future.result().success and future.result().message == 'served'


def test_climb_step_action_goal_feedback_result(node_and_executor):
    node, executor = node_and_executor
    Climb = action.ClimbStep

    def execute(goal_handle):
        for progress in (0.25, 0.5, 1.0):
            feedback = Climb.Feedback(phase=Climb.Feedback.PHASE_LIFT, phase_name='lift',
                                      progress=progress, swivel_angle=0.3)
            goal_handle.publish_feedback(feedback)
        goal_handle.succeed()
        result = Climb.Result(success=True, error_code=srv.ClimbStep.Response.ERROR_NONE)
        result.plan.swivel_angle = goal_handle.request.step_height
        return result

    ActionServer(node, Climb, 'climb', execute_callback=execute)
    client = ActionClient(node, Climb, 'climb')
    spin_until(executor, client.server_is_ready, 10.0, 'action server')
    feedback = []
    send = client.send_goal_async(Climb.Goal(step_height=0.1, step_distance=0.2),
                                  feedback_callback=lambda f: feedback.append(f.feedback))
    spin_until(executor, send.done, 10.0, 'goal acceptance')
    assert send.result().accepted
    result_future = send.result().get_result_async()
    spin_until(executor, result_future.done, 10.0, 'result')
    result = result_future.result().result
    assert result.success and math.isclose(result.plan.swivel_angle, 0.1)
    spin_until(executor, lambda: len(feedback) == 3, 10.0, 'feedback')
    assert [f.progress for f in feedback] == [0.25, 0.5, 1.0]


def test_interface_constants_are_distinct():
    codes = [value for name, value in vars(srv.ClimbStep.Response).items()
             if name.startswith('ERROR_')]
    assert len(codes) == len(set(codes)) == 15
    phases = [value for name, value in vars(action.ClimbStep.Feedback).items()
              if name.startswith('PHASE_')]
    assert len(phases) == len(set(phases))
