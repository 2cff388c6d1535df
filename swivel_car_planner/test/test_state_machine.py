"""
Unit tests of the climb state machine against a kinematic car on flat ground.

``KinematicCar`` (no step, no physics) checks the sequencing, the geometry of the phase
changes and every monitor; the real physics is in the system tests.
"""

import dataclasses
import math

from kinematic_car import KinematicCar
import pytest
from swivel_car_model.params import SwivelCarParams
from swivel_car_planner.core import (
    ClimbRequest, ClimbStateMachine, Command, ErrorCode, make_plan, Phase, PlannerConfig)
from swivel_car_planner.core import steps
from swivel_car_planner.core.geometry import Pose2D, StepEdge
from swivel_car_planner.core.state_machine import Step

P = SwivelCarParams()
CONFIG = PlannerConfig()


def start(height=0.04, distance=1.2, yaw=0.0, config=CONFIG, allowance=0.0):
    request = ClimbRequest(height, distance, yaw, time_allowance=allowance)
    plan = make_plan(P, config, request)
    return ClimbStateMachine(P, config, plan, distance, yaw, allowance), plan


def car_before(height=0.04, distance=1.2, yaw=0.0):
    """
    Make a car with the step of ``start``'s request placed.

    It pitches while only its front axle is on top.
    """
    car = KinematicCar()
    car.place_step(height, distance, yaw)
    return car


def run(machine, car, seconds=120.0, until=None):
    """Run until the outcome (or ``until(machine, car)``); returns the phases seen."""
    phases = []
    while machine.outcome is None and car.time < seconds:
        if until is not None and until(machine, car):
            break
        car.apply(machine.update(car.observe()))
        if not phases or phases[-1] != machine.feedback.phase:
            phases.append(machine.feedback.phase)
    return phases


@pytest.mark.parametrize('yaw', [0.0, 0.3, -0.4])
def test_climb_goes_through_every_phase_and_ends_with_all_wheels_past_the_edge(yaw):
    machine, plan = start(yaw=yaw)
    car = car_before(yaw=yaw)
    phases = run(machine, car)
    assert machine.outcome.success, machine.outcome.message
    assert phases == [Phase.APPROACH, Phase.LIFT, Phase.ADVANCE, Phase.SET_DOWN,
                      Phase.CLIMB_REST, Phase.DONE]
    edge = StepEdge.from_request(Pose2D(0.0, 0.0, 0.0), P.wheelbase, 1.2, yaw)
    pose = Pose2D(car.odometry.x, car.odometry.y, car.odometry.yaw)
    for side in (1.0, -1.0):
        assert edge.signed_distance(*pose.transform(0.0, side * P.h)) >= CONFIG.rest_margin
    assert car.commands[-1] == Command(0.0, 0.0, 0.0, False)  # swivel back to cmd_vel
    assert machine.feedback.progress == 1.0
    assert machine.outcome.distance_travelled > 1.2
    assert machine.outcome.peak_torque >= 10.0 * abs(plan.swivel_angle) - 0.1
    assert machine.outcome.energy > 0.0


def test_a_step_too_close_to_turn_backs_up_straight_then_approaches():
    machine, plan = start(distance=0.25)
    assert plan.backup_distance > 0.0
    car = KinematicCar()
    run(machine, car, until=lambda m, c: c.commands and m.step == Step.APPROACH)
    assert machine.step == Step.APPROACH
    assert car.odometry.x <= -plan.backup_distance + 1e-9  # straight back along x
    assert abs(car.odometry.y) < 0.01
    assert all(c.drive_speed < 0.0 and c.angle == 0.0 for c in car.commands[:-1])
    run(machine, car, until=lambda m, c: m.phase == Phase.LIFT)
    assert machine.outcome is None and machine.phase == Phase.LIFT


def test_the_climb_ends_only_once_the_car_stands_on_top():
    machine, _ = start()
    car = car_before()
    run(machine, car, until=lambda m, c: m.step == Step.STOP_ON_TOP)
    assert machine.outcome is None
    assert car.commands[-1].drive_speed == 0.0 and car.commands[-1].hold
    speeds = []
    run(machine, car, until=lambda m, c: speeds.append(c.observe().speed))
    assert machine.outcome.success
    assert abs(speeds[-1]) <= CONFIG.stop_speed
    assert car.commands[-2].drive_speed == 0.0 and car.commands[-2].hold


def test_a_car_still_tipping_when_its_wheels_stop_is_not_called_on_top():
    # As in the sim on 0.09 m steps: a rear wheel rides up onto the riser's corner and rolls
    # back; odometry (its wheel spinning) puts it 0.2 m past the edge, and the wheels stop just
    # as the rocking car passes level (roll 0.03 rad); the IMU then shows it rolling on at
    # 0.4 rad/s to 0.13 rad, where it comes to rest on the corner.
    machine, _ = start()
    car = car_before()
    run(machine, car, until=lambda m, c: m.step == Step.STOP_ON_TOP)
    stopped = None
    while machine.outcome is None and car.time < 120.0:
        if stopped is None and abs(car.speed) <= CONFIG.stop_speed:
            stopped = car.time
        since = 0.0 if stopped is None else car.time - stopped
        car.roll = min(0.13, 0.03 + 0.4 * since)
        car.apply(machine.update(car.observe()))
    assert_safe_abort(machine, car, ErrorCode.FAILED)
    assert 'rolled 0.130 rad' in machine.outcome.message
    assert 'not on top' in machine.outcome.message


def test_wheels_spinning_against_the_riser_are_not_a_climb():
    # As in the sim at 24-26 cm (the front never up): the car stays level while odometry
    # counts the spinning wheels as travel past the edge.
    machine, _ = start()
    car = KinematicCar()  # no step: level all the way
    run(machine, car)
    assert_safe_abort(machine, car, ErrorCode.FAILED)
    assert 'front wheels never got on top' in machine.outcome.message


def test_lift_starts_at_the_planned_distance_and_heading():
    machine, plan = start(yaw=0.2)
    car = KinematicCar()
    run(machine, car, until=lambda m, c: m.phase == Phase.LIFT)
    edge = StepEdge.from_request(Pose2D(0.0, 0.0, 0.0), P.wheelbase, 1.2, 0.2)
    pose = Pose2D(car.odometry.x, car.odometry.y, car.odometry.yaw)
    lifted = edge.signed_distance(*pose.transform(P.wheelbase, plan.lifted_side * P.h))
    assert lifted == pytest.approx(-plan.lead_distance, abs=0.01)
    assert edge.relative_heading(car.odometry.yaw) == pytest.approx(
        plan.approach_heading, abs=CONFIG.align_tolerance)


def test_lifted_wheel_is_over_the_edge_when_it_is_set_down():
    machine, plan = start()
    car = KinematicCar()
    run(machine, car, until=lambda m, c: m.phase == Phase.SET_DOWN)
    edge = StepEdge.from_request(Pose2D(0.0, 0.0, 0.0), P.wheelbase, 1.2, 0.0)
    pose = Pose2D(car.odometry.x, car.odometry.y, car.odometry.yaw)
    assert edge.signed_distance(
        *pose.transform(P.wheelbase, plan.lifted_side * P.h)) >= CONFIG.lead_margin
    assert edge.signed_distance(
        *pose.transform(P.wheelbase, -plan.lifted_side * P.h)) < 0.0
    assert car.swivel == pytest.approx(plan.swivel_angle, abs=CONFIG.swivel_tolerance)


def test_a_push_lift_leads_with_the_grounded_wheel_and_drives_while_it_sets_down():
    machine, plan = start(height=0.27, distance=2.0)
    assert plan.push_lift
    car = KinematicCar()
    edge = StepEdge.from_request(Pose2D(0.0, 0.0, 0.0), P.wheelbase, 2.0, 0.0)

    def past_edge(bx, by):
        pose = Pose2D(car.odometry.x, car.odometry.y, car.odometry.yaw)
        return edge.signed_distance(*pose.transform(bx, by))

    run(machine, car, until=lambda m, c: m.phase == Phase.LIFT)
    lifted = past_edge(P.wheelbase, plan.lifted_side * P.h)
    assert lifted == pytest.approx(-plan.lead_distance, abs=0.01)
    assert past_edge(P.wheelbase, -plan.lifted_side * P.h) > lifted + 0.1  # grounded leads
    run(machine, car, until=lambda m, c: m.phase == Phase.SET_DOWN)
    assert CONFIG.push_margin <= past_edge(*plan.lifted_point) < CONFIG.push_margin + 0.01
    first = len(car.commands)
    run(machine, car, until=lambda m, c: m.step != Step.SET_DOWN)
    set_down = car.commands[first:-1]
    assert set_down and all(c.drive_speed == CONFIG.set_down_speed for c in set_down)
    angles = [plan.swivel_angle] + [c.angle for c in set_down]
    steps = [plan.lifted_side * (b - a) for a, b in zip(angles, angles[1:])]
    assert all(-CONFIG.swivel_rate * 0.01 - 1e-9 <= s <= 1e-9 for s in steps)  # a ramp
    assert machine.outcome is None


def test_outer_loop_reaches_the_wanted_angles_when_the_swivel_sags_under_load():
    machine, plan = start()
    car = car_before()
    car.sag = 0.15
    run(machine, car, until=lambda m, c: m.phase == Phase.ADVANCE)
    assert car.swivel == pytest.approx(plan.swivel_angle, abs=CONFIG.swivel_tolerance)
    assert car.commands[-1].angle > plan.swivel_angle + 0.1
    run(machine, car)
    assert machine.outcome.success, machine.outcome.message


def test_rear_axle_that_does_not_climb_ends_failed_and_stopped():
    machine, _ = start()
    car = KinematicCar()
    run(machine, car, until=lambda m, c: m.step == Step.REAR)
    car.extra_pitch = -0.1  # front on the step, rear still below: nose up
    run(machine, car)
    assert_safe_abort(machine, car, ErrorCode.FAILED)
    assert 'rear axle' in machine.outcome.message


def test_the_rear_axle_climbs_with_the_swivel_free_and_stops_held():
    machine, _ = start()
    car = car_before()
    run(machine, car, until=lambda m, c: m.step == Step.REAR)
    run(machine, car, until=lambda m, c: m.step != Step.REAR)
    rear = [c for c in car.commands if c.free]
    assert rear and all(c.hold and c.drive_speed == CONFIG.rear_speed for c in rear)
    assert not any(c.free for c in car.commands[:car.commands.index(rear[0])])
    run(machine, car)
    assert machine.outcome.success and not car.commands[-1].free


def in_the_rear_step_with_the_front_up() -> tuple[ClimbStateMachine, KinematicCar]:
    machine, _ = start()
    car = KinematicCar()
    run(machine, car, until=lambda m, c: m.step == Step.REAR)
    car.extra_pitch = -0.1  # front on the step
    car.apply(machine.update(car.observe()))
    return machine, car


def test_front_coming_down_before_the_rear_reaches_the_edge_ends_failed():
    machine, car = in_the_rear_step_with_the_front_up()
    car.extra_pitch = 0.0  # level again, the rear wheels still well before the edge
    car.apply(machine.update(car.observe()))
    assert_safe_abort(machine, car, ErrorCode.FAILED)
    assert 'came down' in machine.outcome.message


def test_a_level_car_whose_odometry_lags_the_climbing_rear_is_not_taken_for_a_fall():
    # Measured (2-3 cm steps, all four wheels on top by ground truth): level again while
    # odometry still put the trailing rear wheel 0.08 m short of the edge.
    machine, car = in_the_rear_step_with_the_front_up()
    edge = StepEdge.from_request(Pose2D(0.0, 0.0, 0.0), P.wheelbase, 1.2, 0.0)

    def trailing_rear(c):
        pose = Pose2D(c.odometry.x, c.odometry.y, c.odometry.yaw)
        return min(edge.signed_distance(*pose.transform(0.0, side * P.h))
                   for side in (1.0, -1.0))

    run(machine, car, until=lambda m, c: trailing_rear(c) >= -(P.r + 0.08))
    car.extra_pitch = 0.0
    car.apply(machine.update(car.observe()))
    assert machine.outcome is None and machine.step == Step.REAR


def test_one_rear_wheel_up_is_not_taken_for_the_front_coming_down():
    # Measured in the sim: with one rear wheel on a 4 cm step the pitch halves, the car
    # rolls 0.13 rad, and odometry still puts the rear axle 0.08 m short of the edge.
    machine, car = in_the_rear_step_with_the_front_up()
    car.extra_pitch, car.roll = 0.0, 0.13
    car.apply(machine.update(car.observe()))
    assert machine.outcome is None and machine.step == Step.REAR
    car.roll = 0.0  # level and not rolled: the front came down after all
    car.apply(machine.update(car.observe()))
    assert_safe_abort(machine, car, ErrorCode.FAILED)
    assert 'came down' in machine.outcome.message


def test_progress_never_goes_back():
    machine, _ = start()
    car = KinematicCar()
    progress = []
    while machine.outcome is None:
        car.apply(machine.update(car.observe()))
        progress.append(machine.feedback.progress)
    assert all(b >= a - 0.02 for a, b in zip(progress, progress[1:]))


def assert_safe_abort(machine, car, code):
    assert machine.outcome is not None and not machine.outcome.success
    assert machine.outcome.error_code == code, machine.outcome.message
    assert machine.feedback.phase == Phase.ABORTING
    final = car.commands[-1]
    assert final.drive_speed == 0.0 and final.hold and not final.free
    assert final.angle == pytest.approx(car.swivel)
    # Further updates keep the car stopped and the swivel held.
    assert machine.update(car.observe()) == final


def test_abort_between_observations_holds_the_swivel_where_last_seen():
    machine, _ = start()
    assert machine.abort(ErrorCode.NOT_READY, 'inputs stopped') is None
    assert machine.outcome.error_code == ErrorCode.NOT_READY and not machine.outcome.success

    machine, _ = start()
    car = KinematicCar()
    run(machine, car, until=lambda m, c: m.step == Step.ADVANCE)
    machine.update(car.observe())  # the last observation before the inputs stop
    command = machine.abort(ErrorCode.NOT_READY, 'inputs stopped')
    car.apply(command)
    assert_safe_abort(machine, car, ErrorCode.NOT_READY)
    assert machine.outcome.duration > 0.0


def test_cancel_stops_the_drive_and_holds_the_swivel():
    machine, _ = start()
    car = KinematicCar()
    run(machine, car, until=lambda m, c: m.phase == Phase.LIFT and abs(c.swivel) > 0.1)
    machine.cancel()
    car.apply(machine.update(car.observe()))
    assert_safe_abort(machine, car, ErrorCode.CANCELED)


def test_stuck_swivel_is_a_stall():
    machine, _ = start()
    car = KinematicCar()
    run(machine, car, until=lambda m, c: m.phase == Phase.LIFT)
    car.stuck = True
    run(machine, car)
    assert_safe_abort(machine, car, ErrorCode.STALL)


def test_blocked_drive_is_no_progress():
    machine, _ = start()
    car = KinematicCar()
    run(machine, car, until=lambda m, c: m.phase == Phase.ADVANCE)
    car.blocked = True
    started = car.time
    run(machine, car)
    assert_safe_abort(machine, car, ErrorCode.NO_PROGRESS)
    assert car.time - started == pytest.approx(CONFIG.no_progress_time, abs=0.05)


def test_nose_up_pitch_near_tip_over_aborts():
    machine, _ = start()
    car = KinematicCar()
    run(machine, car, until=lambda m, c: m.phase == Phase.ADVANCE)
    limit = math.pi / 2 - P.phi / 2
    car.extra_pitch = -(limit - CONFIG.pitch_abort_margin + 0.01)
    car.apply(machine.update(car.observe()))
    assert_safe_abort(machine, car, ErrorCode.TIP_OVER_ABORT)


def test_nose_down_pitch_is_no_tip_over():
    machine, _ = start()
    car = KinematicCar()
    car.extra_pitch = 0.3
    car.apply(machine.update(car.observe()))
    assert machine.outcome is None


def test_heading_comes_from_the_imu():
    machine, plan = start(yaw=0.2)
    car = car_before(yaw=0.2)
    car.extra_yaw = 0.3  # at the start: only an offset between the two headings
    run(machine, car, until=lambda m, c: m.phase == Phase.LIFT)
    car.odometry.set_pose(car.odometry.x, car.odometry.y, car.odometry.yaw + 0.2)
    car.extra_yaw = 0.1  # odometry's heading jumped by 0.2 rad, the IMU's did not
    run(machine, car)
    assert machine.outcome.success, machine.outcome.message


def test_heading_slip_between_imu_and_odometry_is_no_progress():
    machine, _ = start()
    car = KinematicCar()
    run(machine, car, until=lambda m, c: m.step == Step.REAR)
    car.extra_yaw = CONFIG.slip_yaw_tolerance + 0.01
    car.apply(machine.update(car.observe()))
    assert_safe_abort(machine, car, ErrorCode.NO_PROGRESS)
    assert 'slip' in machine.outcome.message


def test_time_allowance_aborts_with_timeout():
    machine, _ = start(allowance=2.0)
    car = KinematicCar()
    run(machine, car)
    assert_safe_abort(machine, car, ErrorCode.TIMEOUT)
    assert car.time == pytest.approx(2.0, abs=0.05)


def test_reaching_the_lift_point_misaligned_fails_safely():
    # A steering gain of zero never aligns.
    config = dataclasses.replace(CONFIG, heading_gain=0.0)
    machine, _ = start(config=config)
    car = KinematicCar()
    run(machine, car)
    assert_safe_abort(machine, car, ErrorCode.FAILED)
    assert 'heading' in machine.outcome.message


def test_a_car_asked_while_moving_first_stops_holding_its_swivel():
    car = KinematicCar()
    for _ in range(50):
        car.apply(Command(0.2, 0.0, 4.0, True))
    assert car.speed > 0.2
    car.place_step(0.04, 1.2)
    machine, plan = start()
    first = machine.update(car.observe())
    assert machine.step == Step.STOP and machine.phase == Phase.APPROACH
    assert first.drive_speed == 0.0 and first.hold
    assert first.angle == pytest.approx(car.swivel)
    car.apply(first)  # the kinematic car stops at once
    approach = machine.update(car.observe())
    assert machine.step == Step.APPROACH and approach.drive_speed > 0.0
    run(machine, car)
    assert machine.outcome.success, machine.outcome.message


@pytest.mark.parametrize('yaw, offset', [(0.1, -0.5), (-0.1, 0.5), (0.0, -0.3)])
def test_with_the_step_extent_the_approach_reaches_the_planned_crossing(yaw, offset):
    request = ClimbRequest(0.04, 2.0, yaw, step_width=1.5, step_offset=offset)
    plan = make_plan(P, CONFIG, request)
    machine = ClimbStateMachine(P, CONFIG, plan, 2.0, yaw)
    car = KinematicCar()
    run(machine, car, until=lambda m, c: m.phase == Phase.LIFT)
    edge = StepEdge.from_request(Pose2D(0.0, 0.0, 0.0), P.wheelbase, 2.0, yaw)
    # base_link on the planned line: through the crossing at the approach heading.
    heading = plan.approach_heading
    normal = edge.signed_distance(car.odometry.x, car.odometry.y)
    along = edge.along(car.odometry.x, car.odometry.y) - plan.crossing
    assert abs(-math.sin(heading) * normal + math.cos(heading) * along) < 0.03
    assert machine.phase == Phase.LIFT


def test_every_step_but_done_has_its_own_behaviour():
    machine, plan = start()
    car = car_before()
    machine.update(car.observe())
    for step in Step:
        if step == Step.DONE:
            assert step not in steps.BEHAVIOURS
        else:
            assert steps.enter(step, machine.climb, car.observe()).step == step


def test_a_step_without_a_behaviour_raises_instead_of_running_another(monkeypatch):
    monkeypatch.delitem(steps.BEHAVIOURS, Step.ADVANCE)
    machine, plan = start()
    car = car_before()
    with pytest.raises(LookupError, match='ADVANCE'):
        run(machine, car)
    assert machine.step == Step.LIFT
