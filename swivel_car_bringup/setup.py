from glob import glob

from setuptools import find_packages, setup

package_name = 'swivel_car_bringup'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml', 'README.md']),
        ('share/' + package_name + '/launch', glob('launch/*.launch.py')),
        ('share/' + package_name + '/config/campaigns', glob('config/campaigns/*.yaml')),
        ('share/' + package_name + '/config', glob('config/*.json')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Swivel car team',
    maintainer_email='team@swivel-car.invalid',
    description='The whole stack: launch, recording, the robot on the graph, a live view; and '
                'the stack wired in one process, without ROS, for design campaigns.',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'recorder_node = swivel_car_bringup.recorder_node:main',
            'robot_description_node = swivel_car_bringup.robot_description_node:main',
            'foxglove_bridge_node = swivel_car_bringup.foxglove_bridge_node:main',
            'campaign = swivel_car_bringup.campaign:main',
            'design_report = swivel_car_bringup.design_report:main',
        ],
    },
)
