// The panel explaining the state clicked on the drawing, as FlexBE's editor does: class,
// parameters, userdata, outcomes with their targets and autonomy, and a container's states.
// ``state`` is a node of the machine's tree (GET /api/jobs/{id}/state-machine).
import * as drawing from './drawing.js';
import { $, element } from './dom.js';
import { vocabulary } from './vocabulary.js';

export function showStateDetails(state) {
  const panel = $('state-details');
  panel.hidden = !state;  // it floats over the drawing's corner, where a click shows it
  if (!state) {
    shownState = null;
    panel.replaceChildren();
    return;
  }
  const { state_classes: classes, autonomy_levels: levels } = vocabulary();
  const row = (name, ...values) => element('tr', {}, element('th', { text: name }), element('td', {}, ...values));
  const className = state.state_class === classes.behavior ? `${state.behavior_class} (behavior)`
    : state.state_class === classes.concurrency ? 'concurrency container' : state.state_class;
  const parameters = state.parameter_names.map((n, i) => `${n} = ${state.parameter_values[i]}`);
  const userdata = state.userdata_keys.map((k, i) => `${k} ← ${state.userdata_remapping[i] || k}`);
  const outcomes = state.outcomes.map((o, i) => element('li', { text: `${o} → ${state.transitions[i]}` +
    (state.autonomy.length ? ` (autonomy ${levels[state.autonomy[i]] ?? state.autonomy[i]})` : '') }));
  const close = element('button', { type: 'button', className: 'small close', 'aria-label': 'close the state details',
    title: 'close', text: '×' });
  close.addEventListener('click', () => showStateDetails(null));
  panel.replaceChildren(
    close,
    element('h3', { text: state.state_path.replace(/^\//, '') }),
    element('table', { className: 'details' },
      row('Class', className),
      row('Parameters', parameters.join(', ') || '—'),
      row('Userdata', userdata.join(', ') || '—'),
      row('Outcomes', element('ul', {}, ...outcomes)),
      ...(state.children.length ? [row('Contains', state.children.map((c) => `${c.name} (${c.state_class})`).join(', '))] : [])));
  shownState = state.name;
  fitInWindow(panel);
  keepClear(panel);
}

let shownState = null;  // the name of the state the panel explains

function overlaps(node, panel) {
  const box = node.getBoundingClientRect();
  const area = panel.getBoundingClientRect();
  return box.right > area.left && box.left < area.right && box.bottom > area.top && box.top < area.bottom;
}

// The panel on a side of the drawing where it covers neither the active state of a run or play
// nor, if it can, the state it explains; when both sides would cover the active state, the
// drawing moves it out from under the panel.
function keepClear(panel) {
  const active = document.querySelector('#graph g.node.active');
  const clicked = shownState ? document.getElementById(`state:${shownState}`) : null;
  const wanted = [[active, clicked].filter(Boolean), [active].filter(Boolean)];
  for (const nodes of wanted) {
    for (const left of [false, true]) {
      panel.classList.toggle('left', left);
      if (nodes.every((node) => !overlaps(node, panel))) return;
    }
  }
  panel.classList.remove('left');
  if (active) drawing.moveOutFrom(active, panel.getBoundingClientRect());
}

// After each move of a run or play: the panel still clear of the active state.
drawing.whenMarked(() => { if (!$('state-details').hidden) keepClear($('state-details')); });

// The panel no taller than the part of the window below its top: all of it in view, scrolling inside.
function fitInWindow(panel) {
  panel.style.maxHeight = '';
  const top = panel.getBoundingClientRect().top;
  const room = window.innerHeight - Math.max(0, top) - 8;
  if (panel.offsetHeight > room) panel.style.maxHeight = `${Math.max(80, room)}px`;
}
