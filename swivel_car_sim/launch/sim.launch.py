"""
Start the swivel car sim: ros2 launch swivel_car_sim sim.launch.py [gui:=true] ...

clock_source:=wall use_sim_time:=false runs it as the robot's driver board would (system
clock, no /clock); sensor_profile:=realistic gives it the hardware's sensors and links.
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node
from launch_ros.parameter_descriptions import ParameterValue


def generate_launch_description():
    default_params = os.path.join(get_package_share_directory('swivel_car_sim'), 'config',
                                  'sim_node.yaml')
    arguments = [
        DeclareLaunchArgument('use_sim_time', default_value='true',
                              description='the sim publishes /clock; true for consistency'),
        DeclareLaunchArgument('gui', default_value='false',
                              description='open the pybullet window'),
        DeclareLaunchArgument('real_time_factor', default_value='1.0',
                              description='[1] 0 = as fast as possible'),
        DeclareLaunchArgument('params_file', default_value=default_params,
                              description='sim node parameter file'),
        DeclareLaunchArgument('robot_variant', default_value='swivel',
                              description='swivel | car_like'),
        DeclareLaunchArgument('clock_source', default_value='sim',
                              description='sim (/clock) | wall (system clock, as the robot)'),
        DeclareLaunchArgument('sensor_profile', default_value='ideal',
                              description='ideal | realistic | a sensor profile YAML path'),
    ]
    # Not respawned: a new sim is a new world (the robot at the origin, no obstacles).
    sim = Node(
        package='swivel_car_sim', executable='sim_node', name='sim', output='screen',
        parameters=[
            LaunchConfiguration('params_file'),
            {
                'use_sim_time': ParameterValue(LaunchConfiguration('use_sim_time'),
                                               value_type=bool),
                'gui': ParameterValue(LaunchConfiguration('gui'), value_type=bool),
                'real_time_factor': ParameterValue(LaunchConfiguration('real_time_factor'),
                                                   value_type=float),
                'robot_variant': ParameterValue(LaunchConfiguration('robot_variant'),
                                                value_type=str),
                'clock_source': ParameterValue(LaunchConfiguration('clock_source'),
                                               value_type=str),
                'sensor_profile': ParameterValue(LaunchConfiguration('sensor_profile'),
                                                 value_type=str),
            },
        ])
    return LaunchDescription(arguments + [sim])
