"""Start the step detector: `ros2 launch swivel_car_perception perception.launch.py`."""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node
from launch_ros.parameter_descriptions import ParameterValue


def generate_launch_description() -> LaunchDescription:
    default_params = os.path.join(
        get_package_share_directory('swivel_car_perception'), 'config',
        'step_detector_node.yaml')
    return LaunchDescription([
        DeclareLaunchArgument('namespace', default_value='',
                              description='namespace of the robot'),
        DeclareLaunchArgument('params_file', default_value=default_params,
                              description='step detector parameter file'),
        DeclareLaunchArgument('use_sim_time', default_value='true',
                              description='run on the sim clock (/clock)'),
        # A dead detector is started again: the planner refuses detected climbs meanwhile
        # (no fresh detection), and a new detector starts a new estimate.
        Node(
            package='swivel_car_perception', executable='step_detector_node',
            name='step_detector', namespace=LaunchConfiguration('namespace'), output='screen',
            respawn=True, respawn_delay=1.0,
            parameters=[
                LaunchConfiguration('params_file'),
                {'use_sim_time': ParameterValue(LaunchConfiguration('use_sim_time'),
                                                value_type=bool)},
            ]),
    ])
