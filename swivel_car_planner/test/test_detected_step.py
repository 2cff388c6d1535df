"""climb_step on a detected step: the core (freshness, odometry, corrections) and the node."""

from dataclasses import replace
import math
import os

import pytest
import rclpy
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from swivel_car_msgs.msg import DetectedStep
from swivel_car_msgs.srv import ClimbStep
from swivel_car_perception.core.detector import Detection
from swivel_car_planner.core import ClimbRequest, ErrorCode
from swivel_car_planner.core.detected import DetectedSteps
from swivel_car_planner.core.geometry import Pose2D, StepEdge
from swivel_car_planner.planner_node import PlannerNode
from swivel_car_testing import next_domain_id, spin_until

FRONT_AXLE = 0.433  # [m]
TIMEOUT = 20.0  # [s] wall guard against a hang, not a measurement


def _step(distance=1.0, yaw=0.1, found=True, distance_std=0.002, yaw_std=0.004):
    return Detection(found, '', 0.05, distance, yaw, 1.2, 0.1, 0.5, 0.001, distance_std,
                     yaw_std, 0.01, True, True)


def test_a_fresh_detection_moved_to_the_present_pose():
    steps = DetectedSteps(FRONT_AXLE, max_age=0.5)
    steps.pose(10.0, 0.0, 0.0, 0.0)
    steps.heard(10.0, _step(yaw=0.0))
    steps.pose(10.3, 0.2, 0.0, 0.0)  # drove 0.2 m straight at the edge since
    request, why = steps.request(ClimbRequest(0.0, 0.0, 0.0, plan_only=True), now=10.4)
    assert why == '' and request.plan_only
    assert (request.step_height, request.step_width, request.step_offset) == \
        pytest.approx((0.05, 1.2, 0.1))
    assert request.step_distance == pytest.approx(0.8) and request.step_yaw == 0.0


def test_a_height_above_the_limit_within_its_uncertainty_is_the_limits():
    # An 8 cm step at the 8 cm limit read a fraction of a millimetre above it was refused as
    # unreachable in the detected climb benchmark, where the told step climbed.
    steps = DetectedSteps(FRONT_AXLE, max_age=0.5)
    steps.pose(10.0, 0.0, 0.0, 0.0)
    for height, taken in ((0.0803, 0.08), (0.0795, 0.0795), (0.0825, 0.0825)):
        steps.heard(10.0, replace(_step(), height=height))
        request, _ = steps.request(ClimbRequest(0.0, 0.0, 0.0), now=10.1, limit=0.08)
        assert request.step_height == pytest.approx(taken)  # beyond 2 sigma: refused later
    request, _ = steps.request(ClimbRequest(0.0, 0.0, 0.0), now=10.1)  # no limit: as read
    assert request.step_height == pytest.approx(0.0825)


def test_an_end_not_seen_bounds_the_face_where_it_was_seen():
    # The face was taken to reach 2 m past an end not seen, and as of unknown width (held
    # heading, no side limit) with neither end seen: a 7 cm step 0.26 m ahead, 1.1 m wide
    # (0.91 m seen) was climbed straight and a wheel fell off its side (rolled 0.24 rad),
    # where the told climb repositioned to cross within the face.
    steps = DetectedSteps(FRONT_AXLE, max_age=0.5)
    steps.pose(10.0, 0.0, 0.0, 0.0)
    one_end = replace(_step(yaw=0.0), right_end_seen=False)  # seen from -0.5 to 0.7 m
    for detection in (one_end, replace(one_end, left_end_seen=False)):
        steps.heard(10.0, detection)
        request, _ = steps.request(ClimbRequest(0.0, 0.0, 0.0), now=10.1)
        assert (request.step_width, request.step_offset) == pytest.approx((1.2, 0.1))


@pytest.mark.parametrize('setup, words', [
    (lambda s: None, 'no detected_step heard'),
    (lambda s: (s.pose(10.0, 0, 0, 0), s.heard(10.0, _step())), '0.60 s old'),
    (lambda s: (s.pose(10.5, 0, 0, 0), s.heard(10.5, _step(found=False))), 'sees no step'),
    (lambda s: s.heard(10.5, _step()), 'no odometry')])
def test_no_fresh_detection_is_refused_with_the_reason(setup, words):
    steps = DetectedSteps(FRONT_AXLE, max_age=0.5)
    setup(steps)
    request, why = steps.request(ClimbRequest(0.0, 0.0, 0.0), now=10.6)
    assert request is None and words in why and '\n' not in why


def test_the_approach_follows_a_detection_beyond_its_uncertainty_once():
    steps = DetectedSteps(FRONT_AXLE, max_age=0.5)
    planned = StepEdge.from_request(Pose2D(0.0, 0.0, 0.0), FRONT_AXLE, 1.0, 0.1)
    steps.pose(1.0, 0.0, 0.0, 0.0)
    steps.heard(1.0, _step(distance=1.0))
    steps.request(ClimbRequest(0.0, 0.0, 0.0), now=1.0)  # the climb's step: 5 cm high
    steps.heard(1.0, _step(distance=1.003))  # 3 mm: within 2 sigma of 2 mm
    assert steps.correction(planned, 1.1) is None
    steps.heard(1.1, _step(distance=1.03))  # 3 cm further: beyond
    steps.pose(1.1, 0.0, 0.0, 0.0)
    moved = steps.correction(planned, 1.2)
    assert moved.normal_yaw == pytest.approx(0.1)
    assert planned.signed_distance(moved.px, moved.py) == pytest.approx(0.03 * math.cos(0.1))
    # The old point dropped onto the new line: the plan's crossing keeps its place.
    assert planned.along(moved.px, moved.py) == pytest.approx(0.0, abs=1e-12)
    assert steps.correction(moved, 1.2) is None  # used once
    steps.heard(1.2, _step(distance=0.3))  # 0.7 m off, but where the front wheels hide it
    steps.pose(1.2, 0.0, 0.0, 0.0)
    assert steps.correction(moved, 1.2) is None
    for stamp, misread in ((1.3, _step(distance=1.2)), (1.4, _step(yaw=0.3)),
                           (1.5, replace(_step(distance=1.05), height=0.02))):
        steps.pose(stamp, 0.0, 0.0, 0.0)
        steps.heard(stamp, misread)  # 17 cm, 0.2 rad off, or 3 cm lower: a misreading
        assert steps.correction(moved, stamp) is None


def test_the_planner_node_refuses_use_detected_step_without_a_detector():
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=next_domain_id())
    namespace = f'/detected_test_{os.getpid()}'
    planner = PlannerNode(context=context, namespace=namespace)
    client_node = Node('client', namespace=namespace, context=context)
    executor = EventsExecutor(context=context)
    executor.add_node(planner)
    executor.add_node(client_node)
    try:
        client = client_node.create_client(ClimbStep, 'climb_step')
        spin_until(executor, client.service_is_ready, TIMEOUT, 'climb_step')

        def call():
            future = client.call_async(ClimbStep.Request(
                use_detected_step=True, plan_only=True, step_height=0.04, step_distance=1.0))
            spin_until(executor, future.done, TIMEOUT, 'climb_step response')
            return future.result()

        down = call()
        assert down.error_code == ClimbStep.Response.ERROR_NO_STEP_DETECTED
        assert not down.success and 'step detector' in down.message
        publisher = client_node.create_publisher(DetectedStep, 'detected_step', 10)
        spin_until(executor, lambda: publisher.get_subscription_count() > 0, TIMEOUT,
                   'discovery')
        flat = DetectedStep(found=False)
        flat.header.stamp = planner.get_clock().now().to_msg()
        publisher.publish(flat)
        spin_until(executor, lambda: planner._detected.fresh(math.inf)[1].startswith(
            'the last'), TIMEOUT, 'detected_step heard')
        nothing = call()
        assert nothing.error_code == ErrorCode.NO_STEP_DETECTED
        assert 'sees no step' in nothing.message
    finally:
        executor.shutdown()
        planner.destroy_node()
        client_node.destroy_node()
        rclpy.try_shutdown(context=context)
