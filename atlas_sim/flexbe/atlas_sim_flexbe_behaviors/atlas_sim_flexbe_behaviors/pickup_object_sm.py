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
Define Pickup Object.

Picks up the selected object template (input key template_id) with the simulated ATLAS.

Created on Sun Nov 22 2026
@author: behavior-synthesis
"""


from atlas_sim_flexbe_states.object_action_state import ObjectActionState
from flexbe_core import Autonomy
from flexbe_core import Behavior
from flexbe_core import ConcurrencyContainer
from flexbe_core import Logger
from flexbe_core import OperatableStateMachine
from flexbe_core import PriorityContainer
from flexbe_core import StateLogger
from flexbe_core.proxy import initialize_proxies
from flexbe_states.check_condition_state import CheckConditionState

# Additional imports can be added inside the following tags
# [MANUAL_IMPORT]

# [/MANUAL_IMPORT]


class PickupObjectSM(Behavior):
    """
    Define Pickup Object.

    Picks up the selected object template (input key template_id) with the simulated ATLAS.
    """

    def __init__(self, node):
        super().__init__()
        self.name = 'Pickup Object'

        # parameters of this behavior

        # initialize ROS node information
        ConcurrencyContainer.initialize_ros(node)
        Logger.initialize(node)
        StateLogger.initialize_ros(node)
        OperatableStateMachine.initialize_ros(node)
        PriorityContainer.initialize_ros(node)
        initialize_proxies(node)
        ObjectActionState.initialize_ros(node)
        CheckConditionState.initialize_ros(node)

        # references to used behaviors

        # Additional initialization code can be added inside the following tags
        # [MANUAL_INIT]

        # [/MANUAL_INIT]

        # Behavior comments:

    def create(self):
        """Create state machine."""
        # Root state machine
        # x:533 y:90, x:533 y:190
        _state_machine = OperatableStateMachine(outcomes=['finished', 'failed'], input_keys=['template_id'])
        _state_machine.userdata.template_id = None

        # Additional creation code can be added inside the following tags
        # [MANUAL_CREATE]

        # [/MANUAL_CREATE]

        with _state_machine:
            # x:60 y:80
            OperatableStateMachine.add('Check Template',
                                       CheckConditionState(predicate=lambda template_id: template_id is not None),
                                       transitions={'true': 'Pick Up', 'false': 'failed'},
                                       autonomy={'true': Autonomy.Off, 'false': Autonomy.Off},
                                       remapping={'input_value': 'template_id'})

            # x:300 y:80
            OperatableStateMachine.add('Pick Up',
                                       ObjectActionState(capability='pickup_object'),
                                       transitions={'completed': 'finished', 'failed': 'failed'},
                                       autonomy={'completed': Autonomy.Low, 'failed': Autonomy.Off},
                                       remapping={'template_id': 'template_id'})

        return _state_machine

    # Private functions can be added inside the following tags
    # [MANUAL_FUNC]

    # [/MANUAL_FUNC]
