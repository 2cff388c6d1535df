"""The sim's depth camera (ROS-free): the render against geometry, the noise model, the config."""

import math

import numpy as np
import pytest
from swivel_car_sim.depth_camera import CameraConfig, DepthCamera, PARAMETERS
from swivel_car_sim.physics import SwivelCarSim
from swivel_car_sim.sensor_models import StereoDepthNoise
from swivel_car_sim.world import StepSpec

DEFAULTS = {name: default for name, (default, _) in PARAMETERS.items()}


def _rays(camera, state):
    """Each pixel's ray (optical z component 1) in the world, and the camera's eye [m]."""
    k = camera.intrinsics
    eye, axes = camera.optical_pose(state.position, state.orientation)
    v, u = np.mgrid[0:k.height, 0:k.width]
    rays = (((u - k.cx) / k.fx)[..., None] * axes[:, 0]
            + ((v - k.cy) / k.fy)[..., None] * axes[:, 1] + axes[:, 2])
    return eye, rays


@pytest.fixture(scope='module')
def sim():
    with SwivelCarSim() as world:
        yield world


def test_rendered_depth_is_the_geometry_of_ground_and_riser(sim):
    camera = DepthCamera(sim.client, sim.description, 212, 120, noise=None)
    state = sim.state()
    eye, rays = _rays(camera, state)
    ground = -eye[2] / rays[..., 2]  # [m] depth of the ground plane through each pixel
    depth = camera.true_depth(state.position, state.orientation)
    # The car's own parts hide some ground nearer than it; the sky is NaN.
    seen = np.isfinite(depth) & (depth > ground - 0.05)
    assert seen.sum() > 10000
    # The tiny renderer's depth buffer, converted: 0.05 mm measured; a pixel convention off
    # by half a pixel gives several mm on ground seen at a grazing angle.
    np.testing.assert_allclose(depth[seen], ground[seen], atol=0.5e-3)
    assert np.isnan(depth[0]).all(), 'the top row looks above the horizon: no return'
    sim.spawn_obstacle(StepSpec('riser', 0.1, 1.0, 2.0, 0.8, 0.0, 1.0))
    try:
        depth = camera.true_depth(state.position, state.orientation)
    finally:
        sim.remove_obstacle('riser')
    riser_x = sim.description.wheelbase + 0.8  # [m] in base_link, the car at the origin
    on_riser = np.abs(depth - (riser_x - eye[0]) / rays[..., 0]) < 0.5e-3
    heights = (eye[2] + depth * rays[..., 2])[on_riser]
    assert on_riser.sum() > 100 and heights.max() == pytest.approx(0.1, abs=0.01)


def test_noise_follows_the_stereo_rms_model_with_dropouts_and_range():
    noise = StereoDepthNoise()
    # sigma = z^2 * 0.08 / (424 * 0.05): 3.77 mm at 1 m, 15.1 mm at 2 m.
    assert noise.sigma(np.array([1.0, 2.0])) == pytest.approx([3.774e-3, 15.09e-3], rel=1e-3)
    for z in (1.0, 2.0):
        truth = np.full((300, 300), z)
        reading = noise.apply(truth, np.random.default_rng(5))
        valid = np.isfinite(reading)
        # 90,000 pixels: the RMS within 2 % (its standard error is 0.24 %), dropouts within
        # 0.2 % of 1 % (binomial standard error 0.033 %).
        assert np.sqrt(np.mean((reading[valid] - z) ** 2)) == pytest.approx(
            noise.sigma(z), rel=0.02)
        assert 1.0 - valid.mean() == pytest.approx(0.01, abs=0.002)
    near_far = noise.apply(np.array([0.1, 10.5, np.nan]), np.random.default_rng(0))
    assert np.isnan(near_far).all()


def test_frames_are_seeded_by_their_stamp(sim):
    camera = DepthCamera(sim.client, sim.description, 64, 36, seed=3)
    state = sim.state()
    first = camera.capture(state.position, state.orientation, 100_000_000)
    camera.capture(state.position, state.orientation, 200_000_000)
    again = camera.capture(state.position, state.orientation, 100_000_000)
    other = DepthCamera(sim.client, sim.description, 64, 36, seed=4).capture(
        state.position, state.orientation, 100_000_000)
    np.testing.assert_array_equal(first, again)
    assert first.dtype == np.float32
    assert not np.array_equal(np.nan_to_num(first), np.nan_to_num(other))


@pytest.mark.parametrize('name, value, words', [
    ('camera_rate', 7.0, 'whole number'), ('camera_rate', -1.0, '>= 0'),
    ('camera_rate', math.nan, '>= 0'), ('camera_width', 1, '>= 2'),
    ('camera_width', 4000, 'native'), ('camera_height', 12.5, 'integer'),
    ('camera_noise', 1, 'bool'), ('camera_seed', -2, '>= 0'), ('camera_frame_id', '', 'frame')])
def test_bad_camera_parameters_are_refused_in_one_line(name, value, words):
    with pytest.raises(ValueError, match=words) as error:
        CameraConfig.from_values({**DEFAULTS, name: value}, 0.01)
    assert name in str(error.value) and '\n' not in str(error.value)


def test_camera_config_defaults_and_off():
    config = CameraConfig.from_values(DEFAULTS, 0.01)
    assert (config.width, config.height, config.periods_per_frame(0.01)) == (212, 120, 10)
    assert CameraConfig.from_values({**DEFAULTS, 'camera_rate': 0}, 0.01).rate == 0.0
