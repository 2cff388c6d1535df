"""
Repositioning: a path on the free floor to where the approach can start.

When the approach cannot be made from where the car stands (the step too close to turn onto
the approach heading, or the crossing of the edge the car can reach lies beside the top
face), the car first drives to a *staging pose* from which it can: back up, turn with the
swivel at its turning limit (``swivel_limit``: base_link on a 0.24 m circle, the controller's
"turn on the spot"), drive straight, turn again. Two turns the same way round with a straight
between move it sideways.

Kinematics
----------
The offset tricycle of ``swivel_car_model.planar``, as the approach uses it: with the swivel
held at theta2 base_link follows an arc of curvature ``planar.curvature_for_swivel``, forwards
or backwards. A path is a list of ``Segment``: at a standstill the swivel moves to the
segment's angle, then the car drives the segment's signed length. Moving the swivel at a
standstill turns and shifts the car (``dynamics.swivel_pose_drift``: 0.42 rad from 0 to the
1.4 rad limit, 0.36 rad and 7 cm back to 0); the path includes those moves. Every turn is
``0 -> +-swivel_limit -> drive -> 0``, so each drift is a fixed rigid motion and a
turn-straight-turn path to a given pose still has a closed form (``_csc``): the drifts fold
into the two turning circles' centres and into the tangent condition.

Collision
---------
The step's box is the request's top face (``step_width`` along the edge, unbounded when 0)
extended without end away from the car (its depth is not known). The car's ground footprint
is bounded, whatever the swivel angle, by a rectangle in base_link (``footprint``: the rear
wheels, the front wheels about the contact points the model gives over the whole swivel
range, each wheel's radius and half width) grown by ``clearance``. A path is clear when that
rectangle, at poses sampled at most ``_SAMPLE_STEP`` of base_link path and ``_SAMPLE_TURN``
of heading apart, grown further by the most any point of it moves between two samples, never
overlaps the box (separating axes).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
import functools
import math
from typing import Callable

import numpy as np
from swivel_car_model import climbing, dynamics, kinematics, planar
from swivel_car_model.params import SwivelCarParams

from swivel_car_planner.core.config import PlannerConfig
from swivel_car_planner.core.geometry import wrap_angle

_SAMPLE_STEP = 0.02  # [m] base_link path between two checked poses
_SAMPLE_TURN = 0.02  # [rad] heading change between two checked poses
_FAR = 1e3  # [m] stands for "without end" in the step's box


@dataclass(frozen=True)
class Segment:
    """One piece of a repositioning path: swivel to ``swivel``, then drive ``length``."""

    swivel: float  # [rad] held while driving
    length: float  # [m] base_link's signed path, negative reversing


@dataclass(frozen=True)
class Pose:
    """A planar pose of base_link in the request's frame (base_link when asked)."""

    x: float  # [m]
    y: float  # [m]
    yaw: float  # [rad]
    turning: bool = False  # the swivel away from 0 (the front wheels anywhere in its range)

    def compose(self, dx: float, dy: float, dyaw: float) -> Pose:
        """Return this pose moved by (dx, dy) [m] in its own frame and turned by dyaw [rad]."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        return Pose(self.x + c * dx - s * dy, self.y + s * dx + c * dy, self.yaw + dyaw)


@dataclass(frozen=True)
class StepBox:
    """
    The step's footprint in the request's frame.

    The edge's line passes through ``(edge_x, 0)`` with its normal (into the step) at
    ``normal_yaw``; the top face spans ``offset +- width / 2`` along it (leftwards of the
    normal), all of it when ``width`` is 0.
    """

    edge_x: float  # [m] where the request's x axis meets the edge
    normal_yaw: float  # [rad]
    width: float  # [m] 0: not known (unbounded)
    offset: float  # [m]

    def corners(self) -> np.ndarray:
        """Return the corners of the box, shape (4, 2) [m]; "without end" is ``_FAR``."""
        nx, ny = math.cos(self.normal_yaw), math.sin(self.normal_yaw)
        half = self.width / 2.0 if self.width > 0.0 else _FAR
        low, high = self.offset - half, self.offset + half
        return np.array([[self.edge_x + n * nx - t * ny, n * ny + t * nx]
                         for n, t in ((0.0, low), (0.0, high), (_FAR, high), (_FAR, low))])


@dataclass(frozen=True)
class Footprint:
    """A rectangle in base_link that holds the car's ground footprint at any swivel."""

    back: float  # [m] behind base_link (positive)
    front: float  # [m] ahead of base_link
    half_width: float  # [m]

    def grown(self, margin: float) -> Footprint:
        return Footprint(self.back + margin, self.front + margin, self.half_width + margin)


@functools.lru_cache(maxsize=16)
def footprint(p: SwivelCarParams, turning: bool) -> Footprint:
    """
    Bound the car's ground footprint, the swivel at 0 or anywhere in its range [m].

    A wheel's ground projection lies within ``hypot(r, wheel_width / 2)`` of its centre's:
    the rear wheels' centres stand at (0, +-h), the front ones' at (wheelbase, +-h) with the
    swivel at 0; turning, the grounded front wheel's above its contact point and the lifted
    one's within r of its lowest point (both from the model over the whole swivel range).
    """
    disc = math.hypot(p.r, p.wheel_width / 2.0)  # [m]
    front, half = p.wheelbase + disc, p.h + disc
    if turning:
        angles = np.linspace(0.0, p.swivel_limit, 57)
        xs, ys = (np.asarray(v, dtype=float) for v in kinematics.contact_point(p, angles))
        lifted = np.array([climbing.lifted_wheel_lowest_point(p, float(a))[:2]
                           for a in angles])
        front = max(front, float(np.max(xs)) + disc,
                    float(np.max(lifted[:, 0])) + p.r + disc)
        half = max(half, float(np.max(np.abs(ys))) + disc,
                   float(np.max(np.abs(lifted[:, 1]))) + p.r + disc)
    return Footprint(disc, front, half)


@dataclass(frozen=True)
class _Turn:
    """The tightest turn one way round and the drifts of the swivel's moves to it and back."""

    swivel: float  # [rad]
    curvature: float  # [1/m]
    there: tuple[float, float, float]  # (dx [m], dy [m], dyaw [rad]) of 0 -> swivel
    back: tuple[float, float, float]  # of swivel -> 0


@functools.lru_cache(maxsize=8)
def _turns(p: SwivelCarParams) -> dict[int, _Turn]:
    """Return the tightest turns, to the left (+1) and to the right (-1)."""
    turns = {}
    for swivel in (p.swivel_limit, -p.swivel_limit):
        curvature = float(planar.curvature_for_swivel(p, swivel))
        turns[1 if curvature > 0.0 else -1] = _Turn(
            swivel, curvature, _drift(p, 0.0, swivel), _drift(p, swivel, 0.0))
    return turns


def _drift(p: SwivelCarParams, start: float, end: float) -> tuple[float, float, float]:
    return tuple(float(v) for v in dynamics.swivel_pose_drift(p, start, end))


def path_curvature(p: SwivelCarParams, swivel: float) -> float:
    """Return base_link's curvature [1/m] at a path's swivel (0 or a tightest turn's)."""
    if swivel == 0.0:
        return 0.0
    for turn in _turns(p).values():
        if turn.swivel == swivel:
            return turn.curvature
    return float(planar.curvature_for_swivel(p, swivel))


def propagate(p: SwivelCarParams, start: Pose, segments: tuple[Segment, ...],
              swivel: float = 0.0) -> list[Pose]:
    """
    Return the poses along ``segments`` from ``start`` with the swivel at ``swivel`` [rad].

    Sampled at most ``_SAMPLE_STEP`` of path and ``_SAMPLE_TURN`` of heading apart; the
    swivel's moves at a standstill (their drift) and a final move back to 0 are included,
    both ends of a move with the swivel away from 0 (``Pose.turning``). The last pose is
    where the path ends.
    """
    poses = [start]
    pose = start
    for segment in (*segments, Segment(0.0, 0.0)):
        if segment.swivel != swivel:
            poses[-1] = dataclasses.replace(poses[-1], turning=True)
            pose = dataclasses.replace(pose.compose(*_drift(p, swivel, segment.swivel)),
                                       turning=True)
            swivel = segment.swivel
            poses.append(pose)
        if segment.length == 0.0:
            continue
        curvature = path_curvature(p, segment.swivel)  # [1/m]
        turn = abs(curvature * segment.length)
        count = max(1, math.ceil(max(abs(segment.length) / _SAMPLE_STEP, turn / _SAMPLE_TURN)))
        turning = segment.swivel != 0.0
        for k in range(1, count + 1):
            poses.append(arc(pose, curvature, segment.length * k / count, turning))
        pose = poses[-1]
    return poses


def arc(pose: Pose, curvature: float, length: float, turning: bool = False) -> Pose:
    """Return ``pose`` moved ``length`` [m] along an arc of ``curvature`` [1/m]."""
    turn = curvature * length
    half = turn / 2.0
    chord = length * math.sin(half) / half if half != 0.0 else length  # [m]
    return Pose(pose.x + chord * math.cos(pose.yaw + half),
                pose.y + chord * math.sin(pose.yaw + half), pose.yaw + turn, turning)


def collides(p: SwivelCarParams, poses: list[Pose], box: StepBox, clearance: float,
             swept: bool = True) -> bool:
    """
    Tell whether the car's footprint, ``clearance`` [m] grown, overlaps ``box`` at any pose.

    ``swept``: the poses are ``propagate``'s samples of a motion. Between two of them no point
    of the footprint moves further than ``_SAMPLE_STEP`` plus its farthest corner's radius
    times ``_SAMPLE_TURN``; the footprint is grown by that too, so the poses between are
    covered.
    """
    corners = []
    for turning in (False, True):
        shape = footprint(p, turning).grown(clearance)
        reach = math.hypot(max(shape.back, shape.front), shape.half_width)  # [m]
        if swept:
            shape = shape.grown(_SAMPLE_STEP + reach * _SAMPLE_TURN)
        corners.append([[-shape.back, -shape.half_width], [shape.front, -shape.half_width],
                        [shape.front, shape.half_width], [-shape.back, shape.half_width]])
    local = np.array([corners[q.turning] for q in poses])  # (k, 4, 2)
    xy = np.array([[q.x, q.y] for q in poses])  # (k, 2)
    yaw = np.array([q.yaw for q in poses])
    c, s = np.cos(yaw)[:, None], np.sin(yaw)[:, None]
    car = np.stack([xy[:, :1] + c * local[..., 0] - s * local[..., 1],
                    xy[:, 1:] + s * local[..., 0] + c * local[..., 1]], axis=-1)  # (k, 4, 2)
    step = box.corners()
    # Separating axes: the box's two edge directions and the car's two, per pose.
    overlap = np.ones(len(poses), dtype=bool)
    axes = [np.broadcast_to(np.array([math.cos(a), math.sin(a)]), (len(poses), 2))
            for a in (box.normal_yaw, box.normal_yaw + math.pi / 2.0)]
    axes += [np.concatenate([c, s], axis=1), np.concatenate([-s, c], axis=1)]
    for axis in axes:
        on_car = np.einsum('kcj,kj->kc', car, axis)
        on_step = step @ axis.T  # (4, k)
        overlap &= ((on_car.min(axis=1) <= on_step.max(axis=0))
                    & (on_step.min(axis=0) <= on_car.max(axis=1)))
    return bool(np.any(overlap))


def reposition_length(segments: tuple[Segment, ...]) -> float:
    """Return the path's length [m]: base_link's travel, forwards and backwards."""
    return sum(abs(s.length) for s in segments)


def reposition_time(p: SwivelCarParams, config: PlannerConfig,
                    segments: tuple[Segment, ...]) -> float:
    """
    Return the time [s] the path takes: driving at ``approach_speed``, every swivel move.

    Each move to a turn and back at ``swivel_rate`` plus ``settle_time`` (``config``: the
    planner's settings).
    """
    moves = 2 * sum(segment.swivel != 0.0 for segment in segments)
    return (reposition_length(segments) / (config.approach_speed * p.r)
            + moves * (p.swivel_limit / config.swivel_rate + config.settle_time))


def _rotate(angle: float, x: float, y: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([c * x - s * y, s * x + c * y])


def _csc(p: SwivelCarParams, start: Pose, goal: Pose) -> list[tuple[Segment, ...]]:
    """
    Return the turn-straight-turn paths from ``start`` to ``goal`` (swivel at 0 at both).

    Each turn is on the tightest circle, either way round, forwards or backwards (the
    shorter); the straight forwards or backwards. Drifts of the swivel's moves (module
    docstring) included: (dx, dy, dyaw) of 0 -> turn (``a``) and turn -> 0 (``b``) are rigid
    motions in the frame they start from.
    """
    paths = []
    for first in (1, -1):
        for second in (1, -1):
            one, two = _turns(p)[first], _turns(p)[second]
            s1, k1, a1, b1 = one.swivel, one.curvature, one.there, one.back
            s2, k2, a2, b2 = two.swivel, two.curvature, two.there, two.back
            # First turn: the pose after the swivel's move, its circle's centre.
            q1 = start.compose(*a1)
            c1 = np.array([q1.x, q1.y]) + _rotate(q1.yaw, 0.0, 1.0 / k1)
            # Last turn: the pose before the swivel's move back to 0, its centre.
            inverse = Pose(0.0, 0.0, 0.0).compose(*b2)
            back = _rotate(-inverse.yaw, -inverse.x, -inverse.y)
            g2 = goal.compose(float(back[0]), float(back[1]), -inverse.yaw)
            c2 = np.array([g2.x, g2.y]) + _rotate(g2.yaw, 0.0, 1.0 / k2)
            # With the straight's heading theta: its start is c1 + R(theta) v1, its end
            # c2 + R(theta) v2 (arc end, then the drift b1; the drift a2, then the arc).
            v1 = _rotate(-b1[2], 0.0, -1.0 / k1) + _rotate(-b1[2], b1[0], b1[1])
            v2 = _rotate(a2[2], 0.0, -1.0 / k2) - np.array(a2[:2])
            w = v2 - v1
            d = c2 - c1
            distance = float(np.hypot(*d))
            if distance < abs(w[1]) or distance == 0.0:
                continue
            bearing = math.atan2(d[1], d[0])
            offset = math.asin(-w[1] / distance)
            for theta in (bearing - offset, bearing + offset - math.pi):
                straight = float(d @ np.array([math.cos(theta), math.sin(theta)]) + w[0])
                turn1 = wrap_angle(theta - b1[2] - q1.yaw)
                turn2 = wrap_angle(g2.yaw - theta - a2[2])
                paths.append((Segment(s1, turn1 / k1), Segment(0.0, straight),
                              Segment(s2, turn2 / k2)))
    return paths


def plan_path(p: SwivelCarParams, goals: list[Pose], usable: Callable[[int], bool],
              box: StepBox, clearance: float, max_length: float,
              backups: tuple[float, ...] = (0.0, 0.2, 0.4, 0.6)
              ) -> tuple[tuple[Segment, ...], int] | None:
    """
    Find the shortest clear path from the request's pose to one of ``goals``.

    Candidates: a straight backup of each of ``backups`` [m], then turn-straight-turn
    (``_csc``), to the goals ``usable(index)`` accepts (asked lazily, shortest path first).
    Returns the path and the index of the goal it reaches, or None when no candidate up to
    ``max_length`` [m] is clear of ``box`` (``clearance`` [m] kept).
    """
    start = Pose(0.0, 0.0, 0.0)
    candidates = []
    for index, goal in enumerate(goals):
        for backup in backups:
            origin = arc(start, 0.0, -backup)
            for path in _csc(p, origin, goal):
                total = backup + reposition_length(path)
                if total <= max_length:
                    candidates.append((total, index, backup, path))
    candidates.sort(key=lambda item: item[0])
    # Backing up straight moves the car away from where it stands, which may be nearer the
    # step than ``clearance``: that part only must not touch it.
    clear = {backup: not collides(p, propagate(p, start, (Segment(0.0, -backup),)), box, 0.0)
             for backup in backups}
    for _, index, backup, path in candidates:
        if clear[backup] and usable(index) \
                and not collides(p, propagate(p, arc(start, 0.0, -backup), path), box,
                                 clearance):
            first = (Segment(0.0, -backup),) if backup > 0.0 else ()
            return first + path, index
    return None
