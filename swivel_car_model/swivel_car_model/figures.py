"""
Regenerate the thesis' model figures and the reproduction table.

``python -m swivel_car_model.figures --out docs/figures [--doc docs/thesis_reproduction.md]``
writes ``fig18.png`` ... ``fig61.png`` (matplotlib, Agg) and the markdown table of the thesis'
headline numbers (claim, thesis value, our value, reproduces?, why not), followed by the
corrections from ``CORRECTIONS.md`` in this package.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
from pathlib import Path
import time
from typing import Callable

import matplotlib
import matplotlib.pyplot as plt
import numpy as np

from swivel_car_model import climbing, dynamics, kinematics, planar
from swivel_car_model.params import SwivelCarParams

matplotlib.use('Agg')
P = SwivelCarParams()
PHIS = [math.pi / 12, math.pi / 6, math.pi / 4, math.pi / 3, 5 * math.pi / 12]
SWIVEL = np.linspace(0.0, math.pi / 2, 301)
SWIVEL_BOTH = np.linspace(-math.pi / 2, math.pi / 2, 401)
CLIMB_STEP = 0.012  # [m] the thesis' comparison step (Sec. II.C.2, Figs. 31, 60-61)
NEGATIVE = dataclasses.replace(P, phi=-P.phi)
CORRECTIONS = Path(__file__).resolve().parent.parent / 'CORRECTIONS.md'


def _phi_label(phi: float) -> str:
    return f'phi = {phi / math.pi * 12:+.0f} pi/12'


def _pair(title: str):
    fig, axes = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    fig.suptitle(title)
    return fig, axes


def _single(title: str, xlabel: str, ylabel: str):
    fig, ax = plt.subplots(figsize=(6, 4), constrained_layout=True)
    ax.set(title=title, xlabel=xlabel, ylabel=ylabel)
    ax.grid(True, alpha=0.3)
    return fig, ax


def _over_phi(title: str, ylabel: str, func: Callable, x=SWIVEL_BOTH):
    fig, axes = _pair(title)
    for ax, sign in zip(axes, (1.0, -1.0)):
        for phi in PHIS:
            p = dataclasses.replace(P, phi=sign * phi)
            ax.plot(x, func(p, x), label=_phi_label(p.phi))
        ax.set(xlabel='swivel angle theta2 [rad]', ylabel=ylabel)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
    return fig


def fig18():
    return _over_phi('Fig. 18: lift constraint', 'lift angle theta1 [rad]', kinematics.lift_angle)


def fig20():
    fig, axes = _pair('Fig. 20: path of the steering wheel contact point, theta2 0 -> pi/2')
    for ax, sign in zip(axes, (1.0, -1.0)):
        for phi in PHIS:
            p = dataclasses.replace(P, phi=sign * phi)
            x, y = kinematics.contact_point(p, SWIVEL)
            ax.plot(x, y, label=_phi_label(p.phi))
        ax.set(xlabel='x (base_link) [m]', ylabel='y (base_link) [m]', aspect='equal')
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
    return fig


def fig21():
    return _over_phi('Fig. 21: steering angle', 'steering angle [rad] (+ = left)',
                     kinematics.steering_angle)


def fig25():
    fig, ax = _single('Fig. 25: lowest point of the lifted wheel (Table 2)',
                      'swivel angle theta2 [rad]', 'height above ground [m]')
    ax.plot(SWIVEL, kinematics.lifted_wheel_lowest_height(P, SWIVEL))
    ax.axhline(2 * P.r, ls='--', c='gray', label='wheel diameter')
    ax.legend()
    return fig


def _lowest_over(field: str, values, unit_scale: float, unit: str, number: int):
    fig, ax = _single(f'Fig. {number}: lowest point of the lifted wheel vs {field}',
                      'swivel angle theta2 [rad]', 'height above ground [m]')
    for value in values:
        p = dataclasses.replace(P, **{field: value})
        ax.plot(SWIVEL, kinematics.lifted_wheel_lowest_height(p, SWIVEL),
                label=f'{field} = {value * unit_scale:g} {unit}')
    ax.legend(fontsize=7)
    return fig


def fig26():
    return _lowest_over('phi', PHIS, 12 / math.pi, 'pi/12', 26)


def fig27():
    return _lowest_over('h', [0.1, 0.15, 0.2, 0.25], 100, 'cm', 27)


def fig28():
    return _lowest_over('l', [0.2, 0.25, 0.3, 0.4], 100, 'cm', 28)


def fig29():
    return _lowest_over('r', [0.05, 0.075, 0.1, 0.125], 100, 'cm', 29)


def fig31():
    theta2 = kinematics.swivel_for_step(P, CLIMB_STEP)
    move = dynamics.simulate_swivel_move(P, theta2, duration=40.0, samples=2001)
    fig, axes = _pair(f'Fig. 31: climbing a {CLIMB_STEP * 1000:.0f} mm step '
                      f'(theta2 = {theta2:.3f} rad), part 1 (part 3 mirrors it)')
    axes[0].plot(move.time, move.torque)
    axes[0].set(xlabel='time [s]', ylabel='swivel torque [N m]')
    axes[1].plot(move.time, move.energy, label='int |tau w| dt')
    axes[1].plot(move.time, move.work, '--', label='net work')
    axes[1].set(xlabel='time [s]', ylabel='energy [J]')
    axes[1].legend()
    for ax in axes:
        ax.grid(True, alpha=0.3)
    return fig


def _peak_torque_over_h(hs):
    return [dynamics.climb_torque_energy(dataclasses.replace(P, h=h), CLIMB_STEP)[0] for h in hs]


def fig32():
    hs = np.array([0.1, 0.125, 0.15, 0.175, 0.2, 0.25])
    fig, ax = _single(f'Fig. 32: peak swivel torque for a {CLIMB_STEP * 1000:.0f} mm step',
                      'wheel shaft length h [m]', 'peak torque [N m]')
    ax.plot(hs, _peak_torque_over_h(hs), 'o-')
    return fig


def fig35():
    state = kinematics.kinematic_state(P, SWIVEL)
    fig, ax = _single('Fig. 35: planar inputs u, v, alpha', 'swivel angle theta2 [rad]',
                      '[m] / [rad]')
    ax.plot(SWIVEL, state.contact_x - P.wheelbase, label='u = a - wheelbase [m]')
    ax.plot(SWIVEL, state.contact_y, label='v = b [m]')
    ax.plot(SWIVEL, state.steering, label='alpha = steering [rad]')
    ax.legend()
    return fig


@dataclasses.dataclass
class _Cache:
    planar: dynamics.PlanarResult | None = None
    climb: tuple | None = None
    car: dynamics.CrankClimbResult | None = None


_CACHE = _Cache()


def _planar_run() -> dynamics.PlanarResult:
    if _CACHE.planar is None:
        _CACHE.planar = dynamics.simulate_planar_swivel(P)
    return _CACHE.planar


def _car_run() -> dynamics.CrankClimbResult:
    if _CACHE.car is None:
        _CACHE.car = dynamics.simulate_car_like_climb(
            dynamics.CarLikeParams(step_height=CLIMB_STEP))
    return _CACHE.car


def fig38():
    run = _planar_run()
    fig, axes = _pair('Fig. 38: pose while the swivel turns 0 -> pi/2 at 0.05 rad/s')
    axes[0].plot(run.time, run.x, label='x')
    axes[0].plot(run.time, run.y, label='y')
    axes[0].set(xlabel='time [s]', ylabel='position [m]')
    axes[0].legend()
    axes[1].plot(run.time, run.yaw)
    axes[1].set(xlabel='time [s]', ylabel='yaw [rad] (+ = counter-clockwise)')
    for ax in axes:
        ax.grid(True, alpha=0.3)
    return fig


def fig40():
    theta2 = kinematics.swivel_for_steering(P, math.pi / 6)
    odom = planar.OffsetTricycleOdometry(P)
    xs, ys = [0.0], [0.0]
    for _ in range(7000):
        odom.update(theta2, 0.0, 0.1, 0.1)
        xs.append(odom.x)
        ys.append(odom.y)
    fig, ax = _single('Fig. 40: path at steering pi/6, rear wheels 0.1 rad/s, dt 0.1 s',
                      'x [m]', 'y [m]')
    ax.plot(xs, ys)
    ax.set_aspect('equal')
    return fig


def _induced_vs_drive(field: str, values, number: int):
    fig, ax = _single(f'Fig. {number}: induced swivel torque vs drive torque (phi = -pi/3)',
                      'drive torque tau_D [N m]', 'assisting torque tau_S [N m]')
    drive = np.linspace(0.0, 10.0, 51)
    for value in values:
        p = dataclasses.replace(NEGATIVE, wheel_width=0.005, **{field: value})
        ax.plot(drive, climbing.induced_swivel_torque(p, drive), label=f'{field} = {value:g} m')
    ax.legend(fontsize=7)
    return fig


def fig48():
    return _induced_vs_drive('h', [0.01, 0.02, 0.03, 0.04, 0.05], 48)


def fig49():
    return _induced_vs_drive('r', [0.05, 0.07, 0.09, 0.11, 0.13], 49)


def _induced_vs_swivel(field: str, values, number: int):
    fig, ax = _single(f'Fig. {number}: induced swivel torque vs swivel angle '
                      '(phi = -pi/3, tau_D = 5 N m)', 'swivel angle theta2 [rad]',
                      'assisting torque tau_S [N m]')
    for value in values:
        p = dataclasses.replace(NEGATIVE, wheel_width=0.005, **{field: value})
        ax.plot(SWIVEL, climbing.induced_swivel_torque(p, 5.0, SWIVEL),
                label=f'{field} = {value:g} m')
    ax.legend(fontsize=7)
    return fig


def fig50():
    return _induced_vs_swivel('h', [0.05, 0.1, 0.15, 0.2], 50)


def fig51():
    return _induced_vs_swivel('r', [0.05, 0.075, 0.1, 0.125], 51)


def _ground_path(title: str, points: dict):
    fig, ax = _single(title, 'x (base_link) [m]', 'y (base_link) [m]')
    for label, xy in points.items():
        ax.plot(xy[:, 0], xy[:, 1], label=label)
        ax.plot(xy[0, 0], xy[0, 1], 'o', c='red')
    ax.set_aspect('equal')
    ax.legend(fontsize=7)
    return fig


def fig54():
    return _ground_path('Fig. 54: P_L (lifted wheel lowest point), phi = -pi/3',
                        {'P_L': climbing.lifted_wheel_lowest_point(NEGATIVE, SWIVEL)})


def fig55():
    return _ground_path('Fig. 55: C_F (steering wheel front point), phi = -pi/3',
                        {'C_F': climbing.steering_wheel_front_point(NEGATIVE, SWIVEL)})


def fig56():
    return _ground_path('Fig. 56: P_L and C_F, phi = -pi/3',
                        {'P_L': climbing.lifted_wheel_lowest_point(NEGATIVE, SWIVEL),
                         'C_F': climbing.steering_wheel_front_point(NEGATIVE, SWIVEL)})


def fig57():
    fig, ax = _single('Fig. 57: minimum approach angle (phi = -pi/3)',
                      'swivel angle theta2 [rad]', 'alpha_S [rad]')
    ax.plot(SWIVEL, climbing.min_approach_angle(NEGATIVE, SWIVEL))
    return fig


def fig58():
    reach, _ = kinematics.max_scalable_step(NEGATIVE)
    steps = np.linspace(0.0, reach, 200)
    fig, ax = _single('Fig. 58: minimum approach angle vs step height (phi = -pi/3)',
                      'step height [m]', 'alpha_S [rad]')
    ax.plot(steps, climbing.min_approach_angle_for_step(NEGATIVE, steps))
    return fig


def fig60():
    run = _car_run()
    fig, ax = _single(f'Fig. 60: car-like robot, {CLIMB_STEP * 1000:.0f} mm step: torque',
                      'time [s]', 'crank torque tau_w [N m]')
    ax.plot(run.time, run.torque)
    return fig


def fig61():
    run = _car_run()
    fig, ax = _single(f'Fig. 61: car-like robot, {CLIMB_STEP * 1000:.0f} mm step: energy',
                      'time [s]', 'energy [J]')
    ax.plot(run.time, run.energy)
    return fig


FIGURES: dict[int, Callable] = {
    18: fig18, 20: fig20, 21: fig21, 25: fig25, 26: fig26, 27: fig27, 28: fig28, 29: fig29,
    31: fig31, 32: fig32, 35: fig35, 38: fig38, 40: fig40, 48: fig48, 49: fig49, 50: fig50,
    51: fig51, 54: fig54, 55: fig55, 56: fig56, 57: fig57, 58: fig58, 60: fig60, 61: fig61,
}


# ----------------------------------------------------------------------------------------------
# headline numbers

@dataclasses.dataclass(frozen=True)
class Claim:
    claim: str
    thesis: str
    ours: str
    reproduces: bool
    why_not: str = ''


def _yes(flag: bool) -> str:
    return 'yes' if flag else 'no'


def headline_claims() -> list[Claim]:
    """Each thesis headline claim with our value (computed now)."""
    claims = []
    quarter = float(kinematics.steering_angle(P, math.pi / 2))
    claims.append(Claim('steering angle pi/2 reachable (turn about the rear axle)', 'pi/2',
                        f'{abs(quarter):.4f} rad at theta2 = pi/2',
                        abs(abs(quarter) - math.pi / 2) < 1e-9))
    # Sec. II.B.4: phi = +-pi/3 give 0.5 and 0.75 rad (at one swivel angle)
    at = kinematics.swivel_for_steering(P, -0.5)
    neg = float(kinematics.steering_angle(NEGATIVE, at))
    claims.append(Claim('steering of phi = -pi/3 vs +pi/3 at the same theta2', '0.75 vs 0.5 rad',
                        f'{abs(neg):.3f} vs 0.5 rad (theta2 = {abs(at):.3f} rad)',
                        abs(abs(neg) - 0.75) < 0.05,
                        'the swivel angle is not given; the ordering (phi < 0 steers more) '
                        'holds' if abs(abs(neg) - 0.75) >= 0.05 else ''))
    claims.append(Claim('theta2 > 0 steers clockwise for phi > 0, counter-clockwise for '
                        'phi < 0', 'yes',
                        f'{float(kinematics.steering_angle(P, 0.5)):+.3f} / '
                        f'{float(kinematics.steering_angle(NEGATIVE, 0.5)):+.3f} rad at 0.5',
                        kinematics.steering_angle(P, 0.5) < 0 < kinematics.steering_angle(
                            NEGATIVE, 0.5)))
    reach, reach_theta2 = kinematics.max_scalable_step(P)
    claims.append(Claim('max scalable step (Fig. 25)', '~ wheel diameter, 0.15 m',
                        f'{reach:.3f} m at theta2 = {reach_theta2:.3f} rad',
                        abs(reach - 2 * P.r) < 0.02,
                        'eqs. 14-16 are not the lowest rim point; the exact lowest point is '
                        '2 h sin(theta2) cos(theta1 - phi/2)'))
    by_r = [kinematics.max_scalable_step(dataclasses.replace(P, r=r))[0]
            for r in (0.05, 0.075, 0.1, 0.125)]
    by_l = [kinematics.max_scalable_step(dataclasses.replace(P, l=v))[0]
            for v in (0.2, 0.25, 0.3, 0.4)]
    spread_r, spread_l = max(by_r) - min(by_r), max(by_l) - min(by_l)
    claims.append(Claim('max step independent of r (Fig. 29)', 'independent',
                        f'spread {spread_r * 1000:.1f} mm over r = 5..12.5 cm', spread_r < 0.005,
                        'r enters through the lift angle only' if spread_r >= 0.005 else ''))
    claims.append(Claim('max step independent of l (Fig. 28)', 'independent',
                        f'spread {spread_l * 1000:.1f} mm over l = 20..40 cm', spread_l < 0.005,
                        'l sets the lift angle, which tilts the shaft' if spread_l >= 0.005
                        else ''))
    at_012 = float(kinematics.lifted_wheel_lowest_height(P, 0.12))
    need = float(kinematics.swivel_for_step(P, CLIMB_STEP))
    claims.append(Claim('swivel angle that clears a 12 mm step', '0.12 rad',
                        f'{need:.4f} rad (0.12 rad clears {at_012 * 1000:.1f} mm)',
                        abs(need - 0.12) < 0.01, 'the thesis used its eqs. 14-16'))
    peak, energy = dynamics.climb_torque_energy(P, CLIMB_STEP)
    move = dynamics.simulate_swivel_move(P, need, duration=40.0)
    holding = float(dynamics.swivel_gravity_torque(P, 1e-9))
    claims.append(Claim('peak swivel torque, 12 mm climb (Fig. 31)', '8 N m', f'{peak:.2f} N m',
                        abs(peak - 8.0) < 1.0,
                        f'the holding torque at theta2 = 0+ alone is m g l cos(phi/2) h/(2l) '
                        f'= {holding:.2f} N m; with the thesis gains the PID waits for its '
                        f'integral to reach it (moves after '
                        f'{float(move.time[np.argmax(move.theta2 > 1e-6)]):.1f} s)'))
    theta1 = float(kinematics.lift_angle(P, need))
    rise = P.mass * dynamics.GRAVITY * P.l * (math.sin(theta1 + P.phi / 2) - math.sin(P.phi / 2))
    claims.append(Claim('energy, 12 mm climb (Fig. 31)', '3 J',
                        f'{energy:.2f} J (parts 1 + 3)', abs(energy - 3.0) < 0.5,
                        f'the work is essentially the apex potential energy gain, '
                        f'{rise:.3f} J per part (theta1 = {theta1:.4f} rad); 3 J would need '
                        f'the 0.12 rad swivel of the thesis' if abs(energy - 3.0) >= 0.5
                        else ''))
    hs = np.array([0.1, 0.15, 0.2, 0.25])
    peaks = np.array(_peak_torque_over_h(hs))
    fit = np.polyfit(hs, peaks, 1)
    linear_error = float(np.max(np.abs(np.polyval(fit, hs) - peaks)))
    linear = linear_error < 0.05 * float(np.ptp(peaks))
    claims.append(Claim('peak torque linear in h (Fig. 32)', 'linear',
                        f'{peaks[0]:.2f} .. {peaks[-1]:.2f} N m, max deviation from a line '
                        f'{linear_error:.3f} N m', linear,
                        '' if linear else 'the peak is no longer the holding torque at 0+'))
    run = _planar_run()
    dx, dy, dyaw = float(run.x[-1]), float(run.y[-1]), float(run.yaw[-1])
    claims.append(Claim('pose drift while the swivel turns 0 -> pi/2: position (Fig. 38)',
                        '~0.02 m, mostly backwards',
                        f'dx = {dx * 1000:+.1f} mm, dy = {dy * 1000:+.1f} mm',
                        dx < 0 and abs(dx) > abs(dy) and abs(math.hypot(dx, dy) - 0.02) < 0.005,
                        'direction reproduces (backwards); the size depends on the mass '
                        'distribution and the contact-point geometry, which the thesis model '
                        '(eqs. 31-35: front wheels at 2l + u instead of 2l cos(phi/2) + u, no '
                        'I_car value) gets differently'))
    claims.append(Claim('pose drift: orientation (Fig. 38)', '~0.2 rad clockwise',
                        f'{dyaw:+.3f} rad', dyaw < 0 and abs(dyaw - (-0.2)) < 0.05,
                        'clockwise reproduces; the yaw is nearly kinematic here (it changes '
                        '< 1 % between a massless and a heavy body): the contact point sweeps '
                        'h sideways in the body while it cannot skid' if abs(dyaw + 0.2) >= 0.05
                        else ''))
    trend = {}
    for field, lo, hi in (('h', 0.15, 0.2), ('phi', math.pi / 6, 5 * math.pi / 12),
                          ('l', 0.3, 0.4)):
        drift = [abs(dynamics.swivel_pose_drift(dataclasses.replace(P, **{field: v}), 0.0,
                                                math.pi / 2)[2]) for v in (lo, hi)]
        trend[field] = drift[1] > drift[0]
    claims.append(Claim('Table 3: the yaw drift grows with h, shrinks with phi and l',
                        'h up, phi down, l down',
                        f"h {'up' if trend['h'] else 'down'}, phi "
                        f"{'up' if trend['phi'] else 'down'}, l {'up' if trend['l'] else 'down'}",
                        trend['h'] and not trend['phi'] and not trend['l'],
                        '' if trend['h'] and not trend['phi'] and not trend['l'] else
                        'see the values above: the exact contact path changes the trend'))
    car = _car_run()
    claims.append(Claim('car-like robot, 12 mm step: peak torque (Fig. 60)', '6.5 N m',
                        f'{car.peak_torque:.2f} N m', abs(car.peak_torque - 6.5) < 0.5,
                        'with the P controller of eq. 109 the peak is Kp (pi/2 - theta_w0) at '
                        'the start'))
    claims.append(Claim('car-like robot, 12 mm step: energy (Fig. 61)', '3.2 J',
                        f'{car.total_energy:.2f} J (until the wheel is over the edge)',
                        abs(car.total_energy - 3.2) < 0.5,
                        'eq. 110 is the work of the crank torque: potential energy gain plus '
                        'the kinetic energy left at the edge; Table 4 gives neither 3.2 J nor '
                        '6.5 N m with a 12 or 16 mm step'))
    claims.append(Claim('swivel car needs a higher peak torque than the car-like robot',
                        'yes (8 vs 6.5 N m)', f'{peak:.2f} vs {car.peak_torque:.2f} N m',
                        peak > car.peak_torque))
    q = SwivelCarParams(phi=-math.pi / 3)
    zero = float(climbing.induced_swivel_torque(q, 5.0))
    top = float(climbing.induced_swivel_torque(q, 5.0, math.pi / 2))
    claims.append(Claim('phi < 0: assisting torque h (tau_D / r) sin(abs(phi)/2) at theta2 = 0, '
                        'tau_D = 5 N m', f'{q.h * 5.0 / q.r * 0.5:.2f} N m (corrected eq. 86)',
                        f'{zero:.2f} N m', abs(zero - q.h * 5.0 / q.r * 0.5) < 1e-9))
    claims.append(Claim('phi < 0: assisting torque vanishes at theta2 = pi/2', '0',
                        f'{top:.2f} N m', abs(top) < 0.05 * abs(zero),
                        'the force still has a lever about the pitched swivel axis'
                        if abs(top) >= 0.05 * abs(zero) else ''))
    return claims


HAND_WRITTEN = 'Written by hand (`python -m swivel_car_model.figures` does not write this section)'


def hand_written_sections(path: Path) -> list[str]:
    """
    Return the hand-written sections of the existing document at ``path``.

    The lines of each ``## `` section whose text starts with ``HAND_WRITTEN`` (measurements in
    physics, which the model cannot make), so that writing the table again keeps them.
    """
    if not path.exists():
        return []
    kept, section = [], []
    for line in path.read_text().splitlines() + ['## ']:
        if line.startswith('## '):
            body = [text for text in section[1:] if text.strip()]
            if body and body[0].startswith(HAND_WRITTEN):
                kept += section
            section = []
        section.append(line)
    return kept


def write_table(path: Path, claims: list[Claim], figures: list[str]) -> None:
    lines = [
        '# Thesis reproduction',
        '',
        'Generated by `python -m swivel_car_model.figures --out docs/figures` (do not edit by '
        'hand; the corrections below come from `swivel_car_model/CORRECTIONS.md`). Parameters: '
        'thesis Table 2 (r = 7.5 cm) unless a claim says otherwise.',
        '',
        '| claim | thesis | ours | reproduces? | why not |',
        '|---|---|---|---|---|',
    ]
    for c in claims:
        lines.append(f'| {c.claim} | {c.thesis} | {c.ours} | {_yes(c.reproduces)} | '
                     f'{c.why_not if not c.reproduces else ""} |')
    lines += ['', f'Figures ({len(figures)}; `python -m swivel_car_model.benchmark` times them): '
              + ', '.join(f'[{name}](figures/{name})' for name in figures), '']
    lines += hand_written_sections(path)
    if CORRECTIONS.exists():
        lines += [CORRECTIONS.read_text().rstrip(), '']
    path.write_text('\n'.join(lines))


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--out', type=Path, default=Path('docs/figures'))
    parser.add_argument('--doc', type=Path, default=None,
                        help='markdown table to write (default: <out>/../thesis_reproduction.md)')
    parser.add_argument('--only', type=int, nargs='*', help='figure numbers to make')
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    names = []
    for number, make in FIGURES.items():
        if args.only and number not in args.only:
            continue
        fig = make()
        name = f'fig{number}.png'
        fig.savefig(args.out / name, dpi=90)
        plt.close(fig)
        names.append(name)
    seconds = time.perf_counter() - start
    if not args.only:
        doc = args.doc or args.out.parent / 'thesis_reproduction.md'
        write_table(doc, headline_claims(), names)
        print(f'wrote {doc}')
    print(f'wrote {len(names)} figures to {args.out} in {seconds:.1f} s')


if __name__ == '__main__':
    main()
