"""
The demo's report: plots of what the stack did and frames of the climb.

The frames are rendered by pybullet's own renderer; one markdown page beside its PNGs, all
drawn from the run's rosbag2 bag (read with rosbags, from the message definitions in the bag).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
from rosbags.highlevel import AnyReader
from swivel_car_model.params import SwivelCarParams
from swivel_car_sim.physics import SimConfig, SwivelCarSim
from swivel_car_sim.world import StepSpec

matplotlib.use('Agg')

FRAME_COUNT = 8
# The report's Python example: it reads the bag and plots one topic (run by tests/test_tf.py on
# a bag the real recorder wrote).
READING_EXAMPLE = """\
from pathlib import Path

import matplotlib.pyplot as plt
from rosbags.highlevel import AnyReader

with AnyReader([Path('report/bag')]) as reader:
    joint_states = [c for c in reader.connections if c.topic == '/joint_states']
    t, swivel = [], []
    for connection, _, data in reader.messages(connections=joint_states):
        msg = reader.deserialize(data, connection.msgtype)
        t.append(msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec)
        swivel.append(msg.position[msg.name.index('swivel_joint')])
plt.plot(t, swivel)
plt.xlabel('sim time [s]')
plt.ylabel('swivel angle [rad]')
plt.savefig('swivel_angle.png')
print(f'{len(t)} joint_states plotted to swivel_angle.png')
"""
# Shipped with swivel_car_telemetry: 3D view following base_link, the swivel angle, pitch and
# torque, and the climb's feedback.
FOXGLOVE_LAYOUT = 'swivel_car_telemetry/config/foxglove_layout.json'


@dataclass
class Recording:
    """Time series of the stack's topics, stamped in sim time."""

    truth: list[tuple[float, float, float, float, float, float, float, float]] = field(
        default_factory=list)  # t [s], x, y, z [m], quaternion x, y, z, w
    odom: list[tuple[float, float, float]] = field(default_factory=list)  # t, x, y
    joints: list[tuple[float, np.ndarray]] = field(default_factory=list)  # t, positions [rad]
    control: list[tuple[float, float, float, float, float]] = field(
        default_factory=list)  # t, set point, measured [rad], rate [rad/s], torque [N m]
    joint_names: tuple[str, ...] = ()


def _seconds(header) -> float:
    return header.stamp.sec + 1e-9 * header.stamp.nanosec


def read_bag(path: Path) -> Recording:
    """Read the report's time series from a bag the recorder wrote."""
    recording = Recording()
    with AnyReader([path]) as reader:
        wanted = [c for c in reader.connections if c.topic in (
            '/ground_truth/odom', '/odom', '/joint_states', '/controller/controller_state')]
        for connection, _, data in reader.messages(connections=wanted):
            msg = reader.deserialize(data, connection.msgtype)
            t = _seconds(msg.header)
            if connection.topic == '/ground_truth/odom':
                p, q = msg.pose.pose.position, msg.pose.pose.orientation
                recording.truth.append((t, p.x, p.y, p.z, q.x, q.y, q.z, q.w))
            elif connection.topic == '/odom':
                p = msg.pose.pose.position
                recording.odom.append((t, p.x, p.y))
            elif connection.topic == '/joint_states':
                recording.joint_names = tuple(msg.name)
                recording.joints.append((t, np.array(msg.position)))
            else:
                recording.control.append((t, msg.set_point, msg.measured, msg.measured_rate,
                                          msg.torque))
    return recording


def _pitch(quaternions: np.ndarray) -> np.ndarray:
    """Return the REP-103 pitch (positive nose down) of rows of (x, y, z, w) [rad]."""
    x, y, z, w = quaternions.T
    return np.arcsin(np.clip(2.0 * (w * y - z * x), -1.0, 1.0))


def _shade_climb(axis, summary: dict) -> None:
    axis.axvspan(summary['climb_start'], summary['climb_end'], color='tab:orange', alpha=0.12,
                 label='climb_step running')


def plot_path(recording, step: StepSpec, out: Path) -> None:
    truth, odom = np.array(recording.truth), np.array(recording.odom)
    fig, axis = plt.subplots(figsize=(8, 3.2))
    axis.plot(truth[:, 1], truth[:, 2], label='ground truth (sim)', linewidth=2.5)
    axis.plot(odom[:, 1], odom[:, 2], '--', label='odometry (tricycle with offset)')
    # The robot starts at the world origin, so the step's edge is this far ahead of it.
    edge = step.distance + SwivelCarParams().wheelbase
    axis.fill_between([edge, edge + step.depth], -step.width / 2, step.width / 2,
                      color='grey', alpha=0.25, label=f'step, {step.height * 100:.0f} cm high')
    axis.set_xlabel('x [m]')
    axis.set_ylabel('y [m]')
    axis.set_aspect('equal', adjustable='datalim')
    axis.legend(loc='best', fontsize=8)
    axis.set_title('Path of base_link (rear axle middle)')
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


def plot_time_series(recording, summary: dict, out: Path) -> None:
    truth, control = np.array(recording.truth), np.array(recording.control)
    t_control = control[:, 0]
    torque, rate = control[:, 4], control[:, 3]
    power = np.abs(torque * rate)
    energy = np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1])
                                              * np.diff(t_control))])
    fig, axes = plt.subplots(4, 1, figsize=(8, 9), sharex=True)
    axes[0].plot(t_control, control[:, 2], label='measured')
    axes[0].plot(t_control, control[:, 1], '--', label='set point')
    axes[0].set_ylabel('swivel angle [rad]')
    axes[1].plot(truth[:, 0], -_pitch(truth[:, 4:8]), color='tab:green')
    axes[1].set_ylabel('nose-up pitch [rad]')
    axes[2].plot(t_control, torque, color='tab:red')
    axes[2].set_ylabel('swivel torque [N m]')
    axes[3].plot(t_control, energy, color='tab:purple')
    axes[3].set_ylabel('swivel energy [J]')
    axes[3].set_xlabel('sim time [s]')
    for axis in axes:
        _shade_climb(axis, summary)
        axis.grid(alpha=0.3)
    axes[0].legend(loc='best', fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


def render_frames(recording, summary: dict, step: StepSpec, folder: Path) -> None:
    """
    Replay the recorded climb in a fresh pybullet world and render it.

    The recorded ground truth and joint angles, in a world holding the same robot and step,
    rendered with pybullet's renderer: a strip of frames of the climb (frames.png) and,
    larger, the moment the swivel is turned furthest (car.png).
    """
    truth = np.array(recording.truth)
    joint_times = np.array([t for t, _ in recording.joints])
    swivel_index = recording.joint_names.index('swivel_joint')
    times = np.linspace(summary['climb_start'], summary['climb_end'], FRAME_COUNT)
    frames = []
    with SwivelCarSim(SimConfig()) as sim:
        sim.spawn_obstacle(step)

        def show(t: float) -> np.ndarray:
            row = truth[np.argmin(np.abs(truth[:, 0] - t))]
            positions = recording.joints[int(np.argmin(np.abs(joint_times - t)))][1]
            sim.show_state(row[1:4], row[4:8], dict(zip(recording.joint_names, positions)))
            return row[1:4] + [0.2, 0.0, 0.0]

        for t in times:
            frames.append(sim.render(width=320, height=240, target=show(t)))
        swivel = [abs(positions[swivel_index]) for _, positions in recording.joints]
        target = show(recording.joints[int(np.argmax(swivel))][0])
        plt.imsave(folder / 'car.png', sim.render(width=800, height=450, target=target))
    fig, axes = plt.subplots(2, FRAME_COUNT // 2, figsize=(12, 4.6))
    for axis, image, t in zip(axes.flat, frames, times):
        axis.imshow(image)
        axis.set_title(f't = {t:.1f} s', fontsize=9)
        axis.axis('off')
    fig.tight_layout()
    fig.savefig(folder / 'frames.png', dpi=100)
    plt.close(fig)


def write_report(summary: dict, recording, step: StepSpec, folder: Path) -> Path:
    """Write the plots, the frames and index.md into ``folder``; return the page's path."""
    folder.mkdir(parents=True, exist_ok=True)
    plot_path(recording, step, folder / 'path.png')
    plot_time_series(recording, summary, folder / 'time_series.png')
    render_frames(recording, summary, step, folder)
    rows = [
        ('climb', 'succeeded' if summary['success'] else f"failed: {summary['message']}"),
        ('step height', f"{summary['step_height'] * 100:.1f} cm"),
        ('swivel angle planned', f"{summary['swivel_angle']:.3f} rad"),
        ('climb time (sim)', f"{summary['climb_time']:.1f} s"),
        ('whole demo', f"{summary['sim_time']:.1f} s sim, {summary['wall_time']:.1f} s wall"),
        ('peak swivel torque', f"{summary['peak_torque']:.2f} N m "
                               f"(model: {summary['planned_peak_torque']:.2f} N m)"),
        ('swivel energy', f"{summary['energy']:.2f} J (model: {summary['planned_energy']:.2f} J)"),
        ('odometry end error', f"{summary['odometry_error'] * 100:.1f} cm over "
                               f"{summary['path_length']:.2f} m "
                               f"({summary['odometry_error_percent']:.1f} %)"),
    ]
    table = '\n'.join(f'| {name} | {value} |' for name, value in rows)
    page = folder / 'index.md'
    page.write_text(f"""# Swivel car demo: driving to a step and climbing it

The stack ran as four processes (`sim_node`, `controller_node`, `odometry_node`,
`planner_node`) on sim time in lockstep, beside `robot_description_node` and `recorder_node`;
the demo drove with `cmd_vel` and called the `climb_step` action. Everything below is drawn
from the run's recording, [`bag/`](bag) (rosbag2, MCAP storage). Shaded: while the climb ran.

| | |
|---|---|
{table}

## Frames of the climb (pybullet's renderer, replaying the ground truth)
![frames](frames.png)

The swivel turned furthest:

![the car](car.png)

## Path: odometry beside ground truth
![path](path.png)

## Swivel angle, pitch, swivel torque and energy
![time series](time_series.png)

## Opening the recording
`bag/` holds every topic of the run (`/clock` included, sim time) with the message
definitions, so no swivel_car package is needed to read it:
- Foxglove: "Open local file", `report/bag/bag.mcap`, then "Import layout" with
  `{FOXGLOVE_LAYOUT}`: a 3D panel following `base_link` (the URDF from
  `/robot_description`, placed by `/tf` and `/tf_static`), plots of the swivel angle, pitch
  and swivel torque, and the climb's feedback (phase, progress and the raw message).
- A full ROS 2 Jazzy install: `ros2 bag info report/bag`, `ros2 bag play report/bag --clock`;
  RViz and `tf2_echo odom base_link` read the bag's `/tf` and `/tf_static`.
- Python: `rosbags` (in the venv) reads every topic. Reading the bag and plotting one topic:

```python
{READING_EXAMPLE}```

  Not `mcap` with `mcap-ros2-support` (0.6.0) for the whole bag: its message parser refuses
  the action feedback's type name, `swivel_car_msgs/action/ClimbStep_FeedbackMessage`
  (`'ClimbStep_FeedbackMessage' is an invalid message name`), and that ends the iteration at
  the first `/climb_step/_action/feedback` message; `iter_decoded_messages(topics=[...])`
  without that topic works.
""")
    return page
