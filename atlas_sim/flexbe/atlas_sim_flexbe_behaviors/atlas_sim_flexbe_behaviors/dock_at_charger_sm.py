#!/usr/bin/env python
# -*- coding: utf-8 -*-

# Copyright 2026 behavior-synthesis
#
# Licensed under the BSD 3-Clause License (see the project's pyproject.toml).

###########################################################
#               WARNING: Generated code!                  #
#              **************************                 #
# Manual changes may get lost if file is generated again. #
# Only code inside the [MANUAL] tags will be kept.        #
###########################################################

"""
Define Dock At Charger.

Docks the simulated mobile manipulator at its charger.

Created on Sun Nov 22 2026
@author: behavior-synthesis
"""


from atlas_sim_flexbe_states.capability_action_state import CapabilityActionState
from flexbe_core import Autonomy
from flexbe_core import Behavior
from flexbe_core import ConcurrencyContainer
from flexbe_core import Logger
from flexbe_core import OperatableStateMachine
from flexbe_core import PriorityContainer
from flexbe_core import StateLogger
from flexbe_core.proxy import initialize_proxies

# Additional imports can be added inside the following tags
# [MANUAL_IMPORT]

# [/MANUAL_IMPORT]


class DockAtChargerSM(Behavior):
    """
    Define Dock At Charger.

    Docks the simulated mobile manipulator at its charger.
    """

    def __init__(self, node):
        super().__init__()
        self.name = 'Dock At Charger'

        # parameters of this behavior

        # initialize ROS node information
        ConcurrencyContainer.initialize_ros(node)
        Logger.initialize(node)
        StateLogger.initialize_ros(node)
        OperatableStateMachine.initialize_ros(node)
        PriorityContainer.initialize_ros(node)
        initialize_proxies(node)
        CapabilityActionState.initialize_ros(node)

        # references to used behaviors

        # Additional initialization code can be added inside the following tags
        # [MANUAL_INIT]

        # [/MANUAL_INIT]

        # Behavior comments:

    def create(self):
        """Create state machine."""
        # Root state machine
        # x:333 y:90, x:333 y:190
        _state_machine = OperatableStateMachine(outcomes=['finished', 'failed'])

        # Additional creation code can be added inside the following tags
        # [MANUAL_CREATE]

        # [/MANUAL_CREATE]

        with _state_machine:
            # x:60 y:80
            OperatableStateMachine.add('Dock',
                                       CapabilityActionState(capability='dock'),
                                       transitions={'completed': 'finished', 'failed': 'failed'},
                                       autonomy={'completed': Autonomy.Low, 'failed': Autonomy.Off})

        return _state_machine

    # Private functions can be added inside the following tags
    # [MANUAL_FUNC]

    # [/MANUAL_FUNC]
