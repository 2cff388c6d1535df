"""
Feasibility check and climb plan, from the model library (swivel_car_model).

The model supplies every thesis quantity (swivel angle for a step, lift angle, the tip-over
rule eq. 72, the interference rule eq. 75, peak torque and energy, the pose change that the
swivel causes). What this module adds is the approach geometry of the active-lift procedure,
derived here rather than taken from thesis eqs. 76-85 (see "Approach geometry" below and the
package README for why).

Approach geometry
-----------------
The car meets the edge at a lead angle psi to the edge's normal, so that one front wheel
(the lifted one) is over the step while the other is still short of the riser. A wheel of
radius r standing on the ground touches an edge of height hs when its contact point is
``a = sqrt(r^2 - (r - min(hs, r))^2)`` from the edge. The two front contacts are 2h apart
along the axle, so along the normal they differ by ``2 h sin(psi)``. Asking the lifted wheel
to be ``lead_margin`` past the edge while the other is ``a + lead_margin`` short of it gives::

    sin(psi_lead) = (a + 2 lead_margin) / (2 h)

Thesis eqs. 76-85 instead chain an arc of the lifted wheel onto the edge at a final angle
gamma; their printed forms are inconsistent (eq. 76 uses 2 l cos(phi) where the wheelbase is
2 l cos(phi/2); eq. 84 defines d_2 while eq. 85 returns d; eq. 85's tan(gamma) does not follow
from the sine law of eq. 84), so the planner does not use them. The lead angle is never below
the model's minimum approach angle (``climbing.min_approach_angle_for_step``, thesis eqs.
92-100 with exact wheel discs), the bound the thesis derives for phi < 0; for phi > 0 the
derivation above is the larger one.

Advancing with the wheel up is no straight line: the swivel is held at the lift angle, so
base_link follows an arc of the model's curvature at that angle (``planar``; a 0.28 m radius
at 1.37 rad, the lift of a 27 cm step), turning away from the lifted side. The plan puts the
*end* of that arc at ``psi_lead`` (the lifted wheel ``lead_margin`` past the edge, the other
``a + lead_margin`` short of it) and starts it ``advance_turn`` earlier. The lift's yaw and
the arc's turn both point the car away from the lifted side, so the approach must start
turned towards it: on a tight arc the other wheel then leads at the lift and swings towards
the riser on the way, and the end heading is made more oblique until that wheel stays off the
riser (its contact at least ``a`` short) throughout. Up to 26 cm such a heading exists; at
27 cm (1.37 rad: the lift yaws 0.41 rad, the arc is 0.28 m) none does below
``max_lead_angle``, and the plan refuses it. Drawn as a straight line, the lifted wheel of a
27 cm climb swung along the edge instead of over it: a wheel at the lifted side's corner
moves at 45 degrees to the car's heading on that arc, and the car circled in front of the
step.

Lifting the wheel turns and shifts the car (thesis II.E; ``dynamics.swivel_pose_drift``): the
approach aims at ``psi_lead - advance_turn - drift_yaw`` so that the car starts the arc at the
planned heading once the wheel is up, and starts the lift far enough back that the drift does
not push the rising wheel into the riser.

Push-lift
---------
Where no such heading exists (``WHEEL_INTERFERENCE`` above, 27 cm on the default robot), and
for every step from ``push_lift_height`` up, the plan turns the other way: the *grounded*
front wheel leads, at ``push_lead`` to the normal, stops ``push_gap`` short of the riser, and
the swivel lifts to its limit whatever the step needs. Near that limit the front wheels no
longer sit where they rest: the grounded wheel's contact moves back and in towards the centre
line (``kinematics.contact_point``) and the lifted wheel rises forward over it (the shaft
turns about the inclined column), so the lifted wheel's lowest point ends 9 cm ahead of the
grounded wheel's contact at 1.4 rad (less at lower angles: in the sim 1.3 rad left it short),
and the lift's yaw turns it further towards the edge. The advance on the arc then carries the
point where the lifted wheel will land (``landing_point``) ``push_margin`` over the edge
while the grounded wheel's contact stays short of the riser, and the set-down drives at
``set_down_speed``: the car pitches up about the rear axle as the wheel takes the load, and
with the wheels held the wheel on the top slid back off the edge (measured in the sim).

Semi-active lift (phi < 0, thesis III.B)
----------------------------------------
With phi < 0 the riser's push on a driven front wheel turns the swivel the way that lifts
that wheel (``climbing.induced_swivel_torque``, eqs. 86-91 corrected). The approach is the
standard one, its heading at least the minimum approach angle (eqs. 92-100) that keeps the
steering wheel off the riser, but the lift does not wait at a standstill: the car drives on
from ``lift_gap`` before the lifted wheel's front meets the riser (its rest contact ``a +
lift_gap`` short of the edge) while the swivel ramps to the lift angle, so the drive presses
the wheel against the riser and does part of the lift. No standstill lift, no drift: the
advance arc starts where the lift starts. The rest (advance, set-down, second wheel, rear
axle) is the standard procedure's. The push-lift is not offered (it leads with the other
wheel). Its heading is large (0.75-0.94 rad on the phi < 0 design), so the crossing assumes
the car turns onto it at once, as the push-lift's does, on the wider arc and after the run
of ``semi_active_turn``, which also sets the room the approach needs.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
import math

import numpy as np
from scipy.optimize import brentq

from swivel_car_model import climbing, dynamics, kinematics, planar
from swivel_car_model.params import SwivelCarParams

from swivel_car_planner.core.codes import ErrorCode
from swivel_car_planner.core.config import PlannerConfig
from swivel_car_planner.core.reposition import (
    collides, plan_path, Pose, reposition_time, Segment, StepBox)
from swivel_car_planner.core.request import ClimbRequest

PROCEDURE_ACTIVE_LIFT = 0  # ClimbPlan.PROCEDURE_ACTIVE_LIFT
PROCEDURE_SEMI_ACTIVE = 1  # ClimbPlan.PROCEDURE_SEMI_ACTIVE


class PlanError(Exception):
    """The request cannot be planned; ``code`` says why (an ``ErrorCode``)."""

    def __init__(self, code: ErrorCode, message: str) -> None:
        super().__init__(message)
        self.code = code
        self.message = message


@dataclass(frozen=True)
class ClimbPlan:
    """
    Everything the climb needs, computed before moving.

    The first fields mirror swivel_car_msgs/ClimbPlan; the rest drive the state machine.
    """

    procedure: int
    swivel_angle: float  # [rad] signed theta2 of the lift
    lift_angle: float  # [rad] theta1 at that swivel angle
    wheel_clearance: float  # [m] lifted wheel's lowest point above the step top
    approach_distance: float  # [m] front axle contact to the edge, along the heading, at lift
    approach_heading: float  # [rad] car heading to the edge's normal when the lift starts
    peak_torque: float  # [N m] predicted
    energy: float  # [J] predicted
    max_scalable_step: float  # [m]
    tip_over_margin: float  # [rad]
    interference_margin: float  # [m]
    duration: float  # [s] predicted
    lifted_side: int  # +1: left front wheel lifted (theta2 > 0), -1: right
    lead_angle: float  # [rad] heading to the normal, signed, once the wheel is over the edge
    lead_distance: float  # [m] lifted wheel's contact to the edge (along the normal) at lift
    second_swivel_angle: float  # [rad] swivel that holds the second wheel clearance_margin up
    step_height: float  # [m]
    # [m] where the car's centre line crosses the edge, along the edge (leftwards) from the
    # point the request's x axis meets it; None: the step's extent is not known, the approach
    # only holds its heading
    crossing: float | None = None
    # [m] the car first backs up this far, straight, to make room for the approach
    backup_distance: float = 0.0
    # Or, where that does not make room, it first drives this path (``reposition`` module)
    # to a staging pose the approach starts from
    reposition: tuple[Segment, ...] = ()
    # [rad] heading change while the lifted wheel advances over the edge (the arc; module
    # docstring); ``lead_angle - advance_turn`` is the heading once the wheel is up
    advance_turn: float = 0.0
    advance_length: float = 0.0  # [m] base_link's path along that arc
    # The push-lift (module docstring): the grounded wheel leads, the advance ends on the
    # point where the lifted wheel will land on the step, ``lifted_point`` in base_link
    push_lift: bool = False
    lifted_point: tuple[float, float] = (0.0, 0.0)  # [m]


def lead_angle(p: SwivelCarParams, config: PlannerConfig, step_height: float) -> float:
    """
    Return the smallest |heading to the edge's normal| that lets the lifted wheel lead [rad].

    At it the lifted wheel gets over the edge before the other front wheel meets the riser
    (module docstring).

    Raises
    ------
    PlanError
        The front wheels are too close together for any angle below ``max_lead_angle``.

    """
    sink = p.r - min(step_height, p.r)
    reach = math.sqrt(p.r ** 2 - sink ** 2)
    sine = (reach + 2.0 * config.lead_margin) / (2.0 * p.h)
    if sine >= math.sin(config.max_lead_angle):
        raise PlanError(ErrorCode.WHEEL_INTERFERENCE,
                        f'the front wheels (2h = {2 * p.h:.3f} m) are too close together to '
                        f'put one over a {step_height:.3f} m step before the other meets it '
                        f'below a lead angle of {config.max_lead_angle:.2f} rad')
    return math.asin(sine)


def crossing_range(p: SwivelCarParams, config: PlannerConfig, request: ClimbRequest,
                   heading: float) -> tuple[float, float]:
    """
    Return where along the edge the car's centre line may cross it, (low, high) [m].

    So that every wheel that is on the step stays on its top face, ``edge_margin`` inside its
    sides, while the car drives on at ``heading`` (to the normal) until the trailing rear
    wheel is ``rest_margin`` past the edge, and ``stop_allowance`` further until it stands.
    Along the edge leftwards from where the request's x axis meets it; empty (low > high)
    when the face is too narrow.
    """
    sine, cosine = math.sin(heading), math.cos(heading)
    # Along the heading from the crossing, the wheels on top lie between the rear axle at
    # the crossing and the front axle once the car stands.
    reach = ((config.rest_margin + p.h * abs(sine)) / cosine + config.stop_allowance
             + p.wheelbase)  # [m]
    half = p.h * cosine + p.wheel_width / 2.0 + config.edge_margin
    low = request.step_offset - request.step_width / 2.0 + half - min(0.0, sine * reach)
    high = request.step_offset + request.step_width / 2.0 - half - max(0.0, sine * reach)
    return low, high


@dataclass(frozen=True)
class AdvanceArc:
    """The lifted wheel's advance over the edge, base_link on an arc (module docstring)."""

    end_heading: float  # [rad] heading to the edge's normal when the wheel is over the edge
    turn: float  # [rad] signed heading change along the arc
    length: float  # [m] base_link's path


_ARC_SAMPLES = 400


def advance_arc(p: SwivelCarParams, config: PlannerConfig, swivel: float, side: int,
                lead: float, lead_distance: float, reach: float,
                drift_yaw: float) -> AdvanceArc:
    """
    Find the arc of ADVANCE with the swivel held at ``swivel`` [rad], [m].

    The lifted wheel (rest geometry, as the state machine measures it) moves from
    ``lead_distance`` short of the edge to ``lead_margin`` past it and ends at a heading at
    least ``lead`` oblique (signed ``-side``), while the other front wheel stays off the riser
    (its contact at least ``reach`` short of the edge) when the lift starts (the heading then
    ``drift_yaw`` before the arc's start), once the wheel is up, and along the arc; at the end
    of the arc it is ``reach + lead_margin`` short or more, by the lead angle.

    Raises
    ------
    PlanError
        ``WHEEL_INTERFERENCE``: no end heading up to ``max_lead_angle`` keeps the other
        wheel off the riser.

    """
    curvature = float(planar.curvature_for_swivel(p, swivel))  # [1/m]
    bx, by = p.wheelbase, side * p.h
    travel = lead_distance + config.lead_margin  # [m]

    def normal_shift(end: float, length: float | np.ndarray, y: float) -> np.ndarray:
        """
        Return the normal displacement of the base_link point (bx, y) [m].

        Over the last ``length`` of the arc ending at ``end``; sinc keeps the straight limit
        exact.
        """
        start = end - curvature * length
        half = curvature * np.asarray(length) / 2.0
        base = length * np.cos(end - half) * np.sinc(half / np.pi)
        return base + bx * (np.cos(end) - np.cos(start)) - y * (np.sin(end) - np.sin(start))

    # Base_link cannot turn more than half a circle before the wheel is over; cap the search
    # at a few metres for the straight case.
    longest = min(4.0, math.pi / abs(curvature)) if curvature != 0.0 else 4.0  # [m]
    lengths = np.linspace(0.0, longest, _ARC_SAMPLES)
    for end in np.linspace(lead, config.max_lead_angle, 40):
        end = -side * float(end)
        shifts = normal_shift(end, lengths, by)
        beyond = np.nonzero(shifts >= travel)[0]
        if beyond.size == 0:
            continue
        k = int(beyond[0])
        length = float(brentq(lambda s: normal_shift(end, s, by) - travel,
                              lengths[k - 1], lengths[k]))
        # The other wheel's signed distance past the edge, over the whole arc.
        along = np.linspace(0.0, length, _ARC_SAMPLES)
        other_end = config.lead_margin + 2.0 * side * p.h * math.sin(end)  # [m]
        other = other_end - normal_shift(end, along, -by)
        start = end - curvature * length
        at_lift = [-lead_distance + 2.0 * side * p.h * math.sin(heading)
                   for heading in (start, start - drift_yaw)]
        if max(np.max(other), *at_lift) <= -reach + 1e-9:
            return AdvanceArc(end, curvature * length, length)
    radius = 1.0 / abs(curvature) if curvature != 0.0 else math.inf  # [m]
    raise PlanError(ErrorCode.WHEEL_INTERFERENCE,
                    f'with the swivel held at {swivel:.2f} rad the lift turns the car by '
                    f'{abs(drift_yaw):.2f} rad and the advance on a {radius:.2f} m radius: at '
                    f"no heading up to {config.max_lead_angle:.2f} rad to the edge's normal "
                    f'does the lifted '
                    f'wheel get over the edge with the other front wheel clear of the riser')


def landing_point(p: SwivelCarParams, height: float, side: int) -> tuple[float, float]:
    """
    Return where in base_link (level) the lifted wheel on ``side`` lands on the step [m].

    Where it touches a step of ``height`` as the swivel sets it down: its lowest point at the
    swivel that puts it at that height (it moves back as the swivel comes down from the lift).
    """
    swivel = float(kinematics.swivel_for_step(p, height, respect_tip_over=False))
    x, y, _ = climbing.lifted_wheel_lowest_point(p, side * swivel)
    return float(x), float(y)


def push_advance(p: SwivelCarParams, config: PlannerConfig, swivel: float, side: int,
                 lead_distance: float, drift_yaw: float, height: float) -> AdvanceArc:
    """
    Find the push-lift's advance on the arc of the held ``swivel`` [rad], [m].

    See the module docstring. From the heading ``side * push_lead`` at lift, turned by the
    lift's ``drift_yaw``, until the point where the wheel will land on a step of ``height``
    is ``push_margin`` past the edge, the lifted wheel's rest contact ``lead_distance`` short
    of it when the lift starts.

    Raises
    ------
    PlanError
        ``WHEEL_INTERFERENCE``: the grounded wheel's contact would reach the riser first, or
        the arc turns the lifted wheel away before it is over.

    """
    lift_heading = side * config.push_lead  # [rad]
    start = lift_heading + drift_yaw  # [rad] once the wheel is up
    curvature = float(planar.curvature_for_swivel(p, swivel))  # [1/m]
    base = (-lead_distance - p.wheelbase * math.cos(lift_heading)
            + side * p.h * math.sin(lift_heading))  # [m] base_link along the normal
    longest = min(2.0, math.pi / abs(curvature)) if curvature != 0.0 else 2.0  # [m]
    lengths = np.linspace(0.0, longest, _ARC_SAMPLES)
    headings = start + curvature * lengths
    if curvature == 0.0:
        travel = lengths * math.cos(start)
    else:
        travel = (np.sin(headings) - math.sin(start)) / curvature

    def normal(point: tuple[float, float]) -> np.ndarray:
        return (base + travel + point[0] * np.cos(headings)
                - point[1] * np.sin(headings))

    lifted = normal(landing_point(p, height, side))
    grounded = normal(tuple(float(v) for v in kinematics.contact_point(p, swivel)))
    over = np.nonzero(lifted >= config.push_margin)[0]
    if over.size == 0 or np.max(grounded[:over[0] + 1]) > 0.0:
        raise PlanError(ErrorCode.WHEEL_INTERFERENCE,
                        f'with the grounded front wheel leading at {config.push_lead:.2f} rad '
                        f'(push_lead) and the swivel held at {swivel:.2f} rad, the lifted '
                        f'wheel does not get {config.push_margin:.3f} m over the edge before '
                        f'the grounded wheel meets the riser or the arc turns it away')
    k = int(over[0])
    return AdvanceArc(float(headings[k]), float(headings[k] - start), float(lengths[k]))


@dataclass(frozen=True)
class _Approach:
    """How the car meets the edge when it lifts the wheel on ``side``."""

    side: int  # +1: left front wheel lifted
    lead: float  # [rad] heading to the normal once the wheel is over the edge
    arc: AdvanceArc
    heading: float  # [rad] heading to the normal when the lift starts
    lead_distance: float  # [m] lifted wheel's contact to the edge at lift
    axle_normal: float  # [m] front axle centre to the edge at lift, along the normal
    crossing: float | None  # [m] see ClimbPlan.crossing
    shift: float  # [m] sideways move the approach must make to reach the crossing
    error: str | None  # why this approach cannot be made


def _approach(p: SwivelCarParams, config: PlannerConfig, request: ClimbRequest,
              theta2: float, side: int) -> _Approach:
    height = request.step_height
    # Never below the model's minimum approach angle (thesis eqs. 92-100, exact wheel discs;
    # the bound the thesis derives for phi < 0, and a check of the derivation above).
    lead = max(lead_angle(p, config, height),
               float(climbing.min_approach_angle_for_step(p, height)))
    swivel = side * abs(theta2)
    reach = math.sqrt(p.r ** 2 - (p.r - min(height, p.r)) ** 2)  # [m] see lead_angle
    if p.phi < 0.0:
        # Semi-active (module docstring): the lift starts lift_gap before the wheel meets the
        # riser and goes on while driving, so there is no standstill drift.
        lead_distance = reach + config.lift_gap
        advance = advance_arc(p, config, swivel, side, lead, lead_distance, reach, 0.0)
        heading = advance.end_heading - advance.turn
        return _placed(p, config, request, side, advance, heading, lead_distance,
                       lead_distance + p.h * abs(math.sin(heading)), turn_first=True)
    drift_x, drift_y, drift_yaw = (
        float(v) for v in dynamics.swivel_pose_drift(p, 0.0, swivel))
    # The drift's push towards the riser lengthens the advance, which turns the heading at
    # lift: twice round settles it (the drift is a few millimetres).
    lead_distance = p.r + config.lift_gap
    for _ in range(2):
        advance = advance_arc(p, config, swivel, side, lead, lead_distance, reach,
                              drift_yaw)
        heading = advance.end_heading - advance.turn - drift_yaw
        drift_normal = drift_x * math.cos(heading) - drift_y * math.sin(heading)
        lead_distance = p.r + config.lift_gap + max(0.0, drift_normal)
    return _placed(p, config, request, side, advance, heading, lead_distance,
                   lead_distance + p.h * abs(math.sin(heading)))


def _push_approach(p: SwivelCarParams, config: PlannerConfig, request: ClimbRequest,
                   theta2: float, side: int) -> _Approach:
    """
    Plan the push-lift's approach (module docstring).

    The grounded wheel leads at ``push_lead`` and stops ``push_gap`` short of the riser; the
    swivel lifts to ``theta2``.
    """
    swivel = side * abs(theta2)
    heading = side * config.push_lead
    reach = math.sqrt(p.r ** 2 - (p.r - min(request.step_height, p.r)) ** 2)  # [m]
    # The grounded wheel's rest contact when its front meets the riser, then the lifted one's.
    touch = reach * math.cos(config.push_lead) + p.wheel_width / 2.0 * math.sin(
        config.push_lead)  # [m]
    lead_distance = touch + config.push_gap + 2.0 * p.h * math.sin(config.push_lead)
    drift_yaw = float(dynamics.swivel_pose_drift(p, 0.0, swivel)[2])
    advance = push_advance(p, config, swivel, side, lead_distance, drift_yaw,
                           request.step_height)
    # The lifted wheel trails: the axle's centre is nearer the edge than it.
    return _placed(p, config, request, side, advance, heading, lead_distance,
                   lead_distance - p.h * math.sin(config.push_lead), turn_first=True)


_TURN_IN = 1.5  # [1] semi-active turn-in arc per tightest aligning arc (the loop's lag)


def semi_active_turn(p: SwivelCarParams, config: PlannerConfig) -> tuple[float, float]:
    """
    Return the semi-active approach's turn: the arc radius [m], the straight run before it [m].

    The arc is ``_TURN_IN`` times the tightest aligning arc (``max_steer``): the heading loop
    reaches full steering only 0.23 rad of error on: of 8 requests (6 that had failed at 1.0
    times, 2 that had passed), 2.0 times left 3 0.16-0.26 rad off at the lift point, 1.5 times
    2 (0.18, 0.23 rad), both of which the room this turn needs now refuses. The run is the
    travel at ``approach_speed`` while the swivel turns to ``max_steer`` at ``swivel_rate``
    (0.53 m on the phi < 0 design, its 0.19 m wheels): the phi < 0 swivel's move yaws the car
    against the turn first.
    """
    radius = _TURN_IN * p.wheelbase / math.tan(config.max_steer)
    delay = (config.approach_speed * p.r * abs(float(kinematics.swivel_for_steering(
        p, config.max_steer))) / config.swivel_rate)
    return radius, delay


def _placed(p: SwivelCarParams, config: PlannerConfig, request: ClimbRequest, side: int,
            advance: AdvanceArc, heading: float, lead_distance: float,
            axle_normal: float, turn_first: bool = False) -> _Approach:
    """
    Place the approach that lifts at ``heading`` and then advances on ``advance``.

    At the lift the lifted wheel's rest contact is ``lead_distance`` and the front axle's
    centre ``axle_normal`` short of the edge. The result says whether there is room to align,
    and where the car crosses the edge: where it gets by turning onto ``heading`` at once on
    its aligning arc, if the face allows. A crossing that assumed an instant turn left the car
    beside its line after the turn (8.8 cm for a 5 cm step 1 m ahead), chasing it at up to
    ``max_steer`` off the planned heading into the lift point. ``turn_first``: the crossings
    reachable are those of turning at once or later on that arc (the push-lift's and the
    semi-active approach's large headings), not those of an instant turn.
    """
    psi_lead = advance.end_heading

    # Aligning turns on an arc of radius >= wheelbase / tan(max_steer); give it room.
    turn_radius, delay = p.wheelbase / math.tan(config.max_steer), 0.0  # [m]
    if p.phi < 0.0:
        turn_radius, delay = semi_active_turn(p, config)
    align_run = (1.5 * turn_radius * abs(math.sin(heading) + math.sin(request.step_yaw))
                 + delay)
    available = request.step_distance * math.cos(request.step_yaw)
    error = None
    if available < axle_normal + align_run:
        error = (f'the step is too close: aligning to {heading:.2f} rad and lifting needs '
                 f'the edge at least {axle_normal + align_run:.2f} m ahead of the front axle '
                 f'(along its normal), it is {available:.2f} m')
    crossing, shift = None, 0.0
    if request.step_width > 0.0:
        low, high = crossing_range(p, config, request, psi_lead)
        # Where base_link's line crosses the edge: turning to the approach heading at once
        # gives ``now`` (on the aligning arc: ``turned``); holding today's heading until the
        # last turn and lift gives ``late``; any crossing between is reachable by choosing
        # when to turn.
        back = p.wheelbase + request.step_distance  # [m] base_link to the edge along x
        along, normal = back * math.sin(request.step_yaw), back * math.cos(request.step_yaw)
        initial = -request.step_yaw  # [rad] heading to the normal now
        # Late: straight on, one arc of radius turn_radius to the approach heading, then
        # straight at it from the lift point (base_link ``final`` before the edge) on.
        arc = turn_radius * abs(math.sin(heading) - math.sin(initial))  # [m] along normal
        swing = math.copysign(turn_radius * abs(math.cos(initial) - math.cos(heading)),
                              heading - initial)  # [m] the arc along the edge
        turned = along + swing + (normal - arc) * math.tan(heading)
        now = turned if turn_first else along + normal * math.tan(heading)
        final = axle_normal + p.wheelbase * math.cos(heading)  # [m]
        late = (along + max(0.0, normal - arc - final) * math.tan(initial) + swing
                + min(normal, final) * math.tan(heading))
        reachable = (min(now, late), max(now, late))
        crossing = min(high, max(low, turned))
        nearest = min(reachable[1], max(reachable[0], crossing))
        shift = abs(crossing - nearest)
        room = reachable[1] - reachable[0]
        if low > high:
            shift = math.inf
            error = (f"the step's top face ({request.step_width:.2f} m wide) is too narrow: "
                     f"crossing at {psi_lead:.2f} rad to the edge's normal the car needs "
                     f'{request.step_width + low - high:.2f} m to keep every wheel on it')
        elif shift > 1e-9 and error is None:
            error = (f'the step is too close: the car would cross the edge {shift:.2f} m '
                     f'beside the top face; the approach can move its crossing by '
                     f'{room:.2f} m')
    return _Approach(side, psi_lead, advance, heading, lead_distance, axle_normal, crossing, shift,
                     error)


def make_plan(p: SwivelCarParams, config: PlannerConfig, request: ClimbRequest,
              whole_car_limit: float = math.inf) -> ClimbPlan:
    """
    Check feasibility and plan the climb of a validated request.

    ``plan_only`` requests get exactly the same checks.

    Parameters
    ----------
    p : SwivelCarParams
        The car's model parameters.
    config : PlannerConfig
        The climb settings.
    request : ClimbRequest
        The climb asked for, already validated (``validate_request``).
    whole_car_limit : float
        Highest step the whole car climbs reliably (``capability.CapabilityTable.limit``);
        higher ones are refused. # [m]

    Raises
    ------
    PlanError
        With ``UNREACHABLE_HEIGHT``, ``TIP_OVER``, ``WHEEL_INTERFERENCE``, ``TORQUE_LIMIT``
        or ``INVALID_REQUEST`` (the step is too close to align, or its top face too narrow
        for the car) and a message.

    """
    height = request.step_height
    max_step, _ = kinematics.max_scalable_step(p, respect_tip_over=True)
    reach, _ = kinematics.max_scalable_step(p, respect_tip_over=False)
    wanted = height + config.clearance_margin
    try:
        theta2 = float(kinematics.swivel_for_step(p, wanted, respect_tip_over=False))
    except ValueError as error:
        raise PlanError(ErrorCode.UNREACHABLE_HEIGHT,
                        f'a {height:.3f} m step plus {config.clearance_margin:.3f} m clearance '
                        f"is beyond the lifted wheel's reach ({reach:.3f} m): {error}") \
            from error
    if abs(theta2) > p.swivel_limit:
        limit_height = float(kinematics.lifted_wheel_lowest_height(p, p.swivel_limit))
        raise PlanError(ErrorCode.UNREACHABLE_HEIGHT,
                        f'a {height:.3f} m step plus {config.clearance_margin:.3f} m clearance '
                        f"needs the swivel at {abs(theta2):.3f} rad, beyond the robot's "
                        f'swivel_limit of {p.swivel_limit:.3f} rad (which lifts the wheel '
                        f'{limit_height:.3f} m)')
    if height > whole_car_limit:
        raise PlanError(ErrorCode.UNREACHABLE_HEIGHT,
                        f'the front wheels could lift over {height:.3f} m, but the whole car '
                        f'climbs reliably only up to {whole_car_limit:.3f} m (the rear axle '
                        f'climbs by traction; measured in the sim, the capability table)')
    theta1, tip_margin, interference = _lift_rules(p, config, height, theta2)
    peak_torque, energy = (float(v) for v in dynamics.climb_torque_energy(
        p, height, config.swivel_rate))
    if peak_torque > p.swivel_torque_limit:
        raise PlanError(ErrorCode.TORQUE_LIMIT,
                        f'the climb needs a peak swivel torque of {peak_torque:.2f} N m, above '
                        f'the actuator limit of {p.swivel_torque_limit:.2f} N m')

    initial_heading = -request.step_yaw  # [rad] car heading to the edge's normal
    leading = 1 if initial_heading <= 0.0 else -1
    # Too close to turn onto the approach (or onto the crossing): backing up straight along
    # the car's x axis gives the same request with the edge further ahead.
    requested = request
    # The push-lift leads with the grounded wheel; the semi-active lift needs the lifted one
    # against the riser.
    semi_active = p.phi < 0.0
    push = not semi_active and height >= config.push_lift_height
    reposition: tuple[Segment, ...] = ()
    staging = requested  # the request as seen from where the approach starts
    for backup in _backups(config.max_backup):
        request = dataclasses.replace(requested, step_distance=requested.step_distance + backup)
        try:
            approaches = _approaches(p, config, request, theta2, leading, push)
        except PlanError as error:
            # No heading keeps the other wheel off the riser: the push-lift leads with it.
            if push or semi_active or error.code != ErrorCode.WHEEL_INTERFERENCE:
                raise
            push = True
            approaches = _approaches(p, config, request, theta2, leading, push)
        preferred = approaches[0].side
        approach = min(approaches,
                       key=lambda a: (a.error is not None, a.shift, a.side != preferred))
        if approach.error is None:
            break
        if backup == 0.0:
            first_error = approach.error
    else:
        if config.max_reposition == 0.0:
            raise PlanError(ErrorCode.INVALID_REQUEST,
                            first_error if config.max_backup == 0.0 else
                            f'{first_error}; backing up {config.max_backup:.2f} m (max_backup) '
                            f'does not make room either: then {approach.error}')
        # No room from here, straight back either: drive to where there is.
        request, backup = requested, 0.0
        approach, reposition, staging = _staged(p, config, request, theta2, leading, push,
                                                first_error)
    if push:  # it lifts the wheel as high as the swivel goes (module docstring)
        theta2 = p.swivel_limit
        theta1, tip_margin, interference = _lift_rules(p, config, height, theta2)
    if reposition:
        request = staging
    available = request.step_distance * math.cos(request.step_yaw)
    side, psi_lead, approach_heading = approach.side, approach.lead, approach.heading
    lead_distance, axle_normal = approach.lead_distance, approach.axle_normal
    approach_distance = axle_normal / math.cos(approach_heading)
    signed_theta2 = side * abs(theta2)

    v_approach = config.approach_speed * p.r  # [m/s]
    v_climb = config.climb_speed * p.r  # [m/s]
    cos_lead = math.cos(psi_lead)
    duration = ((backup + max(0.0, available - axle_normal) / max(0.5, cos_lead)) / v_approach
                + reposition_time(p, config, reposition)
                + 2.0 * abs(theta2) / config.swivel_rate + config.settle_time
                + approach.arc.length / v_climb
                + (p.wheelbase + 2.0 * p.h * abs(math.sin(psi_lead)) + config.rest_margin)
                / cos_lead / v_climb)
    return ClimbPlan(
        procedure=PROCEDURE_SEMI_ACTIVE if semi_active else PROCEDURE_ACTIVE_LIFT,
        swivel_angle=signed_theta2, lift_angle=theta1,
        wheel_clearance=float(kinematics.lifted_wheel_lowest_height(p, theta2)) - height,
        approach_distance=approach_distance, approach_heading=approach_heading,
        peak_torque=peak_torque, energy=energy, max_scalable_step=float(max_step),
        tip_over_margin=tip_margin, interference_margin=interference, duration=duration,
        lifted_side=side, lead_angle=psi_lead, lead_distance=lead_distance,
        second_swivel_angle=-side * float(kinematics.swivel_for_step(
            p, config.clearance_margin, respect_tip_over=False)),
        step_height=height,
        crossing=(None if approach.crossing is None
                  else approach.crossing + requested.step_offset - staging.step_offset),
        backup_distance=backup, reposition=reposition,
        advance_turn=approach.arc.turn, advance_length=approach.arc.length, push_lift=push,
        lifted_point=landing_point(p, height, side) if push else (0.0, 0.0))


# [m] front axle to the edge (along base_link x) at the staging poses tried, square to the
# edge. The approach then turns onto its heading with room to close on it and on its crossing,
# which the path leaves off by what the swivel's moves do unlike the model (5-10 cm in the sim
# and in the kinematic car of the tests). From staging poses 0.3-0.8 m back at the approach
# heading itself the lift point was reached 0.12-0.21 rad off (in-process stack, the system
# test's step and two more), and from 1.0 m square the kinematic car reached it 0.14 rad off.
_STAGING_DISTANCES = (1.3, 1.6, 2.0)


def _staged(p: SwivelCarParams, config: PlannerConfig, request: ClimbRequest, theta2: float,
            leading: int, push: bool, first_error: str
            ) -> tuple[_Approach, tuple[Segment, ...], ClimbRequest]:
    """
    Plan the approach from a staging pose, and the path there (``reposition`` module).

    The staging poses tried stand square to the edge ``_STAGING_DISTANCES`` before it, placed
    so that turning onto an approach's heading at once takes the car to the middle of the
    crossings its wheels stay on the top face from. The shortest clear path to one the
    approach can start from wins.

    Returns
    -------
    (approach, path, staging)
        The approach as planned from the staging pose, the path there, and the request as
        seen from the staging pose.

    Raises
    ------
    PlanError
        ``INVALID_REQUEST``: the top face is too narrow for the track at the lead angle (no
        staging pose helps), or no clear path up to ``max_reposition`` reaches one.

    """
    approaches = _approaches(p, config, request, theta2, leading, push)
    if all(a.shift == math.inf for a in approaches):
        raise PlanError(ErrorCode.INVALID_REQUEST, approaches[0].error)
    normal = request.step_yaw  # [rad] the edge's normal in the request's frame
    edge_x = p.wheelbase + request.step_distance  # [m]
    stagings, goals = [], []
    for approach in approaches:
        # Aim at the middle of the crossings that keep the wheels on the top face.
        middle = (sum(crossing_range(p, config, request, approach.lead)) / 2.0
                  if request.step_width > 0.0 else 0.0)  # [m]
        for distance in _STAGING_DISTANCES:
            reach = p.wheelbase + distance  # [m] base_link to the edge along its x
            along = middle - reach * math.tan(approach.heading)  # [m] where its x axis meets it
            stagings.append(dataclasses.replace(
                request, step_distance=distance, step_yaw=0.0,
                step_offset=request.step_offset - along))
            goals.append(Pose(edge_x - along * math.sin(normal) - reach * math.cos(normal),
                              along * math.cos(normal) - reach * math.sin(normal), normal))
    chosen: dict[int, _Approach | None] = {}

    def approachable(index: int) -> bool:
        if index not in chosen:
            options = _approaches(p, config, stagings[index], theta2, leading, push)
            usable = [a for a in options if a.error is None]
            chosen[index] = usable[0] if usable else None
        return chosen[index] is not None

    box = StepBox(edge_x, normal, request.step_width, request.step_offset)
    if collides(p, [Pose(0.0, 0.0, 0.0)], box, 0.0, swept=False):
        raise PlanError(ErrorCode.INVALID_REQUEST,
                        f'{first_error}; and the car stands against the step (a wheel over '
                        f"the edge's line within the top face): it cannot move from there")
    found = plan_path(p, goals, approachable, box, config.reposition_clearance,
                      config.max_reposition)
    if found is None:
        raise PlanError(ErrorCode.INVALID_REQUEST,
                        f'{first_error}; and no path of at most {config.max_reposition:.2f} m '
                        f'(max_reposition) on the free floor, '
                        f'{config.reposition_clearance:.2f} m clear of the step, reaches a '
                        f'pose the approach can start from')
    path, index = found
    return chosen[index], path, stagings[index]


def _lift_rules(p: SwivelCarParams, config: PlannerConfig, height: float,
                theta2: float) -> tuple[float, float, float]:
    """
    Return the lift angle [rad] at the swivel ``theta2`` [rad] and its two rule margins.

    The margins are on the tip-over rule [rad] and the wheel interference rule [m].

    Raises
    ------
    PlanError
        ``TIP_OVER`` or ``WHEEL_INTERFERENCE`` when a margin is short.

    """
    theta1 = float(kinematics.lift_angle(p, theta2))
    tip_margin = float(kinematics.tip_over_margin(p, theta1))
    if tip_margin < config.tip_over_margin:
        max_step, _ = kinematics.max_scalable_step(p, respect_tip_over=True)
        raise PlanError(ErrorCode.TIP_OVER,
                        f'lifting the wheel over {height:.3f} m pitches the car to '
                        f'{theta1:.3f} rad, {tip_margin:.3f} rad from tipping over '
                        f'(eq. 72); the planner wants {config.tip_over_margin:.3f} rad; the '
                        f'largest step that keeps the rule is {max_step:.3f} m')
    interference = float(kinematics.interference_margin(p, theta1))
    if interference <= 0.0:
        raise PlanError(ErrorCode.WHEEL_INTERFERENCE,
                        f'at the lift angle {theta1:.3f} rad the front wheel shaft reaches the '
                        f'rear wheels (eq. 75 margin {interference:.3f} m)')
    return theta1, tip_margin, interference


def _approaches(p: SwivelCarParams, config: PlannerConfig, request: ClimbRequest,
                theta2: float, leading: int, push: bool) -> list[_Approach]:
    """
    List the approaches to choose from, the one that turns the car the least first.

    The standard lift lifts the wheel that leads already (``leading``), the push-lift the
    other one. With the step's extent known, both sides: the one whose crossing of the edge
    lies nearer the top face may win.
    """
    preferred = -leading if push else leading
    sides = (preferred, -preferred) if request.step_width > 0.0 else (preferred,)
    make, lift = (_push_approach, p.swivel_limit) if push else (_approach, theta2)
    return [make(p, config, request, lift, side) for side in sides]


_BACKUP_INCREMENT = 0.05  # [m]


def _backups(max_backup: float) -> list[float]:
    """List backup distances to try, shortest first: 0, then steps up to ``max_backup`` [m]."""
    count = int(math.floor(max_backup / _BACKUP_INCREMENT + 1e-9))
    return [0.0] + [i * _BACKUP_INCREMENT for i in range(1, count + 1)] + (
        [max_backup] if max_backup > count * _BACKUP_INCREMENT + 1e-9 else [])
