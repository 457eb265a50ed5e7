"""colcon (ament_python) build of the atlas_sim FlexBE behavior package.

Behavior manifests go to lib/<package>/manifest, where flexbe_core's BehaviorLibrary
(flexbe_onboard) looks for them.
"""

from glob import glob

from setuptools import find_packages, setup

PACKAGE_NAME = 'atlas_sim_flexbe_behaviors'

setup(
    name=PACKAGE_NAME,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + PACKAGE_NAME]),
        ('share/' + PACKAGE_NAME, ['package.xml']),
        ('lib/' + PACKAGE_NAME + '/manifest', glob('manifest/*.xml')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Behavior synthesis maintainers',
    maintainer_email='behavior-synthesis@example.org',
    description='FlexBE behaviors for atlas_sim robots',
    license='BSD-3-Clause',
)
