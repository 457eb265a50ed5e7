"""A timeline plot of an executed run: control modes and actions over robot time (PNG).

Rows: the control mode the robot is in (one coloured band per mode), then one row per
capability with a bar from its activation to its result (green completed, red failed,
grey still running when the state ended); vertical lines mark state changes. Uses
matplotlib's Agg backend, so no display is needed.
"""

from __future__ import annotations

from pathlib import Path

from atlas_sim.executive.trace_check import Trace
from respec.vocabulary.naming import COMPLETED, FAILED

OUTCOME_COLOURS = {COMPLETED: '#3a9d5d', FAILED: '#d64541', None: '#9e9e9e'}


def mode_segments(trace: Trace) -> list[tuple[str, float, float]]:
    """(mode, start, end) over the run, from the first step's mode and completed mode changes."""
    if not trace.steps:
        return []
    modes = {s.mode_at_entry for s in trace.steps} | {s.mode_at_exit for s in trace.steps}
    changes = sorted((r['time'], r['capability']) for s in trace.steps for r in s.results
                     if r['outcome'] == COMPLETED and r['capability'] in modes)
    segments, mode, start = [], trace.steps[0].mode_at_entry, trace.steps[0].entered_at
    for when, new_mode in changes:
        if new_mode != mode:
            segments.append((mode, start, when))
            mode, start = new_mode, when
    segments.append((mode, start, trace.steps[-1].ended_at))
    return segments


def capability_bars(trace: Trace) -> list[tuple[str, float, float, str | None]]:
    """(capability, activated at, ended at, outcome or None) for every activation."""
    bars: list[tuple[str, float, float, str | None]]
    open_bars: dict[str, float]
    bars, open_bars = [], {}  # capability -> start of an activation carried over to the next state
    for step in trace.steps:
        ended = {r['capability']: r for r in step.results if not r.get('abandoned')}
        for capability in step.capabilities:
            start = open_bars.pop(capability, step.entered_at)
            if capability in ended:
                bars.append((capability, start, ended[capability]['time'], ended[capability]['outcome']))
            else:
                open_bars[capability] = start
        for capability, start in list(open_bars.items()):
            if capability not in step.capabilities:  # abandoned: draw up to the end of the state
                bars.append((capability, start, step.ended_at, None))
                del open_bars[capability]
    if trace.steps:
        bars.extend((c, start, trace.steps[-1].ended_at, None) for c, start in open_bars.items())
    return bars


#: Characters of a title line: a 10-inch figure holds about 110 of matplotlib's 12 pt title.
TITLE_LINE_CHARACTERS = 100


def wrapped_title(title: str, width: int = TITLE_LINE_CHARACTERS) -> str:
    """``title`` broken into lines at spaces, so that a long goal list is not cut at both ends."""
    import textwrap
    return '\n'.join(textwrap.wrap(title, width)) or title


def plot_timeline(trace: Trace, path: str | Path, title: str = '') -> Path:
    """Draw the timeline of ``trace`` into the PNG file ``path``."""
    figure = timeline_figure(trace, title)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, dpi=100)
    import matplotlib.pyplot as plt
    plt.close(figure)
    return path


def timeline_figure(trace: Trace, title: str = ''):
    """The matplotlib figure of :func:`plot_timeline` (the caller closes it)."""
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    segments, bars = mode_segments(trace), capability_bars(trace)
    capabilities = list(dict.fromkeys(bar[0] for bar in bars))
    rows = ['mode'] + capabilities
    figure, axes = plt.subplots(figsize=(10, 1.2 + 0.45 * len(rows)))
    palette = plt.get_cmap('tab10')
    mode_colours = {m: palette(i % 10) for i, m in enumerate(dict.fromkeys(s[0] for s in segments))}
    for mode, start, end in segments:
        axes.barh(0, end - start, left=start, color=mode_colours[mode], edgecolor='black', height=0.6)
        axes.text((start + end) / 2, 0, mode, ha='center', va='center', fontsize=8)
    for capability, start, end, outcome in bars:
        row = rows.index(capability)
        axes.barh(row, max(end - start, 0.02), left=start, color=OUTCOME_COLOURS[outcome], height=0.6)
    for step in trace.steps:
        axes.axvline(step.entered_at, color='#cccccc', linewidth=0.6, zorder=0)
    axes.set_yticks(range(len(rows)), rows)
    axes.invert_yaxis()
    axes.set_xlabel('robot time (s)')
    axes.set_title(wrapped_title(title or f'outcome: {trace.outcome}'))
    figure.tight_layout()
    return figure
