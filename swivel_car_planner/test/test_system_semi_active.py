"""
System test of the semi-active climb (phi < 0, thesis III.B) through the ROS stack.

The phi < 0 design (swivel_car_model/config/designs/phi_negative.yaml) as every node's robot
description, the sim with the body's collision shapes (its belly hangs below the axle line),
unpaced lockstep; the climb is judged by the sim's ground truth.
"""

from pathlib import Path

from sim_session import SimSession
from swivel_car_msgs.msg import ClimbPlan
from swivel_car_msgs.srv import ClimbStep
import yaml

DESIGN = (Path(__file__).resolve().parents[2] / 'swivel_car_model' / 'config' / 'designs'
          / 'phi_negative.yaml')
HEIGHT = 0.05  # [m] below the 5.5 cm at which the belly meets the edge (design file)
DISTANCE = 1.8  # [m] room to turn onto its 0.75 rad approach
ROBOT = yaml.safe_load(DESIGN.read_text())['/**']['ros__parameters']


def test_the_phi_negative_robot_climbs_a_step_with_the_semi_active_procedure():
    session = SimSession(robot_parameters=ROBOT,
                         planner_parameters={'capability_file': 'none'},
                         sim_parameters={'body_collision': True})
    try:
        session.wait_ready()
        # Wide: the oblique approach crosses the edge about 1.3 m to the side.
        session.spawn_step(HEIGHT, DISTANCE, width=6.0, depth=3.0)
        response = session.climb(HEIGHT, DISTANCE)
        session.settle(0.5)
        assert response.plan.procedure == ClimbPlan.PROCEDURE_SEMI_ACTIVE
        assert session.front_on_top(HEIGHT), (response.message, session.truth)
        assert session.four_wheels_on_top(HEIGHT), (response.message, session.truth)
        assert response.success, response.message
        assert response.error_code == ClimbStep.Response.ERROR_NONE
    finally:
        crashed = session.close()
    assert not crashed, crashed
