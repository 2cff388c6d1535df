"""
Start the swivel car's controller and odometry (for a full Jazzy install with launch_ros).

ros2 launch swivel_car_control control.launch.py [use_sim_time:=true] [namespace:=robot1]
    [use_stamped:=true] [controller_params:=...] [odometry_params:=...]
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node
from launch_ros.parameter_descriptions import ParameterValue


def generate_launch_description():
    share = get_package_share_directory('swivel_car_control')
    use_sim_time = LaunchConfiguration('use_sim_time')
    namespace = LaunchConfiguration('namespace')
    return LaunchDescription([
        DeclareLaunchArgument('use_sim_time', default_value='true',
                              description='use the sim /clock'),
        DeclareLaunchArgument('namespace', default_value='',
                              description='namespace of the robot'),
        DeclareLaunchArgument('use_stamped', default_value='true',
                              description='cmd_vel is TwistStamped (true) or Twist (false)'),
        DeclareLaunchArgument(
            'controller_params',
            default_value=os.path.join(share, 'config', 'controller_node.yaml'),
            description='controller parameter file'),
        DeclareLaunchArgument(
            'odometry_params',
            default_value=os.path.join(share, 'config', 'odometry_node.yaml'),
            description='odometry parameter file'),
        # A dead controller or odometry is started again: the sim's watchdog has stopped the
        # car meanwhile, a new controller holds until commanded, a new odometry starts a new
        # odom frame at the origin, as at launch (a planner's climb ends NOT_READY).
        Node(package='swivel_car_control', executable='controller_node', name='controller',
             namespace=namespace, output='screen', respawn=True, respawn_delay=1.0,
             parameters=[LaunchConfiguration('controller_params'),
                         {'use_sim_time': ParameterValue(use_sim_time, value_type=bool),
                          'use_stamped': ParameterValue(LaunchConfiguration('use_stamped'),
                                                        value_type=bool)}]),
        Node(package='swivel_car_control', executable='odometry_node', name='odometry',
             namespace=namespace, output='screen', respawn=True, respawn_delay=1.0,
             parameters=[LaunchConfiguration('odometry_params'),
                         {'use_sim_time': ParameterValue(use_sim_time, value_type=bool)}]),
    ])
