from glob import glob

from setuptools import find_packages, setup

package_name = 'swivel_car_telemetry'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml', 'README.md']),
        ('share/' + package_name + '/config', glob('config/*.json')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Swivel car team',
    maintainer_email='team@swivel-car.invalid',
    description='The robot on the graph and its record: the URDF and TF (robot_description_node), '
                'rosbag2 bags with MCAP storage (recorder_node), a live Foxglove view '
                '(foxglove_bridge_node).',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'recorder_node = swivel_car_telemetry.recorder_node:main',
            'robot_description_node = swivel_car_telemetry.robot_description_node:main',
            'foxglove_bridge_node = swivel_car_telemetry.foxglove_bridge_node:main',
        ],
    },
)
