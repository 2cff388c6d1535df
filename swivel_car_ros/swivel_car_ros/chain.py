"""
The lockstep chain's nodes in the order of one control period, and what only ROS reads. ROS-free.

One control period (docs/architecture.md, "Timing: sim time and lockstep"): the sim has
published the state of time t; the controller answers it, the odometry integrates it, the
planner acts on the three inputs of t, and the sim applies the controller's command and
advances. ``swivel_car_studies.inprocess`` runs its cores in this order; the node tests check
each node's parameters against ``ROS_ONLY``.
"""

from __future__ import annotations

CHAIN = ('controller', 'odometry', 'planner', 'sim')

# Per node of the chain: the parameters its ROS side alone reads (transport, frames, timing
# of the graph); its core does not, so a stack of the cores accepts them without effect.
# use_sim_time is every node's (rclpy's own).
ROS_ONLY: dict[str, frozenset[str]] = {
    'controller': frozenset({
        'use_sim_time', 'use_stamped', 'base_frame_id', 'lockstep_swivel_command',
        'lockstep_cmd_vel', 'lockstep_wait'}),
    'odometry': frozenset({
        'use_sim_time', 'odom_frame_id', 'base_frame_id', 'tf_frame_prefix', 'enable_odom_tf',
        'pose_covariance_diagonal', 'twist_covariance_diagonal'}),
    'planner': frozenset({'use_sim_time', 'ready_timeout', 'detection_max_age'}),
    'sim': frozenset({
        'use_sim_time', 'gui', 'real_time_factor', 'lockstep', 'lockstep_timeout',
        'lockstep_real_time_factor', 'start_paused', 'clock_rate', 'world_frame_id',
        'base_frame_id', 'clock_source'}),
}
