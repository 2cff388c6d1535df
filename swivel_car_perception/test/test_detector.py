"""The detector's core on synthetic depth images (flat ground and a box step, ray cast)."""

import math

import numpy as np
import pytest
from swivel_car_perception.core.detector import Mount, StepDetector
from synthetic_scene import depth_image, INTRINSICS, MOUNT

DETECTOR = StepDetector(INTRINSICS, MOUNT)


@pytest.mark.parametrize('seed', [None, 1, 2])
def test_flat_ground_is_no_step(seed):
    detection = DETECTOR.detect(depth_image(noise_seed=seed))
    assert not detection.found and 'flat ground' in detection.reason
    # The ground's tilt is base_link's own: level here.
    assert abs(detection.ground_pitch) < 1e-3 and abs(detection.ground_roll) < 1e-3


# (height, distance, yaw, width, offset, depth) across the detector's range.
STEPS = [(0.03, 0.4, 0.0, 1.0, 0.0, 1.0), (0.2, 1.5, 0.3, 1.2, 0.1, 1.0),
         (0.1, 0.9, -0.3, 0.6, -0.05, 0.5), (0.05, 1.2, 0.15, 0.8, 0.0, 1.0)]


@pytest.mark.parametrize('step', STEPS, ids=lambda s: f'h{s[0]}-d{s[1]}-yaw{s[2]}')
@pytest.mark.parametrize('seed', [None, 7])
def test_a_step_in_view_is_measured(step, seed):
    _, _, _, width, offset, _ = step
    d = _measured(step, seed)
    assert d.left_end_seen and d.right_end_seen
    assert d.width == pytest.approx(width, abs=0.05)
    assert d.offset == pytest.approx(offset, abs=0.03)
    # The one-sigma figures are the fit's, with floors: small, but not zero.
    assert 0.0 < d.height_std < 0.005 and 0.0 < d.distance_std < 0.01 and 0.0 < d.yaw_std < 0.02


def _measured(step, seed):
    """Detect ``step``; assert its height, distance and yaw are measured; the detection."""
    height, distance, yaw, _, _, _ = step
    d = DETECTOR.detect(depth_image(step, noise_seed=seed))
    assert d.found, d.reason
    # Bounds: the 95th-percentile targets (5 mm, 15 mm, 0.02 rad, 5 cm); each case
    # here measured well inside them (the benchmark gives the distribution).
    assert d.height == pytest.approx(height, abs=0.005)
    assert d.distance == pytest.approx(distance, abs=0.015)
    assert d.yaw == pytest.approx(yaw, abs=0.02)
    return d


# Steps 0.24-0.28 m ahead: the ground in view in front of them is a strip 0.07-0.1 m deep,
# their top face several times larger.
NEAR_STEPS = [(0.05, 0.24, 0.0, 1.5, 0.0, 3.0), (0.03, 0.24, 0.0, 1.5, 0.0, 3.0),
              (0.05, 0.24, 0.3, 1.5, 0.0, 3.0), (0.08, 0.28, 0.0, 1.5, 0.0, 3.0)]


@pytest.mark.parametrize('step', NEAR_STEPS, ids=lambda s: f'h{s[0]}-d{s[1]}-yaw{s[2]}')
@pytest.mark.parametrize('seed', [None, 1])
def test_a_near_step_whose_top_outnumbers_the_ground_in_view_is_measured(step, seed):
    # The ground was the lowest plane with half the best one's support: the top face, or a
    # plane sloping from the ground onto it, had more, and the step was not seen (5 cm) or
    # read 2.3-2.4 cm (5 cm), 1.3 cm (3 cm), 7.0 cm (8 cm).
    d = _measured(step, seed)
    # The ground is level (the sigma-weighted fit of a few thousand points: well under this).
    assert abs(d.ground_pitch) < 0.002 and abs(d.ground_roll) < 0.002


LOW_NEAR_STEPS = [(0.02, 0.28, 0.3, 1.5, 0.0, 3.0), (0.02, 0.36, 0.0, 1.5, 0.0, 3.0),
                  (0.03, 0.24, 0.3, 1.5, 0.0, 3.0)]


@pytest.mark.parametrize('step', LOW_NEAR_STEPS, ids=lambda s: f'h{s[0]}-d{s[1]}-yaw{s[2]}')
@pytest.mark.parametrize('seed', [None, 1])
def test_a_low_near_riser_places_the_edge_on_the_riser(step, seed):
    # A 2-3 cm riser's raised part is a few pixels high; the top face's points just past it
    # drew the fitted edge 13-15 mm onto the top. So near, the depth error is about 1 mm and
    # a pixel 1-2 mm: the edge within 5 mm, the yaw within 0.01 rad (both measured <= 3 mm
    # and 0.005 rad on these).
    d = _measured(step, seed)
    assert d.distance == pytest.approx(step[1], abs=0.005)
    assert d.yaw == pytest.approx(step[2], abs=0.01)


def test_a_step_wider_than_the_view_has_no_ends_and_a_lower_bound_width():
    d = DETECTOR.detect(depth_image((0.08, 0.6, 0.0, 6.0, 0.0, 1.0), noise_seed=3))
    assert d.found and not d.left_end_seen and not d.right_end_seen
    assert 0.5 < d.width < 6.0


def test_a_step_beyond_max_distance_or_too_low_is_not_reported():
    far = DETECTOR.detect(depth_image((0.1, 2.8, 0.0, 2.0, 0.0, 1.0)))
    assert not far.found and 'outside' in far.reason
    low = DETECTOR.detect(depth_image((0.01, 0.8, 0.0, 2.0, 0.0, 1.0)))
    assert not low.found


def test_no_return_anywhere_and_the_sky_are_no_step():
    blank = DETECTOR.detect(np.full((INTRINSICS.height, INTRINSICS.width), np.nan))
    assert not blank.found and 'no depth' in blank.reason
    # The camera turned 0.6 rad up (the car nose up): mostly sky, and the ground it sees
    # is nowhere near where the mounting says the ground should be.
    up = 0.6  # [rad]
    upward = Mount(MOUNT.rotation @ np.array([[1.0, 0.0, 0.0],
                                              [0.0, math.cos(up), -math.sin(up)],
                                              [0.0, math.sin(up), math.cos(up)]]),
                   MOUNT.position, MOUNT.ground_height, MOUNT.front_axle, MOUNT.self_reach)
    sky = depth_image(mount=upward, noise_seed=1)
    assert np.isnan(sky).mean() > 0.7
    detection = DETECTOR.detect(sky)
    assert not detection.found and 'no ground' in detection.reason


def test_an_image_of_another_size_is_refused():
    with pytest.raises(ValueError, match='106x60.*212x120'):
        DETECTOR.detect(np.zeros((60, 106)))


def _tilted(roll, pitch):
    """Return the mounting of a car rolled and pitched about base_link's origin [rad]."""
    cr, sr, cp, sp = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch)
    rotation = (np.array([[cp, 0.0, sp], [0.0, 1.0, 0.0], [-sp, 0.0, cp]])
                @ np.array([[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]]))
    return Mount(rotation @ MOUNT.rotation, rotation @ MOUNT.position, MOUNT.ground_height,
                 MOUNT.front_axle, MOUNT.self_reach)


@pytest.mark.parametrize('roll, pitch', [(0.06, 0.0), (0.0, -0.05), (0.06, -0.05)])
def test_a_tilted_car_still_measures_a_near_step(roll, pitch):
    # The car turning onto its approach rolls and pitches by a few degrees (the swivel lifts
    # it): a near step's top face then lay where the level ground should be, and the ground
    # fitted to both gave it 1.9 cm of its 4 cm, or no ground at all.
    step = (0.04, 0.5, 0.39, 2.5, 0.0, 3.0)
    d = DETECTOR.detect(depth_image(step, mount=_tilted(roll, pitch), noise_seed=1))
    assert d.found, d.reason
    assert d.height == pytest.approx(0.04, abs=0.005)
    assert d.distance == pytest.approx(0.5, abs=0.015) and d.yaw == pytest.approx(0.39, abs=0.02)
    assert d.ground_roll == pytest.approx(-roll, abs=0.005)
