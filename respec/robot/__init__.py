"""Robot systems: what a robot can do, as the synthesis sees it (ROS-free).

Modules:
    system         RobotSystem (one system, loaded once, validated, immutable), robot_system(), SystemCatalog,
                   and the catalog as JSON (how a suite serves its systems: ServedCatalog)
    files          locating and reading system files (config/<system>.yaml), their errors
    description    the robot interface both formats implement (RobotDescription); a layer above keeps what
                   it does per format in a registry read with system.for_description
    abstraction    our own format's discrete abstraction (the ``abstraction:`` section)
    cnu            robots described by CNU flexbe_synthesis capability files
    state_library  the FlexBE state classes of a workspace (its ament index), read without importing them
"""

from respec.robot.description import RobotDescription
from respec.robot.system import (ABSTRACTION_KIND, CAPABILITIES_KIND, RobotSystem, ServedCatalog, SystemCatalog,
                                 catalog_to_json, for_description, robot_system, robot_system_from_file,
                                 robot_system_from_files)

__all__ = ['ABSTRACTION_KIND', 'CAPABILITIES_KIND', 'RobotDescription', 'RobotSystem', 'ServedCatalog',
           'SystemCatalog', 'catalog_to_json', 'for_description', 'robot_system', 'robot_system_from_file',
           'robot_system_from_files']
