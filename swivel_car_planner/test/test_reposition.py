"""Unit and property tests of the repositioning path (core/reposition.py, via make_plan)."""

import dataclasses
import math

from hypothesis import given, settings, strategies as st
from kinematic_car import KinematicCar
import numpy as np
import pytest
from swivel_car_model import dynamics, planar
from swivel_car_model.params import SwivelCarParams

from swivel_car_planner.core import (
    ClimbRequest, ClimbStateMachine, ErrorCode, make_plan, PlanError, PlannerConfig)
from swivel_car_planner.core.reposition import footprint, Pose, propagate, reposition_length
from swivel_car_planner.core.state_machine import Step

P = SwivelCarParams()
CONFIG = PlannerConfig()
# What the planner refused before it could reposition: straight backups only.
STRAIGHT = dataclasses.replace(CONFIG, max_reposition=0.0)
TRACK = 2.0 * P.h + P.wheel_width  # [m]
_FINE = 0.005  # [m] the dense integration below steps at most this far


def request(height=0.05, distance=0.3, yaw=0.0, width=1.0, offset=0.0):
    return ClimbRequest(step_height=height, step_distance=distance, step_yaw=yaw,
                        step_width=width, step_offset=offset)


def dense_path(p, plan):
    """
    Integrate the plan's path independently of the module: (x, y, yaw, turning) rows.

    Small unicycle steps at each segment's curvature, and each swivel move at a standstill
    as the model's drift, interpolated over its course.
    """
    x = y = yaw = swivel = 0.0
    rows = [(x, y, yaw, False)]
    back = dataclasses.replace(plan.reposition[0], swivel=0.0, length=0.0)
    for segment in (*plan.reposition, back):
        if segment.swivel != swivel:
            dx, dy, dyaw = dynamics.swivel_pose_drift(p, swivel, segment.swivel)
            for f in np.linspace(0.0, 1.0, 20):
                c, s = math.cos(yaw), math.sin(yaw)
                rows.append((x + f * (c * dx - s * dy), y + f * (s * dx + c * dy),
                             yaw + f * dyaw, True))
            x, y, yaw = rows[-1][:3]
            swivel = segment.swivel
        curvature = planar.curvature_for_swivel(p, segment.swivel) if swivel else 0.0
        count = int(math.ceil(abs(segment.length) / _FINE))
        for _ in range(count):
            ds = segment.length / count
            x += ds * math.cos(yaw + curvature * ds / 2.0)
            y += ds * math.sin(yaw + curvature * ds / 2.0)
            yaw += curvature * ds
            rows.append((x, y, yaw, swivel != 0.0))
    return rows


def gap_to_box(rows, req, clearance):
    """
    Return the least distance [m] between the step's box and the footprint grown by clearance.

    Negative: they overlap. The box: the top face, without end away from the car. Checked on
    the footprint's outline (points 5 mm apart) against the box's region, and the box's near
    corners against the footprint rectangle.
    """
    edge = np.array([P.wheelbase + req.step_distance, 0.0])
    normal = np.array([math.cos(req.step_yaw), math.sin(req.step_yaw)])
    along = np.array([-normal[1], normal[0]])
    low, high = (req.step_offset - req.step_width / 2.0, req.step_offset + req.step_width / 2.0)
    near = [edge + low * along, edge + high * along]
    rows = np.array(rows, dtype=float)
    x, y, yaw = rows[:, :1], rows[:, 1:2], rows[:, 2:3]
    shapes = [footprint(P, False), footprint(P, True)]
    pick = rows[:, 3].astype(int)
    back = np.array([-f.back - clearance for f in shapes])[pick][:, None]
    front = np.array([f.front + clearance for f in shapes])[pick][:, None]
    half = np.array([f.half_width + clearance for f in shapes])[pick][:, None]
    c, s = np.cos(yaw), np.sin(yaw)
    f = np.linspace(0.0, 1.0, 40)[None, :]
    u = np.concatenate([back + f * (front - back), np.repeat(front, 40, axis=1),
                        front + f * (back - front), np.repeat(back, 40, axis=1)], axis=1)
    v = np.concatenate([np.repeat(-half, 40, axis=1), -half + 2.0 * f * half,
                        np.repeat(half, 40, axis=1), half - 2.0 * f * half], axis=1)
    px, py = x + c * u - s * v - edge[0], y + s * u + c * v - edge[1]
    n, t = px * normal[0] + py * normal[1], px * along[0] + py * along[1]
    # Distance of each outline point to the box region (negative inside).
    outside_n = np.maximum(-n, 0.0)
    outside_t = np.maximum(np.maximum(low - t, t - high), 0.0)
    inside = (n >= 0.0) & (t >= low) & (t <= high)
    distance = np.where(inside, -np.minimum(n, np.minimum(t - low, high - t)),
                        np.hypot(outside_n, outside_t))
    least = float(np.min(distance))
    for corner in near:  # a box corner inside the rectangle: overlap
        du, dv = corner[0] - x, corner[1] - y
        cu, cv = c * du + s * dv, -s * du + c * dv
        if np.any((back <= cu) & (cu <= front) & (-half <= cv) & (cv <= half)):
            least = min(least, -1e-3)
    return least


@settings(max_examples=20, deadline=None)
@given(height=st.sampled_from([0.02, 0.05, 0.08]), distance=st.floats(0.2, 2.0),
       yaw=st.floats(-0.3, 0.3), width=st.floats(0.8, 2.0),
       offset=st.floats(-0.6, 0.6))
def test_repositioning_never_drives_into_the_step(height, distance, yaw, width, offset):
    req = request(height, distance, yaw, width, offset)
    plan = make_plan(P, CONFIG, req)  # the climb benchmark's room: never refused
    if not plan.reposition:
        return
    assert reposition_length(plan.reposition) <= CONFIG.max_reposition
    rows = dense_path(P, plan)
    # The path backs up straight first with no clearance to keep (it moves the car away from
    # where it stands); from its first turn on, the clearance holds up to the 1 mm the dense
    # integration may differ from the exact arcs.
    first_turn = next(i for i, row in enumerate(rows) if row[3])
    if first_turn > 1:
        assert gap_to_box(rows[1:first_turn], req, 0.0) >= -1e-3
    assert gap_to_box(rows[first_turn:], req, CONFIG.reposition_clearance) >= -1e-3


def test_the_path_ends_where_the_approach_can_start():
    # The system test's step: 0.3 m ahead, square, a 1 m face; from there the approach cannot
    # turn onto its heading in time, backing up straight it would cross beside the face.
    req = request(0.05, 0.3, 0.0, 1.0)
    with pytest.raises(PlanError):
        make_plan(P, STRAIGHT, req)
    plan = make_plan(P, CONFIG, req)
    assert plan.reposition and plan.backup_distance == 0.0
    assert any(abs(s.swivel) == P.swivel_limit for s in plan.reposition)
    end = propagate(P, Pose(0.0, 0.0, 0.0), plan.reposition)[-1]
    exact = dense_path(P, plan)[-1]
    assert (end.x, end.y, end.yaw) == pytest.approx(exact[:3], abs=2e-3)
    # The same step seen from the end of the path: planned without moving first, the same
    # approach and crossing.
    c, s = math.cos(end.yaw), math.sin(end.yaw)
    edge_x, edge_y = P.wheelbase + req.step_distance, 0.0
    # Where the end pose's x axis meets the edge, and how far along the edge from the first.
    normal = req.step_yaw
    to_edge = ((edge_x - end.x) * math.cos(normal) + (edge_y - end.y) * math.sin(normal)) \
        / math.cos(end.yaw - normal)
    meet = (end.x + c * to_edge, end.y + s * to_edge)
    shift = -(meet[0] - edge_x) * math.sin(normal) + (meet[1] - edge_y) * math.cos(normal)
    seen = ClimbRequest(req.step_height, to_edge - P.wheelbase, normal - end.yaw,
                        step_width=req.step_width, step_offset=req.step_offset - shift)
    there = make_plan(P, dataclasses.replace(STRAIGHT, max_backup=0.0), seen)
    assert there.approach_heading == pytest.approx(plan.approach_heading)
    assert there.crossing + shift == pytest.approx(plan.crossing, abs=1e-6)


def test_a_face_beside_the_car_is_reached_by_a_path_not_refused():
    req = request(0.05, 1.0, 0.0, 1.5, 2.5)
    with pytest.raises(PlanError, match='beside the top face'):
        make_plan(P, STRAIGHT, req)
    plan = make_plan(P, CONFIG, req)
    assert plan.reposition
    # The crossing lies on the face, its wheels edge_margin inside it.
    assert 2.5 - 0.75 < plan.crossing < 2.5 + 0.75
    assert plan.duration > make_plan(P, CONFIG, request(0.05, 1.0, 0.0, 1.5, 0.0)).duration


def test_a_path_longer_than_max_reposition_is_refused_naming_it():
    config = dataclasses.replace(CONFIG, max_reposition=0.5)
    with pytest.raises(PlanError) as caught:
        make_plan(P, config, request(0.05, 1.0, 0.0, 1.5, 2.5))
    assert caught.value.code == ErrorCode.INVALID_REQUEST
    assert 'max_reposition' in caught.value.message and '0.50 m' in caught.value.message


def test_a_face_too_narrow_for_the_track_is_refused_as_narrow_wherever_the_car_stands():
    for distance in (0.3, 2.0):
        with pytest.raises(PlanError) as caught:
            make_plan(P, CONFIG, request(0.05, distance, 0.0, TRACK))
        assert caught.value.code == ErrorCode.INVALID_REQUEST
        assert 'too narrow' in caught.value.message
        assert 'max_reposition' not in caught.value.message
        needed = float(caught.value.message.split('needs ')[1].split(' m')[0])
        assert needed > TRACK


def test_a_car_standing_against_the_step_is_refused_as_such():
    # The front wheel's corner is over the edge's line within the face; nothing but the
    # repositioning to try.
    with pytest.raises(PlanError, match='stands against the step'):
        make_plan(P, dataclasses.replace(CONFIG, max_backup=0.0),
                  request(0.05, 0.02, 0.5, 1.5))


def test_reposition_settings_are_validated():
    for name in ('max_reposition', 'reposition_clearance'):
        with pytest.raises(ValueError, match=name):
            PlannerConfig(**{name: -0.1})
        with pytest.raises(ValueError, match=name):
            PlannerConfig(**{name: math.nan})


def test_the_climb_drives_the_path_then_approaches_and_climbs():
    # The system test's step, through the state machine and the kinematic car.
    req = request(0.05, 0.3, 0.0, 1.0)
    plan = make_plan(P, CONFIG, req)
    machine = ClimbStateMachine(P, CONFIG, plan, req.step_distance, req.step_yaw)
    car = KinematicCar()
    car.place_step(req.step_height, req.step_distance, req.step_yaw)
    names, rows = [], []
    while machine.outcome is None and car.time < 120.0:
        car.apply(machine.update(car.observe()))
        if not names or names[-1] != machine.feedback.phase_name:
            names.append(machine.feedback.phase_name)
        if machine.step == Step.REPOSITION:
            rows.append((car.odometry.x, car.odometry.y, car.odometry.yaw,
                         car.swivel != 0.0))
    assert machine.outcome.success, machine.outcome.message
    assert names[:2] == ['APPROACH: REPOSITION', 'APPROACH']
    # Every segment driven: turns at the swivel's limit, forwards and backwards.
    driven = {(c.angle, math.copysign(1.0, c.drive_speed)) for c in car.commands
              if c.drive_speed != 0.0 and abs(c.angle) == P.swivel_limit}
    assert driven == {(s.swivel, math.copysign(1.0, s.length)) for s in plan.reposition
                      if s.swivel != 0.0}
    # The car stayed clear of the step while it repositioned (the planned clearance keeps
    # room for the kinematic car's differences from the planned arcs).
    assert gap_to_box(rows, req, 0.0) > 0.0
