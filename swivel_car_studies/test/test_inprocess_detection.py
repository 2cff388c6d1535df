"""The in-process stack's depth camera and detector: a detected climb's refusals (cheap)."""

from swivel_car_planner.core import ClimbRequest, ErrorCode
from swivel_car_studies.inprocess import InProcessStack

ANY = ClimbRequest(0.0, 0.0, 0.0)  # the geometry a detected climb ignores


def test_a_detected_climb_needs_the_camera_and_a_step_in_view():
    with InProcessStack() as stack:
        off = stack.climb(ANY, use_detected_step=True)
        assert off.error_code == ErrorCode.NO_STEP_DETECTED and 'camera is off' in off.message
        stack.enable_detection()
        stack.settle(0.3)  # three frames of flat ground
        flat = stack.climb(ANY, use_detected_step=True)
        assert flat.error_code == ErrorCode.NO_STEP_DETECTED, flat.message
        assert 'sees no step' in flat.message and stack.detection.frames == 3
        stack.spawn_step(0.05, 0.9, 0.1, width=2.5, depth=3.0)
        stack.settle(0.3)
        planned = stack.climb(ClimbRequest(0.0, 0.0, 0.0, plan_only=True),
                              use_detected_step=True)
        assert planned.success, planned.message
