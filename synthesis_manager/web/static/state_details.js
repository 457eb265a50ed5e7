// The panel explaining the state clicked on the drawing, as FlexBE's editor does: class,
// parameters, userdata, outcomes with their targets and autonomy, and a container's states.
// ``state`` is a node of the machine's tree (GET /api/jobs/{id}/state-machine).
import { $, element } from './dom.js';
import { vocabulary } from './vocabulary.js';

export function showStateDetails(state) {
  const panel = $('state-details');
  if (!state) {
    panel.replaceChildren(element('p', { className: 'muted', text: 'Click a state to see its class, parameters, userdata, outcomes and autonomy.' }));
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
  panel.replaceChildren(
    element('h3', { text: state.state_path.replace(/^\//, '') }),
    element('table', { className: 'details' },
      row('Class', className),
      row('Parameters', parameters.join(', ') || '—'),
      row('Userdata', userdata.join(', ') || '—'),
      row('Outcomes', element('ul', {}, ...outcomes)),
      ...(state.children.length ? [row('Contains', state.children.map((c) => `${c.name} (${c.state_class})`).join(', '))] : [])));
}
