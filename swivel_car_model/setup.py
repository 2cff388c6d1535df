from glob import glob

from setuptools import find_packages, setup

package_name = 'swivel_car_model'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/config/designs', glob('config/designs/*.yaml')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Swivel car team',
    maintainer_email='team@swivel-car.invalid',
    description='The swivel car kinematics, dynamics and climbing geometry, ROS-free.',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [],
    },
)
