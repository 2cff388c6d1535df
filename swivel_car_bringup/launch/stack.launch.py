"""
The whole stack: sim, controller, odometry, planner, step detector and the robot on the graph.

Optionally a recording and a live view (for a full Jazzy install with launch_ros).

ros2 launch swivel_car_bringup stack.launch.py [record:=true] [bag:=my_run]
    [foxglove:=true] [foxglove_port:=8765] [gui:=true] [robot_variant:=swivel]
    [clock_source:=wall] [sensor_profile:=realistic]

clock_source:=wall runs the stack as on the robot: the sim stamps with the system clock and
publishes no /clock, and every node runs with use_sim_time false; sim (the default) puts
every node on the sim's /clock.
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import (
    DeclareLaunchArgument, IncludeLaunchDescription, SetEnvironmentVariable)
from launch.conditions import IfCondition
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import EnvironmentVariable, LaunchConfiguration, PythonExpression
from launch_ros.actions import Node
from launch_ros.parameter_descriptions import ParameterValue


def _include(package: str, launch_file: str, arguments: dict) -> IncludeLaunchDescription:
    return IncludeLaunchDescription(
        PythonLaunchDescriptionSource(os.path.join(
            get_package_share_directory(package), 'launch', launch_file)),
        launch_arguments=arguments.items())


def generate_launch_description() -> LaunchDescription:
    # One switch for every node: on the sim's /clock, or all on the system clock.
    on_sim_time = PythonExpression(["'", LaunchConfiguration('clock_source'), "' != 'wall'"])
    use_sim_time = {'use_sim_time': ParameterValue(on_sim_time, value_type=bool)}
    sim_time_argument = {'use_sim_time': on_sim_time}
    return LaunchDescription([
        # One BLAS thread per node unless set otherwise: OpenBLAS's extra threads spin after
        # each call (the README, "With a real driver", has what they cost).
        SetEnvironmentVariable('OPENBLAS_NUM_THREADS', EnvironmentVariable(
            'OPENBLAS_NUM_THREADS', default_value='1')),
        DeclareLaunchArgument('clock_source', default_value='sim',
                              description='sim: every node on the sim /clock; wall: as on the '
                                          'robot, system clock, use_sim_time false everywhere'),
        DeclareLaunchArgument('sensor_profile', default_value='ideal',
                              description='ideal | realistic | a sensor profile YAML path'),
        DeclareLaunchArgument('gui', default_value='false',
                              description='open the pybullet window'),
        DeclareLaunchArgument('robot_variant', default_value='swivel',
                              description='swivel | car_like'),
        DeclareLaunchArgument('record', default_value='false',
                              description='record every topic into a rosbag2 bag (MCAP)'),
        DeclareLaunchArgument('bag', default_value='',
                              description="bag directory; '' = rosbag2_<date>_<time>"),
        DeclareLaunchArgument('foxglove', default_value='false',
                              description='serve the topics to Foxglove over WebSocket'),
        DeclareLaunchArgument('foxglove_port', default_value='8765',
                              description='port of the Foxglove WebSocket server'),
        _include('swivel_car_sim', 'sim.launch.py', {
            **sim_time_argument, 'gui': LaunchConfiguration('gui'),
            'robot_variant': LaunchConfiguration('robot_variant'),
            'clock_source': LaunchConfiguration('clock_source'),
            'sensor_profile': LaunchConfiguration('sensor_profile')}),
        _include('swivel_car_control', 'control.launch.py', sim_time_argument),
        _include('swivel_car_planner', 'planner.launch.py', sim_time_argument),
        _include('swivel_car_perception', 'perception.launch.py', sim_time_argument),
        Node(package='swivel_car_telemetry', executable='robot_description_node',
             name='robot_description', output='screen',
             parameters=[{**use_sim_time, 'robot_variant': ParameterValue(
                 LaunchConfiguration('robot_variant'), value_type=str)}]),
        Node(package='swivel_car_telemetry', executable='recorder_node', name='recorder',
             output='screen', condition=IfCondition(LaunchConfiguration('record')),
             parameters=[{**use_sim_time, 'output': ParameterValue(
                 LaunchConfiguration('bag'), value_type=str)}]),
        Node(package='swivel_car_telemetry', executable='foxglove_bridge_node',
             name='foxglove_bridge', output='screen',
             condition=IfCondition(LaunchConfiguration('foxglove')),
             parameters=[{**use_sim_time, 'port': ParameterValue(
                 LaunchConfiguration('foxglove_port'), value_type=int)}]),
    ])
