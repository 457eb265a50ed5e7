"""A FlexBE user's colcon workspace."""

# Our ROS packages in a user's workspace (README, "Use it from FlexBE", step 1).
WORKSPACE_PACKAGES = ('synthesis_msgs', 'atlas_sim/flexbe/atlas_sim_flexbe_states',
                      'atlas_sim/flexbe/atlas_sim_flexbe_behaviors', 'behavior_synthesis_bringup')
