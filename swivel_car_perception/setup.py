from glob import glob

from setuptools import find_packages, setup

package_name = 'swivel_car_perception'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml', 'README.md']),
        ('share/' + package_name + '/config', glob('config/*.yaml')),
        ('share/' + package_name + '/launch', glob('launch/*.launch.py')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Swivel car team',
    maintainer_email='team@swivel-car.invalid',
    description='Step detection in depth images, fused over frames with odometry.',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'step_detector_node = swivel_car_perception.step_detector_node:main',
        ],
    },
)
