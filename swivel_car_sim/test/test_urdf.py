import math
from pathlib import Path
import xml.etree.ElementTree as ET

import numpy as np
import pybullet
import pytest
from swivel_car_model.description import CarDescription

from swivel_car_sim.urdf import build_robot, default_urdf_path, ROBOT_VARIANTS, WHEEL_JOINTS

URDF_DIR = Path(__file__).resolve().parents[1] / 'urdf'

DESIGNS = [CarDescription(), CarDescription(phi=-math.pi / 3),
           CarDescription(l=0.4, h=0.1, r=0.05), CarDescription(h=0.25, r=0.1, phi=0.3),
           CarDescription(body_mass=12.0, body_offset=0.05, rear_axle_mass=3.0)]


@pytest.mark.parametrize('variant', ROBOT_VARIANTS)
def test_committed_default_urdf_matches_generator(variant):
    assert (URDF_DIR / default_urdf_path(variant)).read_text() == \
        build_robot(CarDescription(), variant).urdf, \
        'regenerate: python -m swivel_car_sim.urdf --out swivel_car_sim/urdf'


@pytest.mark.parametrize('description', DESIGNS)
@pytest.mark.parametrize('variant', ROBOT_VARIANTS)
def test_urdf_carries_the_description_masses(description, variant):
    robot = build_robot(description, variant)
    masses = [float(m.get('value')) for m in ET.fromstring(robot.urdf).iter('mass')]
    assert sum(masses) == pytest.approx(description.mass, rel=1e-9)
    assert robot.mass == pytest.approx(description.mass, rel=1e-9)
    if variant == 'swivel':
        assert robot.inertia_about_rear_axle == pytest.approx(
            description.inertia_about_rear_axle, rel=1e-12)
        np.testing.assert_allclose(robot.com, description.com, atol=1e-12)


@pytest.mark.parametrize('variant', ROBOT_VARIANTS)
def test_urdf_inertials_give_the_description_centre_of_mass_in_pybullet(variant, tmp_path):
    description = CarDescription(body_mass=10.0, body_offset=0.04)
    # As the sim loads it: pybullet gives the camera's inertia-less frames 1 kg each.
    robot = build_robot(description, variant, sensor_frames=False)
    path = tmp_path / 'robot.urdf'
    path.write_text(robot.urdf)
    client = pybullet.connect(pybullet.DIRECT)
    try:
        body = pybullet.loadURDF(str(path), flags=pybullet.URDF_USE_INERTIA_FROM_FILE,
                                 physicsClientId=client)
        total, moment = 0.0, np.zeros(3)
        for link in range(-1, pybullet.getNumJoints(body, physicsClientId=client)):
            mass = pybullet.getDynamicsInfo(body, link, physicsClientId=client)[0]
            position = (pybullet.getBasePositionAndOrientation(body, physicsClientId=client)[0]
                        if link < 0 else
                        pybullet.getLinkState(body, link, physicsClientId=client)[0])
            total += mass
            moment += mass * np.array(position)
    finally:
        pybullet.disconnect(client)
    assert total == pytest.approx(description.mass)
    np.testing.assert_allclose(moment / total, robot.com, atol=1e-9)


@pytest.mark.parametrize('description', DESIGNS)
@pytest.mark.parametrize('variant', ROBOT_VARIANTS)
def test_designs_load_in_pybullet_with_the_contract_joints(description, variant, tmp_path):
    robot = build_robot(description, variant, sensor_frames=False)  # as the sim loads it
    params = description.model_params()
    path = tmp_path / 'robot.urdf'
    path.write_text(robot.urdf)
    client = pybullet.connect(pybullet.DIRECT)
    try:
        body = pybullet.loadURDF(str(path), physicsClientId=client)
        info = [pybullet.getJointInfo(body, i, physicsClientId=client)
                for i in range(pybullet.getNumJoints(body, physicsClientId=client))]
    finally:
        pybullet.disconnect(client)
    joints = {i[1].decode(): i for i in info}
    assert set(joints) == {robot.steer_joint, *WHEEL_JOINTS}
    steer = joints[robot.steer_joint]
    assert steer[2] == pybullet.JOINT_REVOLUTE
    expected_axis = params.swivel_axis if variant == 'swivel' else [0.0, 0.0, 1.0]
    np.testing.assert_allclose(steer[13], expected_axis, atol=1e-9)
    if variant == 'swivel':
        assert (steer[8], steer[9]) == pytest.approx(
            (-params.max_swivel_angle, params.max_swivel_angle))
    for name in WHEEL_JOINTS:
        assert joints[name][2] == pybullet.JOINT_REVOLUTE
        np.testing.assert_allclose(joints[name][13], [0.0, 1.0, 0.0], atol=1e-9)


def test_wheels_sit_where_the_params_say():
    d = CarDescription(phi=-0.8, l=0.3, h=0.12)
    p = d.model_params()
    root = ET.fromstring(build_robot(d).urdf)
    origins = {j.get('name'): np.array(j.find('origin').get('xyz').split(), dtype=float)
               for j in root.iter('joint')}
    np.testing.assert_allclose(origins['swivel_joint'], p.apex, atol=1e-8)
    np.testing.assert_allclose(origins['rear_left_wheel_joint'], [0, p.h, 0], atol=1e-8)
    np.testing.assert_allclose(origins['front_right_wheel_joint'] + p.apex,
                               p.front_axle + [0, -p.h, 0], atol=1e-8)


def test_unknown_variant_is_refused():
    with pytest.raises(ValueError, match='robot_variant'):
        build_robot(CarDescription(), 'tank')


def test_camera_frames_sit_where_the_description_mounts_the_camera():
    description = CarDescription(body_offset=0.03)
    root = ET.fromstring(build_robot(description).urdf)
    joints = {j.get('name'): j for j in root.iter('joint')}
    mount = joints['camera_link_joint']
    position, pitch = description.camera_mount()
    assert (mount.find('parent').get('link'), mount.find('child').get('link')) == \
        ('base_link', 'camera_link')
    np.testing.assert_allclose([float(v) for v in mount.find('origin').get('xyz').split()],
                               position, atol=1e-9)
    np.testing.assert_allclose([float(v) for v in mount.find('origin').get('rpy').split()],
                               [0.0, pitch, 0.0], atol=1e-9)
    optical = joints['camera_depth_optical_frame_joint']
    roll, _, yaw = (float(v) for v in optical.find('origin').get('rpy').split())
    # REP 103: the optical z (forward) is camera_link's x, optical x (right) its -y.
    rotation = np.array(pybullet.getMatrixFromQuaternion(
        pybullet.getQuaternionFromEuler([roll, 0.0, yaw]))).reshape(3, 3)
    np.testing.assert_allclose(rotation[:, 2], [1.0, 0.0, 0.0], atol=1e-8)
    np.testing.assert_allclose(rotation[:, 0], [0.0, -1.0, 0.0], atol=1e-8)
    assert 'camera_link' not in build_robot(description, sensor_frames=False).urdf
