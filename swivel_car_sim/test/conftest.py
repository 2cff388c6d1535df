"""Shared test helpers for swivel_car_sim."""

from __future__ import annotations

import pytest

from swivel_car_sim.physics import RobotState, SwivelCarSim

CONTROL_STEPS = 5  # [1] physics steps per 0.01 s control period


class SwivelHold:
    """Holds the swivel at a set point with a PD at 100 Hz, the way the controller drives
    the sim (the real controller lives in swivel_car_control; this one only keeps tests
    independent of it). kd stays well below the discrete limit 2 I / dt with the front T's
    inertia about the swivel axis, I = 0.036 kg m^2."""

    def __init__(self, sim: SwivelCarSim, kp: float = 60.0, kd: float = 2.0) -> None:
        self.sim, self.kp, self.kd = sim, kp, kd

    def period(self, swivel_target: float, drive_speed: float) -> RobotState:
        """Command from the state now, advance one control period; returns the state
        before the period."""
        state = self.sim.state()
        torque = self.kp * (swivel_target - state.positions[0]) - self.kd * state.velocities[0]
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
