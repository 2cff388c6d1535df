"""Start the step-climbing planner: `ros2 launch swivel_car_planner planner.launch.py`."""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node
from launch_ros.parameter_descriptions import ParameterValue


def generate_launch_description() -> LaunchDescription:
    default_params = os.path.join(
        get_package_share_directory('swivel_car_planner'), 'config', 'planner_node.yaml')
    return LaunchDescription([
        DeclareLaunchArgument('namespace', default_value='',
                              description='namespace of the robot'),
        DeclareLaunchArgument('params_file', default_value=default_params,
                              description='planner parameter file'),
        DeclareLaunchArgument('use_sim_time', default_value='true',
                              description='run on the sim clock (/clock)'),
        # A dead planner is started again: its climb's client got no answer, the controller's
        # swivel_command deadman stopped the car, and a new planner starts with no climb.
        Node(
            package='swivel_car_planner', executable='planner_node', name='planner',
            namespace=LaunchConfiguration('namespace'), output='screen',
            respawn=True, respawn_delay=1.0,
            parameters=[
                LaunchConfiguration('params_file'),
                {'use_sim_time': ParameterValue(LaunchConfiguration('use_sim_time'),
                                                value_type=bool)},
            ]),
    ])
