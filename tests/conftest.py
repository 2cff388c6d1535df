"""Fixtures shared by the system tests: an rclpy context on a fresh ROS domain."""

from __future__ import annotations

import os
from typing import Iterator

import pytest
import rclpy
from rclpy.context import Context
from swivel_car_testing import next_domain_id


@pytest.fixture
def ros_domain() -> Iterator[tuple[int, Context]]:
    """Give a fresh ROS_DOMAIN_ID and an rclpy context on it, shut down afterwards."""
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    domain_id = next_domain_id()
    context = Context()
    rclpy.init(context=context, domain_id=domain_id)
    try:
        yield domain_id, context
    finally:
        rclpy.try_shutdown(context=context)
