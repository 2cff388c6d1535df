from glob import glob

from setuptools import find_packages, setup

package_name = 'swivel_car_studies'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml', 'README.md']),
        ('share/' + package_name + '/config/campaigns', glob('config/campaigns/*.yaml')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Swivel car team',
    maintainer_email='team@swivel-car.invalid',
    description='Studies of the stack without ROS: the cores wired in one process, the climb '
                'benchmarks, design campaigns on Ray and the design report.',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'campaign = swivel_car_studies.campaign:main',
            'design_report = swivel_car_studies.design_report:main',
        ],
    },
)
