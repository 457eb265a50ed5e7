// The behavior synthesis page: build a request from the system's own names, run it as a
// job on the server, follow its progress (server-sent events) and show the result.
'use strict';

const $ = (id) => document.getElementById(id);

const SECTION_TITLES = {
  env_props: 'Environment propositions (inputs)',
  sys_props: 'System propositions (outputs)',
  env_init: 'Environment initial conditions',
  sys_init: 'System initial conditions',
  env_trans: 'Environment safety',
  sys_trans: 'System safety',
  env_liveness: 'Environment liveness',
  sys_liveness: 'System liveness',
};

const DOWNLOAD_LABELS = {
  'state_machine.yaml': 'State machine (StateInstantiation list, YAML)',
  'state_machine.json': 'State machine (StateInstantiation list, JSON)',
  'state_machine.svg': 'Picture (SVG)',
  'state_machine.png': 'Picture (PNG)',
  'state_machine.dot': 'Picture source (Graphviz DOT)',
  'specification.structuredslugs': 'Specification (.structuredslugs)',
  'specification.slugsin': 'Specification (.slugsin)',
  'automaton.json': 'Automaton (JSON)',
  'result.json': 'Whole result (JSON)',
  'flexbe_behavior.zip': 'FlexBE behavior package (.zip, as export-behavior writes it)',
};

let currentJob = null;   // id of the job being followed
let events = null;       // its EventSource
let shownJob = null;     // the job whose result is on the page
let choices = null;      // the current system's control modes and actions
let canSimulate = false; // the server can run atlas_sim
let simulationEvents = null;

function element(tag, attributes = {}, ...children) {
  const node = document.createElement(tag);
  for (const [name, value] of Object.entries(attributes)) {
    if (name === 'text') node.textContent = value;
    else if (name === 'className') node.className = value;
    else node.setAttribute(name, value);
  }
  for (const child of children) node.append(child);
  return node;
}

async function api(method, path, body) {
  const options = { method, headers: {} };
  if (body !== undefined) {
    options.headers['Content-Type'] = 'application/json';
    options.body = JSON.stringify(body);
  }
  const response = await fetch(path, options);
  const data = await response.json().catch(() => ({}));
  if (!response.ok) {
    const error = new Error(data.message || `${response.status} ${response.statusText}`);
    error.code = data.error || String(response.status);
    error.item = data.item;
    throw error;
  }
  return data;
}

// --- the request form --------------------------------------------------------------------

async function loadSystems() {
  const [{ systems }, info] = await Promise.all([api('GET', '/api/systems'), api('GET', '/api/info')]);
  $('backend-description').textContent = info.description || '';
  canSimulate = info.simulation;
  const select = $('system');
  select.replaceChildren(...systems.map((name) => element('option', { value: name, text: name })));
  if (systems.includes('atlas')) select.value = 'atlas';
  await loadChoices();
}

async function loadChoices() {
  choices = await api('GET', `/api/systems/${encodeURIComponent($('system').value)}`);
  const checkbox = (name, hint, checked) => {
    const box = element('input', { type: 'checkbox', value: name, name: 'initial-condition' });
    box.checked = checked;
    return element('label', { className: 'choice', title: hint }, box, ` ${name}`);
  };
  const defaults = new Set(choices.default_initial_conditions);
  $('initial-control-modes').replaceChildren(
    element('span', { className: 'group-title', text: 'Control modes' }),
    ...choices.control_modes.map((m) => checkbox(m.name, `next: ${m.next.join(', ') || '—'}`, defaults.has(m.name))));
  $('initial-actions').replaceChildren(
    element('span', { className: 'group-title', text: 'Actions (already completed)' }),
    ...choices.actions.map((a) => checkbox(a.name, `needs: ${a.preconditions.join(', ') || 'nothing'}`, false)));

  const group = (label, items, hint) => element('optgroup', { label },
    ...items.map((item) => element('option', { value: item.name, title: hint(item), text: item.name })));
  $('goal-choice').replaceChildren(
    group('Actions', choices.actions, (a) => `needs: ${a.preconditions.join(', ') || 'nothing'}`),
    group('Control modes', choices.control_modes, (m) => `reached from: ${predecessors(m.name).join(', ') || 'no other mode'}`));
  $('goals').replaceChildren();
  updateGoalsHint();
}

// The control modes that can change to ``mode`` (its own self-loop aside).
function predecessors(mode) {
  return choices.control_modes.filter((m) => m.name !== mode && m.next.includes(mode)).map((m) => m.name);
}

function goalItem(name) {
  const button = (text, label, action) => {
    const b = element('button', { type: 'button', className: 'small', title: label, 'aria-label': `${label} ${name}`, text });
    b.addEventListener('click', action);
    return b;
  };
  const item = element('li', { 'data-goal': name }, element('span', { className: 'goal-name', text: name }));
  item.append(
    button('↑', 'move up', () => { if (item.previousElementSibling) item.previousElementSibling.before(item); }),
    button('↓', 'move down', () => { if (item.nextElementSibling) item.nextElementSibling.after(item); }),
    button('×', 'remove', () => { item.remove(); updateGoalsHint(); }));
  return item;
}

function addGoal() {
  const name = $('goal-choice').value;
  if (!name) return;
  $('goals').append(goalItem(name));
  updateGoalsHint();
}

function updateGoalsHint() {
  $('goals-empty').hidden = $('goals').children.length > 0;
}

function currentRequest() {
  const checked = (selector) => document.querySelector(selector).value;
  return {
    system: $('system').value,
    initial_conditions: [...document.querySelectorAll('input[name="initial-condition"]:checked')].map((b) => b.value),
    goals: [...$('goals').children].map((item) => item.dataset.goal),
    sm_outcomes: checked('input[name="sm-outcomes"]:checked').split(','),
    option: checked('input[name="option"]:checked') || null,
    unordered: $('unordered').checked,
    name: $('behavior-name').value.trim(),
  };
}

// --- running a job -----------------------------------------------------------------------

async function synthesize(event) {
  event.preventDefault();
  stopFollowing();
  resetResult();
  let job;
  try {
    job = await api('POST', '/api/jobs', currentRequest());
  } catch (error) {
    showRequestError(error);
    return;
  }
  currentJob = job.id;
  setRunning(true);
  showProgress(job);
  events = new EventSource(`/api/jobs/${job.id}/events`);
  events.addEventListener('progress', (message) => showProgress(JSON.parse(message.data)));
  events.addEventListener('finished', (message) => {
    stopFollowing();
    finish(JSON.parse(message.data));
  });
  events.onerror = () => {
    // The stream broke (e.g. the server restarted): fall back to asking once.
    stopFollowing();
    api('GET', `/api/jobs/${job.id}`).then(finish, (error) => showRequestError(error));
  };
}

async function cancel() {
  if (!currentJob) return;
  $('cancel').disabled = true;
  try {
    showProgress(await api('POST', `/api/jobs/${currentJob}/cancel`));
  } catch (error) {
    $('status').textContent = error.message;
  }
}

function stopFollowing() {
  if (events) events.close();
  events = null;
}

function setRunning(running) {
  $('synthesize').disabled = running;
  $('cancel').disabled = !running;
  document.body.classList.toggle('running', running);
}

function showProgress(job) {
  $('progress').value = job.progress;
  $('status').textContent = job.status;
  $('timeline').replaceChildren(...job.timeline.map((entry) => element('li', {},
    element('span', { className: 'time', text: formatSeconds(entry.seconds) }),
    element('span', { text: entry.status }))));
}

function finish(job) {
  setRunning(false);
  showProgress(job);
  if (job.state !== 'finished') return;
  currentJob = null;
  showResult(job);
}

// --- the result --------------------------------------------------------------------------

function resetResult() {
  $('result').hidden = true;
  shownJob = null;
  resetSimulation();
  for (const id of ['graph-section', 'downloads-section', 'specification-section', 'simulation-section']) {
    $(id).hidden = true;
  }
  $('graph').replaceChildren();
  $('timeline').replaceChildren();
  $('progress').value = 0;
}

// A message's first line is its plain sentence; the rest (e.g. the unrealizable core and the
// synthesizer's own account) goes into a collapsed "Details".
function showBanner(code, message, good) {
  $('result').hidden = false;
  $('result-banner').className = `banner ${good ? 'good' : 'bad'}`;
  $('result-code').textContent = code;
  const [sentence, ...rest] = (message || '').split('\n');
  $('result-message').textContent = sentence;
  const details = rest.join('\n').trim();
  $('result-details').hidden = !details;
  $('result-details-text').textContent = details;
  const top = $('result-banner').getBoundingClientRect().top;
  if (top < 0 || top > window.innerHeight) $('result-banner').scrollIntoView({ block: 'start' });
}

function showRequestError(error) {
  setRunning(false);
  $('status').textContent = 'The request was not accepted.';
  showBanner(error.code, error.message, false);
  $('summary').replaceChildren();
}

function showResult(job) {
  const { outcome, summary } = job;
  const message = outcome.message || (summary.succeeded ? describeSuccess(job) : '');
  showBanner(outcome.error_name, message, summary.succeeded);
  showSummary(summary, job.stages);
  if (job.artifacts.includes('state_machine.svg')) drawStateMachine(job.id);
  showDownloads(job);
  showSpecification(outcome.ltl_specification);
  shownJob = job;
  offerSimulation(job);
}

function describeSuccess(job) {
  const goals = job.request.goals.join(', then ');
  const from = job.request.initial_conditions.join(', ') || 'nothing';
  return `from ${from}: ${goals}`;
}

function showSummary(summary, stages) {
  const realizable = { true: 'yes', false: 'no (unrealizable)', null: 'not checked' }[String(summary.realizable)];
  const rows = [['Realizable', realizable]];
  if (summary.formulas) {  // rows only for what this result has
    rows.push(['Propositions', `${summary.input_propositions + summary.output_propositions} ` +
      `(${summary.input_propositions} inputs, ${summary.output_propositions} outputs)`]);
    rows.push(['Formulas', summary.formulas]);
  }
  if (summary.automaton_states) rows.push(['Automaton states', summary.automaton_states]);
  if (summary.state_instantiations) {
    rows.push(['State machine states', `${summary.state_machine_states} ` +
      `(${summary.state_instantiations} StateInstantiation entries` +
      `${summary.concurrency_containers ? `, ${summary.concurrency_containers} concurrency containers` : ''})`]);
  }
  rows.push(['Total time', formatSeconds(summary.seconds)]);
  rows.push(...stages.map((stage) => [stage.stage, formatSeconds(stage.seconds), 'stage']));
  $('summary').replaceChildren(...rows.map(([name, value, className = '']) =>
    element('tr', { className }, element('th', { text: name }), element('td', { text: String(value) }))));
}

async function drawStateMachine(jobId) {
  const response = await fetch(`/api/jobs/${jobId}/artifacts/state_machine.svg?inline=1`);
  if (!response.ok) {
    const data = await response.json().catch(() => ({}));
    $('graph').replaceChildren(element('p', { className: 'bad', text: data.message || 'no picture' }));
    $('graph-section').hidden = false;
    return;
  }
  const svg = new DOMParser().parseFromString(await response.text(), 'image/svg+xml').documentElement;
  svg.removeAttribute('width');   // scale to the column; the viewBox keeps the proportions
  svg.removeAttribute('height');
  svg.setAttribute('id', 'state-machine-svg');
  $('graph').replaceChildren(document.importNode(svg, true));
  $('graph-section').hidden = false;
}

function showDownloads(job) {
  $('downloads').replaceChildren(...job.artifacts.map((name) => element('li', {},
    element('a', { href: `/api/jobs/${job.id}/artifacts/${name}`, download: '', 'data-artifact': name,
      text: DOWNLOAD_LABELS[name] || name }))));
  $('downloads-section').hidden = job.artifacts.length === 0;
}

function showSpecification(sections) {
  const names = Object.keys(SECTION_TITLES).filter((name) => (sections[name] || []).length);
  $('specification').replaceChildren(...names.map((name) => element('details', { 'data-section': name },
    element('summary', { text: `${SECTION_TITLES[name]} — ${sections[name].length}` }),
    element('pre', { text: sections[name].join('\n') }))));
  $('specification-section').hidden = names.length === 0;
}

// --- the simulation ----------------------------------------------------------------------

function offerSimulation(job) {
  if (!canSimulate || !job.artifacts.includes('state_machine.yaml')) return;
  const names = [...choices.actions, ...choices.control_modes].map((c) => c.name);
  $('fail-first').replaceChildren(element('option', { value: '', text: 'nothing (no faults)' }),
    ...names.map((name) => element('option', { value: name, text: name })));
  $('simulation-section').hidden = false;
}

function resetSimulation() {
  if (simulationEvents) simulationEvents.close();
  simulationEvents = null;
  $('simulate').disabled = false;
  $('simulation-status').textContent = '';
  $('simulation-view').hidden = true;
  $('simulation-steps').replaceChildren();
  $('simulation-frames').replaceChildren();
  $('simulation-check').textContent = '';
  $('simulation-timeline').hidden = true;
}

async function simulate() {
  if (!shownJob) return;
  resetSimulation();
  $('simulate').disabled = true;
  const failing = $('fail-first').value;
  let simulation;
  try {
    simulation = await api('POST', `/api/jobs/${shownJob.id}/simulations`, { fail_first: failing ? [failing] : [] });
  } catch (error) {
    $('simulation-status').textContent = `${error.code}: ${error.message}`;
    $('simulate').disabled = false;
    return;
  }
  showSimulation(simulation);
  simulationEvents = new EventSource(`/api/simulations/${simulation.id}/events`);
  simulationEvents.addEventListener('progress', (message) => showSimulation(JSON.parse(message.data)));
  simulationEvents.addEventListener('finished', (message) => {
    simulationEvents.close();
    simulationEvents = null;
    $('simulate').disabled = false;
    showSimulation(JSON.parse(message.data));
  });
}

function showSimulation(simulation) {
  const base = `/api/simulations/${simulation.id}`;
  let status = `Running: ${simulation.steps.length} states, robot time ${simulation.robot_time.toFixed(2)} s`;
  if (simulation.state === 'finished') {
    status = simulation.error
      ? `Stopped: ${simulation.error.code}: ${simulation.error.message}`
      : `Outcome: ${simulation.outcome} after ${simulation.steps.length} states ` +
        `(robot time ${simulation.robot_time.toFixed(2)} s, wall time ${simulation.wall_seconds.toFixed(2)} s)`;
  }
  $('simulation-status').textContent = status;
  $('simulation-status').className = `status ${simulation.error ? 'bad' : ''}`;
  $('simulation-view').hidden = false;
  $('simulation-steps').replaceChildren(
    element('tr', {}, ...['#', 'state', 'activated', 'results', 'outcome', 'robot time (s)'].map((h) => element('th', { text: h }))),
    ...simulation.steps.map((step) => element('tr', { 'data-state': step.state },
      element('td', { text: String(step.index) }),
      element('td', { text: step.state.replace(/^\//, '') }),
      element('td', { text: step.capabilities.join(', ') }),
      element('td', { text: step.results.map((r) => `${r.capability} ${r.outcome}`).join(', ') }),
      element('td', { text: step.state_outcome ? `${step.state_outcome} → ${step.transition}` : '…' }),
      element('td', { text: `${step.entered_at.toFixed(2)}–${step.ended_at.toFixed(2)}` }))));
  const frames = simulation.frames;
  if (frames.length) {
    const latest = frames[frames.length - 1];
    showFrame(`${base}/frames/${latest.index}`, latest.label);
    $('simulation-frames').replaceChildren(...frames.map((frame) => {
      const thumb = element('img', { src: `${base}/frames/${frame.index}`, alt: frame.label, title: frame.label });
      thumb.addEventListener('click', () => showFrame(thumb.src, frame.label));
      return thumb;
    }));
  }
  if (simulation.check) {
    const check = simulation.check;
    $('simulation-check').textContent = check.ok
      ? `Trace check against the specification: ok (${check.positions} positions)`
      : `Trace check: ${check.violations.length} violation(s): ` +
        check.violations.map((v) => v.message || JSON.stringify(v)).join('; ');
    $('simulation-check').className = check.ok ? 'good' : 'bad';
  }
  if (simulation.timeline) {
    $('simulation-timeline').src = `${base}/timeline.png`;
    $('simulation-timeline').hidden = false;
  }
}

function showFrame(src, label) {
  $('simulation-frame').src = src;
  // key frame files are named <index>_<sim time>s_<capability>_<event>
  const match = label.match(/^\d+_0*(\d+\.\d+)s_(.*)$/);
  $('simulation-frame-label').textContent = match ? `t = ${match[1]} s: ${match[2].replace(/_/g, ' ')}` : label;
}

function formatSeconds(seconds) {
  return seconds < 1 ? `${Math.round(seconds * 1000)} ms` : `${seconds.toFixed(2)} s`;
}

// --- start -------------------------------------------------------------------------------

document.addEventListener('DOMContentLoaded', () => {
  $('system').addEventListener('change', loadChoices);
  $('add-goal').addEventListener('click', addGoal);
  $('request-form').addEventListener('submit', synthesize);
  $('cancel').addEventListener('click', cancel);
  $('simulate').addEventListener('click', simulate);
  loadSystems().then(() => document.body.classList.add('ready'),
    (error) => { $('status').textContent = `Cannot load the systems: ${error.message}`; });
});
