"""
The model's kinematic and torque claims measured in physics, through the in-process stack.

Every measurement drives the car as the planner does: a ``swivel_command`` to the controller
(renewed every control period, the set point ramped at the command's rate), the sim's ground
truth read back. ``measure`` returns the rows of the fidelity table in
``docs/design_campaign.md`` (``python -m swivel_car_studies.design_report``): physics, the
model (``swivel_car_model`` with the robot description's parameters, at the swivel angle
physics reached) and the thesis. About 20 s of wall time.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np

from swivel_car_model import dynamics, kinematics, planar
from swivel_car_studies.inprocess import InProcessStack, StackConfig

SWIVEL_SAMPLES = (0.3, 0.6, 0.9, 1.2)  # [rad] where the standstill sweep is read
SWEEP_RATE = 0.1  # [rad/s] quasi-static, as the sim's model tests sweep
STEER_SAMPLES = (0.3, 0.6, 1.0)  # [rad] swivel held while driving
DRIVE_SPEED = 4.0  # [rad/s] at the wheels while turning
THESIS_STEP = 0.012  # [m] the thesis' comparison step (Sec. II.C.2, Fig. 31)


@dataclass(frozen=True)
class Row:
    """One line of the fidelity table: a claim, its value in physics, model and thesis."""

    claim: str
    physics: str
    model: str
    thesis: str


def _command(stack: InProcessStack, angle: float, rate: float, drive: float,
             duration: float) -> None:
    """
    Hold ``angle`` [rad] (reached at ``rate`` [rad/s]) and drive at ``drive`` [rad/s].

    For ``duration`` [s] of sim time, the command renewed every period as the planner's is.
    """
    for _ in range(round(duration / stack.control_period)):
        stack.controller.core.set_swivel_command(angle, rate, drive, True, stack.time)
        stack.settle(stack.control_period)


def _in_frame(start, end) -> tuple[float, float, float]:
    """Return ``end``'s pose in ``start``'s base_link frame: (dx [m], dy [m], dyaw [rad])."""
    dx, dy = (end.position - start.position)[:2]
    c, s = math.cos(start.yaw), math.sin(start.yaw)
    dyaw = math.remainder(end.yaw - start.yaw, math.tau)
    return c * dx + s * dy, -s * dx + c * dy, dyaw


def standstill_sweep(stack: InProcessStack) -> list[Row]:
    """
    Measure a swivel from 0 to the tip-safe limit at standstill (drive held at 0).

    The rows: lift angle and the lifted wheel's lowest point at ``SWIVEL_SAMPLES``, and the
    pose drift of the whole sweep.
    """
    p = stack.car
    limit = stack.controller.core.swivel_limit
    stack.reset()
    stack.settle(0.5)
    start = stack.sim.state()
    samples, rows = list(SWIVEL_SAMPLES), []
    for _ in range(round((limit / SWEEP_RATE + 1.0) / stack.control_period)):
        _command(stack, limit, SWEEP_RATE, 0.0, stack.control_period)
        state = stack.sim.state()
        theta2 = float(state.positions[0])
        if samples and theta2 >= samples[0]:
            samples.pop(0)
            lifted = float(stack.sim.wheel_lowest_points()[2])  # theta2 > 0 lifts the left
            rows.append(Row(f'lift angle theta1 at theta2 = {theta2:.3f} rad',
                            f'{-state.pitch:.4f} rad',
                            f'{float(kinematics.lift_angle(p, theta2)):.4f} rad',
                            'eq. 7 (corrected: the model)'))
            rows.append(Row(f"lifted wheel's lowest point at theta2 = {theta2:.3f} rad",
                            f'{lifted * 1000:.1f} mm',
                            f'{float(kinematics.lifted_wheel_lowest_height(p, theta2)) * 1000:.1f}'
                            ' mm', 'eqs. 14-16: not the lowest point (correction 7)'))
    end = stack.sim.state()
    theta2 = float(end.positions[0])
    dx, dy, dyaw = _in_frame(start, end)
    mx, my, myaw = dynamics.swivel_pose_drift(p, 0.0, theta2)
    rows.append(Row(f'pose drift of swivelling 0 -> {theta2:.3f} rad at standstill: position',
                    f'dx {dx * 1000:+.1f} mm, dy {dy * 1000:+.1f} mm (drive held at 0)',
                    f'dx {mx * 1000:+.1f} mm, dy {my * 1000:+.1f} mm (wheels rolling freely)',
                    '~2 cm backwards (Fig. 38, 0 -> pi/2)'))
    rows.append(Row('pose drift, same sweep: orientation', f'{dyaw:+.3f} rad',
                    f'{myaw:+.3f} rad', '~0.2 rad clockwise (-0.2)'))
    return rows


def turning(stack: InProcessStack) -> list[Row]:
    """
    Measure the turning radius with the swivel held at each of ``STEER_SAMPLES``, driving.

    Path length over heading change of the ground truth, against the offset tricycle and the
    thesis' plain tricycle (eq. 76 with the wheelbase corrected, item 21).
    """
    p, rows = stack.car, []
    for target in STEER_SAMPLES:
        stack.reset()
        stack.settle(0.2)
        _command(stack, target, 0.6, 0.0, target / 0.6 + 1.0)
        _command(stack, target, 0.6, DRIVE_SPEED, 2.0)
        first = len(stack.trajectory())
        _command(stack, target, 0.6, DRIVE_SPEED, 3.0)
        window = stack.trajectory(slice(first, None))
        x, y, z, w = window.orientation.T
        yaw = np.unwrap(np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z)))
        length = float(np.sum(np.linalg.norm(np.diff(window.position[:, :2], axis=0), axis=1)))
        radius = length / abs(yaw[-1] - yaw[0])
        theta2 = float(np.mean(window.joint_positions[:, 0]))
        steering = abs(float(kinematics.steering_angle(p, theta2)))
        rows.append(Row(f'turning radius at steering angle {steering:.3f} rad (theta2 = '
                        f'{theta2:.3f} rad)', f'{radius:.3f} m',
                        f'{1.0 / abs(planar.curvature_for_swivel(p, theta2)):.3f} m',
                        f'{p.wheelbase / math.tan(steering):.3f} m (eq. 76, plain tricycle)'))
    return rows


def step_torque(stack: InProcessStack, planner_rate: float) -> list[Row]:
    """
    Measure the peak swivel torque of lifting the front wheel over the thesis' 12 mm step.

    At standstill, the set point ramped at the planner's ``swivel_rate`` [rad/s].
    """
    p = stack.car
    theta2 = float(kinematics.swivel_for_step(p, THESIS_STEP))
    stack.reset()
    stack.settle(0.5)
    first = len(stack.trajectory())
    _command(stack, theta2, planner_rate, 0.0, theta2 / planner_rate + 3.0)
    peak = float(np.max(np.abs(stack.trajectory(slice(first, None)).swivel_torque)))
    model, _ = dynamics.climb_torque_energy(p, THESIS_STEP, planner_rate)
    return [Row(f'peak swivel torque lifting over the 12 mm step (theta2 = {theta2:.4f} rad, '
                f'ramped at {planner_rate:g} rad/s)', f'{peak:.2f} N m',
                f'{float(model):.2f} N m', '8 N m (Fig. 31)')]


def measure(config: StackConfig | None = None) -> list[Row]:
    """Every row of the fidelity table, on ``config`` (default: the installed one)."""
    with InProcessStack(config=config) as stack:
        return (standstill_sweep(stack) + turning(stack)
                + step_torque(stack, stack.config.planner.swivel_rate))
