"""Shared test helpers for swivel_car_sim."""

from __future__ import annotations

import numpy as np
import pytest

from swivel_car_sim.physics import SwivelCarSim
from swivel_car_sim.robot_state import RobotState

CONTROL_STEPS = 5  # [1] physics steps per 0.01 s control period


class SwivelHold:
    """
    A PD at 100 Hz that holds the swivel at a set point, the way the controller drives the sim.

    The real controller lives in swivel_car_control; this one only keeps tests independent of
    it: the description's kp and kd, the set point ramped at ``rate`` as the controller ramps
    it. A stepped set point rolls the car over once its weight is forward: the swivel
    overshoots to its joint limit and the rear body rolls onto one wheel.
    """

    def __init__(self, sim: SwivelCarSim, rate: float = 1.5) -> None:
        self.sim = sim
        self.kp, self.kd = sim.description.kp, sim.description.kd
        self.step_change = rate * CONTROL_STEPS * sim.config.time_step  # [rad] per control period
        self.set_point: float | None = None  # [rad]

    def period(self, swivel_target: float, drive_speed: float) -> RobotState:
        """
        Command from the state now and advance one control period.

        Returns the state before the period.
        """
        state = self.sim.state()
        if self.set_point is None:
            self.set_point = state.positions[0]
        self.set_point += float(np.clip(swivel_target - self.set_point,
                                        -self.step_change, self.step_change))
        torque = self.kp * (self.set_point - state.positions[0]) - self.kd * state.velocities[0]
        self.sim.set_command(torque, drive_speed)
        self.sim.step(CONTROL_STEPS)
        return state

    def run(self, periods: int, swivel_target: float, drive_speed: float) -> RobotState:
        for _ in range(periods):
            self.period(swivel_target, drive_speed)
        return self.sim.state()


@pytest.fixture
def sim():
    with SwivelCarSim() as s:
        yield s
