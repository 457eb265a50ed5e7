// The panel explaining the state clicked on the drawing, as FlexBE's editor does: class,
// parameters, userdata, outcomes with their targets and autonomy, and a container's states.
// ``state`` is a node of the machine's tree (GET /api/jobs/{id}/state-machine).
import { $, element } from './dom.js';
import { vocabulary } from './vocabulary.js';

export function showStateDetails(state) {
  const panel = $('state-details');
  panel.hidden = !state;  // it floats over the drawing's corner, where a click shows it
  if (!state) {
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
  fitInWindow(panel);
  besideTheState(panel, state);
}

// The panel on the side of the drawing the clicked state is not on.
function besideTheState(panel, state) {
  panel.classList.remove('left');
  const node = document.getElementById(`state:${state.name}`);
  if (!node) return;
  const box = node.getBoundingClientRect();
  const area = panel.getBoundingClientRect();
  const overlaps = box.right > area.left && box.left < area.right && box.bottom > area.top && box.top < area.bottom;
  if (overlaps) panel.classList.add('left');
}

// The panel no taller than the part of the window below its top: all of it in view, scrolling inside.
function fitInWindow(panel) {
  panel.style.maxHeight = '';
  const top = panel.getBoundingClientRect().top;
  const room = window.innerHeight - Math.max(0, top) - 8;
  if (panel.offsetHeight > room) panel.style.maxHeight = `${Math.max(80, room)}px`;
}
