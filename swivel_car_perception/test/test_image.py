"""An Image's fields to metres, refused in one line when they do not fit; ROS-free."""

import numpy as np
import pytest
from swivel_car_perception.core.detector import Intrinsics
from swivel_car_perception.core.image import depth_from_fields, intrinsics_from_camera_info

K = Intrinsics(4, 2, 3.0, 3.0, 2.0, 0.0)


def test_32fc1_and_16uc1_in_either_byte_order():
    metres = np.array([[0.5, np.nan, 1.0, 2.0], [3.0, 4.0, 5.0, 6.0]])
    for order, flag in (('<', 0), ('>', 1)):
        data = metres.astype(order + 'f4').tobytes()
        np.testing.assert_array_equal(
            depth_from_fields('32FC1', 4, 2, 16, flag, data, K), metres)
    millimetres = np.array([[500, 0, 1000, 2000], [3000, 4000, 5000, 6000]], dtype='<u2')
    # A row padded to 10 bytes.
    padded = np.zeros((2, 10), dtype=np.uint8)
    padded[:, :8] = millimetres.view(np.uint8).reshape(2, 8)
    np.testing.assert_array_equal(
        depth_from_fields('16UC1', 4, 2, 10, 0, padded.tobytes(), K), metres)


@pytest.mark.parametrize('encoding, width, height, step, size, words', [
    ('rgb8', 4, 2, 12, 24, 'not a depth encoding'),
    ('32FC1', 8, 2, 32, 64, '8x2 but its camera_info says 4x2'),
    ('32FC1', 4, 2, 16, 20, 'does not fill')])
def test_images_that_do_not_fit_are_refused(encoding, width, height, step, size, words):
    with pytest.raises(ValueError, match=words) as error:
        depth_from_fields(encoding, width, height, step, 0, bytes(size), K)
    assert '\n' not in str(error.value)


def test_camera_info_without_a_camera_matrix_is_refused():
    assert intrinsics_from_camera_info(4, 2, [3, 0, 2, 0, 3, 0, 0, 0, 1]) == K
    with pytest.raises(ValueError, match='not a camera matrix'):
        intrinsics_from_camera_info(4, 2, [0.0] * 9)
    with pytest.raises(ValueError, match='no image size'):
        intrinsics_from_camera_info(0, 0, [3, 0, 2, 0, 3, 0, 0, 0, 1])
