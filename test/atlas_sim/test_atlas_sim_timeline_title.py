"""The timeline plot's title stays inside the picture, however many goals it names."""

from atlas_sim.executive.timeline import timeline_figure, wrapped_title
from atlas_sim.executive.trace_check import Trace, TraceStep

TWELVE_GOALS = ('look_down, object_template, approach_object, pregrasp_pose, pregrasp_plan, pregrasp, '
                'grasp_object, pickup_object, target_pose, footstep_goal, footstep_plan, footstep_execution: '
                'finished')


def test_a_twelve_goal_title_is_wrapped_inside_the_figure():
    trace = Trace(steps=[TraceStep(index=0, state='/stand', state_class='ChangeControlModeActionState',
                                   activated=['stand_a'], capabilities=['stand'], entered_at=0.0, ended_at=1.5,
                                   mode_at_entry='stand_prep', mode_at_exit='stand',
                                   results=[{'capability': 'stand', 'outcome': 'completed', 'reason': '',
                                             'time': 1.5, 'abandoned': False}])], outcome='finished')
    import matplotlib.pyplot as plt
    figure = timeline_figure(trace, TWELVE_GOALS)
    try:
        figure.canvas.draw()
        title = figure.axes[0].title
        box, frame = title.get_window_extent(), figure.bbox
        assert frame.x0 <= box.x0 and box.x1 <= frame.x1 and box.y1 <= frame.y1
        assert title.get_text().replace('\n', ' ') == TWELVE_GOALS
    finally:
        plt.close(figure)
    assert wrapped_title('look_down: finished') == 'look_down: finished'
