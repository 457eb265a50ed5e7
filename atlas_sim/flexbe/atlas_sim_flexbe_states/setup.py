"""colcon (ament_python) build of the atlas_sim FlexBE state package."""

from setuptools import find_packages, setup

PACKAGE_NAME = 'atlas_sim_flexbe_states'

setup(
    name=PACKAGE_NAME,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + PACKAGE_NAME]),
        ('share/' + PACKAGE_NAME, ['package.xml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Behavior synthesis maintainers',
    maintainer_email='behavior-synthesis@example.org',
    description='FlexBE states driving the atlas_sim simulator node',
    license='BSD-3-Clause',
)
