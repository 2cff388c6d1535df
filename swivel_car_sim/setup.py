from glob import glob

from setuptools import find_packages, setup

package_name = 'swivel_car_sim'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml', 'README.md']),
        ('share/' + package_name + '/config', glob('config/*.yaml')),
        ('share/' + package_name + '/config/sensor_profiles',
         glob('config/sensor_profiles/*.yaml')),
        ('share/' + package_name + '/launch', glob('launch/*.launch.py')),
        ('share/' + package_name + '/urdf', glob('urdf/*.urdf')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Swivel car team',
    maintainer_email='team@swivel-car.invalid',
    description='pybullet simulation of the swivel car, the hardware stand-in.',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'sim_node = swivel_car_sim.sim_node:main',
        ],
    },
)
