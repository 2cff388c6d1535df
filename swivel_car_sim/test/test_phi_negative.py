"""
The phi < 0 design (swivel_car_model/config/designs/phi_negative.yaml) in physics.

Its body clears the ground, and the model's phi < 0 branches (lift constraint, lifted wheel,
steering map, contact point, approach angle, turning curvature) hold for it; a driven front
wheel pressed against a riser helps the swivel (thesis eqs. 86-91). The sim core directly,
deterministic; docs/thesis_reproduction.md (III.B in physics) has the numbers.
"""

import math
from pathlib import Path
import xml.etree.ElementTree as ET

import numpy as np
import pybullet
import pytest
from swivel_car_model import climbing, kinematics, planar
from swivel_car_model.description import CarDescription

from swivel_car_sim.physics import SimConfig, SwivelCarSim
from swivel_car_sim.urdf import build_robot
from swivel_car_sim.world import StepSpec
import yaml

from .conftest import SwivelHold

DESIGN = (Path(__file__).resolve().parents[2] / 'swivel_car_model' / 'config' / 'designs'
          / 'phi_negative.yaml')
SWIVEL_TARGETS = (0.5, 1.0, 1.4)  # [rad]
DRIVE_SPEED = 2.0  # [rad/s] wheel rate, 0.38 m/s
RISER_SWIVEL = 0.3  # [rad] the left front wheel lifted 8 cm, pressed against the riser


@pytest.fixture(scope='module')
def design() -> CarDescription:
    return CarDescription.from_values(yaml.safe_load(DESIGN.read_text())['/**']['ros__parameters'])


def _rim_point(sim: SwivelCarSim, joint: str, direction) -> tuple[np.ndarray, np.ndarray]:
    """Return the wheel's rim point furthest along ``direction`` (world) and its axle (world)."""
    link = sim._joint_ids[sim.joint_names.index(joint)]
    state = pybullet.getLinkState(sim._body, link, computeForwardKinematics=1,
                                  physicsClientId=sim._client)
    axle = np.array(pybullet.getMatrixFromQuaternion(state[5])).reshape(3, 3)[:, 1]
    radial = np.asarray(direction, dtype=float) - (np.dot(direction, axle)) * axle
    return np.array(state[4]) + sim.params.r * radial / np.linalg.norm(radial), axle


def _in_level_base(state, point: np.ndarray) -> np.ndarray:
    """Return a world point in the level base_link frame (x, y) [m]."""
    c, s = math.cos(state.yaw), math.sin(state.yaw)
    dx, dy = point[:2] - state.position[:2]
    return np.array([c * dx + s * dy, -s * dx + c * dy])


@pytest.fixture(scope='module')
def swivelled(design):
    """
    Hold the design at rest, then the swivel at each target in turn.

    theta2 > 0: the right front wheel steers, the left one lifts. Gives the smallest body
    clearance of every period.
    """
    with SwivelCarSim(SimConfig(description=design, body_collision=True)) as sim:
        sim.step(50)
        rest = sim.body_clearance()
        hold, clearances, held = SwivelHold(sim), [], []
        for target in SWIVEL_TARGETS:
            for _ in range(int(target / 0.015) + 60):
                hold.period(target, 0.0)
                clearances.append(sim.body_clearance())
            state = sim.state()
            _, axle = _rim_point(sim, 'front_right_wheel_joint', [0.0, 0.0, -1.0])
            rolling = np.cross(axle, [0.0, 0.0, 1.0])
            lowest, _ = _rim_point(sim, 'front_left_wheel_joint', [0.0, 0.0, -1.0])
            front, _ = _rim_point(sim, 'front_right_wheel_joint', [math.cos(state.yaw),
                                                                   math.sin(state.yaw), 0.0])
            link = sim._joint_ids[sim.joint_names.index('front_right_wheel_joint')]
            contacts = pybullet.getContactPoints(sim._body, sim._ground, link, -1,
                                                 physicsClientId=sim._client)
            held.append({'state': state, 'lowest': sim.wheel_lowest_points()[2],
                         'steering': math.atan2(rolling[1], rolling[0]) - state.yaw,
                         'contact': _in_level_base(state, np.mean([c[6] for c in contacts], 0)),
                         'P_L': _in_level_base(state, lowest),
                         'C_F': _in_level_base(state, front)})
    return {'rest': rest, 'clearances': clearances, 'held': held}


def test_the_body_clears_the_ground_at_rest_and_over_the_swivel_range(design, swivelled):
    # The box under the apex is the lowest part, r - l sin(pi/6) - 0.25 l / 2 above the
    # ground; the lift only raises it.
    expected = design.r + design.l * math.sin(design.phi / 2.0) - 0.125 * design.l
    assert swivelled['rest'] == pytest.approx(expected, abs=5e-4)
    assert min(swivelled['clearances']) > expected - 5e-4
    assert swivelled['held'][-1]['state'].positions[0] > SWIVEL_TARGETS[-1] - 0.03


def test_lift_angle_and_lifted_wheel_follow_the_model(design, swivelled):
    # The 4 mm tyre disc tilted by the swivel touches on its rim edge, up to 2 mm below the
    # mid-plane the model uses: up to 0.004 rad more pitch over the 0.43 m wheelbase.
    p = design.model_params()
    for held in swivelled['held']:
        theta2 = held['state'].positions[0]
        assert -held['state'].pitch == pytest.approx(kinematics.lift_angle(p, theta2),
                                                     abs=0.005)
        assert held['lowest'] == pytest.approx(
            kinematics.lifted_wheel_lowest_height(p, theta2), abs=0.002)


def test_steering_contact_and_approach_angle_follow_the_model(design, swivelled):
    p = design.model_params()
    for held in swivelled['held']:
        theta2 = held['state'].positions[0]
        k = kinematics.kinematic_state(p, theta2)
        assert k.steering > 0.0  # phi < 0: theta2 > 0 steers left (thesis, after Fig. 21)
        assert held['steering'] == pytest.approx(k.steering, abs=0.005)
        np.testing.assert_allclose(held['contact'], [k.contact_x, k.contact_y], atol=0.003)
        line = held['C_F'] - held['P_L']
        assert math.atan2(abs(line[0]), abs(line[1])) == pytest.approx(
            climbing.min_approach_angle(p, theta2), abs=0.01)


@pytest.mark.parametrize('target', [0.5, -1.0])
def test_turning_curvature_while_driving_follows_the_model(design, target):
    with SwivelCarSim(SimConfig(description=design, body_collision=True)) as sim:
        hold = SwivelHold(sim)
        hold.run(100, target, 0.0)
        hold.run(100, target, DRIVE_SPEED)
        states = [hold.period(target, DRIVE_SPEED) for _ in range(200)]
    curvature = (np.mean([s.angular_velocity[2] for s in states])
                 / np.mean([s.linear_velocity[0] for s in states]))
    theta2 = float(np.mean([s.positions[0] for s in states]))
    model = planar.curvature_for_swivel(design.model_params(), theta2)
    assert math.copysign(1.0, curvature) == math.copysign(1.0, target)  # theta2 > 0: left
    assert curvature == pytest.approx(model, rel=0.02)


def test_body_collision_gives_the_body_its_shapes_and_sees_obstacles(design):
    plain = ET.fromstring(build_robot(design).urdf)
    solid = ET.fromstring(build_robot(design, body_collision=True).urdf)
    assert len(plain.findall('.//collision')) == 4
    assert len(solid.findall('.//collision')) == len(design.parts())
    with SwivelCarSim(SimConfig(description=design, body_collision=True)) as sim:
        ground = sim.body_clearance()
        # A 2 cm slab 0.23-0.33 m ahead of the rear axle, under the body box's front half,
        # between the wheels.
        sim.spawn_obstacle(StepSpec('slab', 0.02, 0.1, 0.2, 0.1, 0.0, 1.0))
        sim.reset(x=0.3)
        assert sim.body_clearance() == pytest.approx(ground - 0.02, abs=1e-3)
    with SwivelCarSim() as sim, pytest.raises(ValueError, match='body_collision'):
        sim.body_clearance()
    with pytest.raises(ValueError, match='body_collision'):
        SimConfig(body_collision=1)


def _contact_moments(sim: SwivelCarSim, joint: str, other: int, axis: np.ndarray,
                     apex: np.ndarray) -> tuple[float, float, np.ndarray]:
    """
    Return the moments about the swivel axis of the contact forces on the wheel of ``joint``.

    The moments [N m] of the normal and the friction forces that body ``other`` puts on the
    wheel, and their total force (world) [N].
    """
    link = sim._joint_ids[sim.joint_names.index(joint)]
    normal = friction = 0.0
    force = np.zeros(3)
    for c in pybullet.getContactPoints(sim._body, other, link, -1,
                                       physicsClientId=sim._client):
        arm = np.array(c[5]) - apex
        f_normal = c[9] * np.array(c[7])
        f_friction = c[10] * np.array(c[11]) + c[12] * np.array(c[13])
        normal += float(axis @ np.cross(arm, f_normal))
        friction += float(axis @ np.cross(arm, f_friction))
        force += f_normal + f_friction
    return normal, friction, force


def _against_riser(design: CarDescription, drive_speed: float,
                   swivel: float = RISER_SWIVEL) -> dict:
    """
    Lift the left front wheel to ``swivel`` [rad] in front of a 45 cm riser that only it meets.

    The swivel is held there by a PID (its integral removes the offset a PD leaves, so both
    runs hold the same angle); then the drive pushes the wheel against the riser (motor at its
    torque limit) or stays still. Returns means over the last second.
    """
    p = design.model_params()
    with SwivelCarSim(SimConfig(description=design, body_collision=True)) as sim:
        sim.spawn_obstacle(StepSpec('riser', 0.45, 0.5, 0.12, 0.23, 0.0, 1.0))
        sim.reset(y=-design.h)  # the riser, centred on the car's start line, faces the left wheel
        set_point = integral = 0.0
        log = []
        for period in range(500):
            state = sim.state()
            set_point = min(swivel, set_point + 0.015)
            error = set_point - state.positions[0]
            integral += error * 0.01
            torque = design.kp * error + design.ki * integral - design.kd * state.velocities[0]
            sim.set_command(torque, drive_speed if period > 100 else 0.0)
            sim.step(5)
            if period >= 400:
                position, orientation = sim._base_pose()
                rotation = np.array(pybullet.getMatrixFromQuaternion(orientation)).reshape(3, 3)
                axis, apex = rotation @ p.swivel_axis, position + rotation @ p.apex
                riser_n, riser_f, riser_force = _contact_moments(
                    sim, 'front_left_wheel_joint', sim._obstacles.bodies['riser'], axis, apex)
                ground_n, ground_f, _ = _contact_moments(
                    sim, 'front_right_wheel_joint', sim._ground, axis, apex)
                log.append([torque, state.positions[0], np.linalg.norm(riser_force[:2]),
                            riser_n, riser_f, ground_n, ground_f])
    return dict(zip(('hold', 'theta2', 'riser_force', 'riser_normal', 'riser_friction',
                     'ground_normal', 'ground_traction'), np.mean(log, axis=0)))


def test_a_driven_wheel_against_a_riser_helps_the_swivel_more_than_eq_89_says(design):
    # Thesis eqs. 86-89 (corrected: F = tau_D / r, the lever h sin(|phi|/2)): only the
    # riser's push on the blocked wheel turns the swivel. In physics the steering wheel's
    # own traction pushes forward below the same shaft (the same sign of lever for phi < 0),
    # and the driven wheel rolling up the riser's face carries part of the front's weight
    # off the swivel, so the holding torque drops by several times eq. 89's torque.
    p = design.model_params()
    still, pushed = _against_riser(design, 0.0), _against_riser(design, 5.0)
    assert still['riser_force'] == 0.0
    assert still['theta2'] == pytest.approx(RISER_SWIVEL, abs=0.005)
    assert pushed['theta2'] == pytest.approx(RISER_SWIVEL, abs=0.005)
    model = climbing.induced_swivel_torque(p, pushed['riser_force'] * p.r, pushed['theta2'])
    # The car pivots about the blocked wheel (0.09 rad), so the riser pushes obliquely.
    assert pushed['riser_normal'] == pytest.approx(model, rel=0.25)
    assist = still['hold'] - pushed['hold']
    changes = {k: pushed[k] - still[k] for k in ('riser_normal', 'riser_friction',
                                                 'ground_normal', 'ground_traction')}
    contacts = sum(changes.values())
    print(f'theta2 {pushed["theta2"]:.3f}: riser force {pushed["riser_force"]:.1f} N, '
          f'eq. 89 {model:.2f} N m; swivel holding torque {still["hold"]:.2f} -> '
          f'{pushed["hold"]:.2f} N m (assist {assist:.2f}); contact moments: '
          + ', '.join(f'{k} {v:+.2f}' for k, v in changes.items()))
    assert assist == pytest.approx(contacts, abs=0.5)  # every contact accounted for
    assert assist > 2.0 * model


def test_the_assist_falls_as_the_swivel_rises(design):
    # The thesis' text on Figs. 50-51 says the assisting torque increases with theta2 (and
    # that it vanishes at pi/2). Measured at a 10 N m motor, the holding torque drops by
    # 11.5 N m at theta2 = 0.3 rad and by 3.6 N m at 1.2 rad; eq. 89, corrected, falls too
    # (3.17 to 1.43 N m): the lever of the riser's push shrinks as the shaft turns.
    weak = design.replace(drive_torque_limit=10.0)
    p = weak.model_params()
    assists, models = [], []
    for swivel in (0.3, 1.2):
        still = _against_riser(weak, 0.0, swivel)
        pushed = _against_riser(weak, 5.0, swivel)
        assists.append(still['hold'] - pushed['hold'])
        models.append(climbing.induced_swivel_torque(
            p, pushed['riser_force'] * p.r, pushed['theta2']))
    print(f'assist at theta2 0.3 / 1.2 rad: {assists[0]:.2f} / {assists[1]:.2f} N m, eq. 89 '
          f'{models[0]:.2f} / {models[1]:.2f} N m')
    assert assists[1] < 0.5 * assists[0]
    assert models[1] < models[0]
