"""
System tests: the sim, controller, odometry and planner nodes as real processes.

sim_node (lockstep), controller_node, odometry_node and planner_node; the climb is judged by
the sim's ground truth.
"""

import math

from action_msgs.msg import GoalStatus
import pytest
from sim_session import SimSession
from swivel_car_msgs.action import ClimbStep as ClimbStepAction
from swivel_car_msgs.srv import ClimbStep
from swivel_car_planner.core import ErrorCode, Phase
from swivel_car_stack import process_report

HEIGHT = 0.04  # [m] within the rear axle's traction limit (README: measured limits)
DISTANCE = 1.2  # [m]
RUN_STEPS = 25  # [1] physics steps the cancel test runs at a time: 5 control periods


@pytest.fixture(scope='module')
def session():
    session = SimSession()
    try:
        session.wait_ready()
        yield session
    finally:
        crashed = session.close()
    assert not crashed, crashed


@pytest.fixture
def stack(session):
    session.reset()
    return session


def test_feasible_step_is_climbed_with_all_four_wheels_on_top(stack):
    # 0.3 m ahead, square, a 1 m face: no room to turn onto the approach, and backing up
    # straight the car would cross the edge beside the face. It repositions first.
    distance, width = 0.3, 1.0  # [m]
    stack.spawn_step(HEIGHT, distance, width=width)
    response = stack.climb(HEIGHT, distance, width=width)
    assert response.success, response.message
    assert response.error_code == ClimbStep.Response.ERROR_NONE
    stack.settle(0.5)
    assert stack.four_wheels_on_top(HEIGHT), stack.truth
    assert response.plan.swivel_angle != 0.0
    assert len(response.plan.reposition_length) >= 3
    assert 0.0 < response.outcome.peak_torque
    assert response.outcome.distance_travelled > distance + sum(
        abs(length) for length in response.plan.reposition_length)
    # Released: the controller takes cmd_vel again.
    assert stack.controller_state.source != 'swivel_command'


@pytest.mark.parametrize('height, code', [
    (0.5, ClimbStep.Response.ERROR_UNREACHABLE_HEIGHT),  # beyond the lifted wheel's reach
    (0.09, ClimbStep.Response.ERROR_UNREACHABLE_HEIGHT),  # beyond the rear axle's traction
    (-0.02, ClimbStep.Response.ERROR_INVALID_REQUEST)])
def test_infeasible_step_is_refused_without_motion(stack, height, code):
    if height > 0.0:
        stack.spawn_step(height, DISTANCE)
    before = stack.truth
    response = stack.climb(height, DISTANCE)
    assert not response.success
    assert response.error_code == code, response.message
    stack.settle(1.0)
    after = stack.truth
    assert math.hypot(after.x - before.x, after.y - before.y) < 0.002
    assert after.speed < 0.01


def test_second_goal_is_refused_and_cancel_stops_the_car_safely(stack):
    stack.spawn_step(HEIGHT, DISTANCE)
    feedback = []

    def run_until(phase: Phase) -> None:
        # A few control periods at a time, each ending paused: the cancel lands while the
        # wheel is up however fast the sim runs (pausing on seeing the phase came too late
        # once the chain ran through the advance before the pause). A climb that ends on the
        # way (its result arrives) fails here with the planner's reason and the nodes' output.
        for _ in range(2000):  # 100 s of sim time; ADVANCE comes after about 9
            if feedback and feedback[-1].phase >= phase:
                return
            if result.done():
                ended = result.result()
                raise AssertionError(
                    f'the climb ended before {phase.name} (status {ended.status}): '
                    f'{ended.result.message}\n{process_report(stack.processes, 4000)}')
            stack.run(RUN_STEPS)
        raise AssertionError(f'no {phase.name} within 2000 runs: {feedback[-1:]}\n'
                             f'{process_report(stack.processes, 4000)}')

    stack.set_paused(True)
    goal = ClimbStepAction.Goal(step_height=HEIGHT, step_distance=DISTANCE)
    sent = stack.climb_action.send_goal_async(
        goal, feedback_callback=lambda msg: feedback.append(msg.feedback))
    stack.spin_until(sent.done, 30.0, 'goal response')
    handle = sent.result()
    assert handle.accepted
    result = handle.get_result_async()
    run_until(Phase.LIFT)
    # A second goal and a service call meanwhile: both refused, the climb goes on.
    second = stack.climb_action.send_goal_async(goal)
    stack.spin_until(second.done, 30.0, 'second goal response')
    assert not second.result().accepted
    busy = stack.climb(HEIGHT, DISTANCE)
    assert busy.error_code == ClimbStep.Response.ERROR_BUSY
    run_until(Phase.ADVANCE)
    assert feedback[-1].phase == Phase.ADVANCE
    cancel = handle.cancel_goal_async()
    stack.spin_until(cancel.done, 30.0, 'the cancel response')
    stack.set_paused(False)
    stack.spin_until(result.done, 60.0, 'the canceled result')
    assert cancel.done()
    assert result.result().status == GoalStatus.STATUS_CANCELED, result.result().result.message
    assert result.result().result.error_code == ErrorCode.CANCELED
    # States from before the release may still be queued here (out of the chain, the sim races
    # this node): the hold starts with the first state that says so.
    stack.spin_until(lambda: stack.controller_state.source == 'hold', 30.0, 'the hold')
    held = stack.controller_state
    stack.settle(1.0)
    truth = stack.truth
    assert truth.speed < 0.02  # stopped
    state = stack.controller_state
    # Released after the failure: the controller holds the swivel, cmd_vel may steer again.
    assert state.source == 'hold' and state.drive_speed == pytest.approx(0.0)
    assert state.target == pytest.approx(held.target, abs=0.05)  # swivel held
    assert abs(state.measured) > 0.1  # still holding the wheel up, not dropped
