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

let currentJob = null;   // id of the job being followed
let events = null;       // its EventSource
let shownProgress = { id: null, revision: -1 };  // newest job snapshot shown: replies can overtake
let shownJob = null;     // the job whose result is on the page
let choices = null;      // the current system's control modes and actions
let canSimulate = false; // the server can run atlas_sim
let simulationEvents = null;
let startedAt = 0;         // performance.now() when the followed job was started
let elapsedTimer = null;

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
  // The server takes POSTs only as JSON (what no cross-site form can send): a POST without
  // a body sends {}.
  if (body === undefined && method === 'POST') body = {};
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
  // The robot starts in one control mode (radio buttons); any actions may be completed already.
  const choice = (type, group, name, hint, checked) => {
    const box = element('input', { type, value: name, name: group });
    box.checked = checked;
    return element('label', { className: 'choice', title: hint }, box, ` ${name}`);
  };
  const defaults = new Set(choices.default_initial_conditions);
  $('initial-control-modes').replaceChildren(
    element('span', { className: 'group-title', text: 'Control mode (one)' }),
    ...choices.control_modes.map((m) => choice('radio', 'initial-mode', m.name, `next: ${m.next.join(', ') || '—'}`,
      defaults.has(m.name))));
  $('initial-actions').replaceChildren(
    element('span', { className: 'group-title', text: 'Actions (already completed)' }),
    ...choices.actions.map((a) => choice('checkbox', 'initial-condition', a.name,
      `needs: ${a.preconditions.join(', ') || 'nothing'}`, defaults.has(a.name))));

  const group = (label, items, hint) => element('optgroup', { label },
    ...items.map((item) => element('option', { value: item.name, title: hint(item), text: item.name })));
  $('goal-choice').replaceChildren(
    group('Actions', choices.actions, (a) => `needs: ${a.preconditions.join(', ') || 'nothing'}`),
    group('Control modes', choices.control_modes, (m) => `reached from: ${predecessors(m.name).join(', ') || 'no other mode'}`));
  $('goals').replaceChildren();
  updateGoalsHint();
}

// Ask the server which goals cannot come next (and which chosen goals can never be
// achieved) and say so in the picker and the list, before anything is synthesized.
let goalChecks = 0;  // replies can overtake each other: only the newest check's is shown
async function checkGoals() {
  const request = currentRequest();
  const number = ++goalChecks;
  let check;
  try {
    check = await api('POST', '/api/goal-check', { system: request.system, initial_conditions: request.initial_conditions,
      goals: request.goals, unordered: request.unordered });
  } catch (error) {
    return;  // the synthesis itself will report what is wrong
  }
  if (number !== goalChecks) return;
  for (const option of $('goal-choice').options) {
    const why = check.impossible_next[option.value];
    option.textContent = why ? `${option.value} (impossible here)` : option.value;
    option.classList.toggle('impossible', Boolean(why));
    option.dataset.impossible = why || '';
    if (why) option.title = why;
  }
  for (const item of $('goals').children) {
    const finding = check.findings.find((f) => f.item === item.dataset.goal);
    item.classList.toggle('impossible', Boolean(finding));
    item.querySelector('.goal-warning').textContent = finding ? finding.sentence : '';
  }
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
    button('↑', 'move up', () => { if (item.previousElementSibling) item.previousElementSibling.before(item); updateGoalsHint(); }),
    button('↓', 'move down', () => { if (item.nextElementSibling) item.nextElementSibling.after(item); updateGoalsHint(); }),
    button('×', 'remove', () => { item.remove(); updateGoalsHint(); }),
    element('span', { className: 'goal-warning', role: 'note' }));
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
  checkGoals();
}

function currentRequest() {
  const checked = (selector) => document.querySelector(selector).value;
  return {
    system: $('system').value,
    initial_conditions: [...document.querySelectorAll('input[name="initial-mode"]:checked, input[name="initial-condition"]:checked')]
      .map((b) => b.value),
    goals: [...$('goals').children].map((item) => item.dataset.goal),
    sm_outcomes: checked('input[name="sm-outcomes"]:checked').split(','),
    option: checked('input[name="option"]:checked') || null,
    unordered: $('unordered').checked,
    name: $('behavior-name').value.trim(),
  };
}

// --- running a job -----------------------------------------------------------------------

// What the form can tell before asking the server: no goals, a behavior name it would refuse.
function requestProblem(request) {
  if (!request.goals.length && request.option !== 'ltl_synthesis_only') {
    return { field: 'goal-choice', message: 'Add at least one goal: pick it in the list and press “Add goal”.' };
  }
  const name = $('behavior-name');
  if (!name.checkValidity()) {
    return { field: 'behavior-name', message: `Behavior name “${name.value}”: ${$('behavior-name-hint').textContent.trim()}` };
  }
  return null;
}

async function synthesize(event) {
  event.preventDefault();
  const request = currentRequest();
  const problem = requestProblem(request);
  $('form-problem').textContent = problem ? problem.message : '';
  $('behavior-name-hint').classList.toggle('bad', problem !== null && problem.field === 'behavior-name');
  if (problem) {
    $('status').textContent = 'Not sent: see the note above.';
    $(problem.field).focus();
    return;
  }
  stopFollowing();
  resetResult();
  let job;
  try {
    job = await api('POST', '/api/jobs', request);
  } catch (error) {
    showRequestError(error);
    return;
  }
  currentJob = job.id;
  startedAt = performance.now();
  setRunning(true);
  showProgress(job);
  follow(job.id);
}

// Follow a job's events. When the stream breaks, say so and keep asking until the server
// answers: then either resume (same server) or explain that a restart lost the job.
function follow(jobId) {
  events = streamEvents(`/api/jobs/${jobId}/events`, {
    progress: (job) => { setConnection(''); showProgress(job); },
    finished: (job) => { stopFollowing(); setConnection(''); finish(job); },
    broken: () => { stopFollowing(); reconnect(jobId, 1); },
  });
}

async function reconnect(jobId, attempt) {
  if (currentJob !== jobId) return;
  setConnection(`Connection to the server lost — reconnecting (attempt ${attempt})…`);
  let job;
  try {
    job = await api('GET', `/api/jobs/${jobId}`);
  } catch (error) {
    if (error.code === 'NOT_FOUND') {
      setConnection('');
      currentJob = null;
      setRunning(false);
      $('status').textContent = 'The server restarted, so this job was lost — run it again.';
      showBanner('CONNECTION LOST', 'The server restarted, so this job was lost — run it again.', null);
      return;
    }
    setTimeout(() => reconnect(jobId, attempt + 1), 1000);
    return;
  }
  setConnection('Connected again.');
  if (job.state === 'finished') finish(job);
  else follow(jobId);
}

function setConnection(text) {
  $('connection').textContent = text;
  $('connection').hidden = !text;
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
  clearInterval(elapsedTimer);
  if (running) {
    $('progress').removeAttribute('value');  // indeterminate: no stage knows how long it takes
    elapsedTimer = setInterval(showElapsed, 200);
    showElapsed();
  }
}

function showElapsed() {
  $('elapsed').textContent = `${((performance.now() - startedAt) / 1000).toFixed(1)} s`;
}

function showProgress(job) {
  if (job.id === shownProgress.id && job.revision < shownProgress.revision) return;
  shownProgress = { id: job.id, revision: job.revision };
  if (job.state === 'finished') $('progress').value = job.progress;
  $('status').textContent = job.state === 'finished' ? resultWord(job.status) : job.status;
  $('timeline').replaceChildren(...job.timeline.map((entry) => element('li', {},
    element('span', { className: 'time', text: formatSeconds(entry.seconds) }),
    element('span', { text: entry.status }))));
}

function finish(job) {
  setRunning(false);
  showProgress(job);
  if (job.state !== 'finished') return;
  $('elapsed').textContent = formatSeconds(job.summary.seconds);
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
  StateMachineView.clear();
  $('timeline').replaceChildren();
  $('progress').value = 0;
}

// A message's first line is its plain sentence; the rest (e.g. the unrealizable core and the
// synthesizer's own account) goes into a collapsed "Details".
function showBanner(code, message, good) {
  $('result').hidden = false;
  $('result-banner').className = `banner ${good === null ? 'neutral' : good ? 'good' : 'bad'}`;
  $('result-code').textContent = code;
  const [sentence, ...rest] = (message || '').split('\n');
  $('result-message').textContent = sentence;
  const details = rest.join('\n').trim();
  $('result-details').hidden = !details;
  $('result-details-text').textContent = details;
  const top = $('result-banner').getBoundingClientRect().top;
  if (top < 0 || top > window.innerHeight) $('result-banner').scrollIntoView({ block: 'start' });
  $('result-banner').focus({ preventScroll: true });  // keyboard and screen-reader users land on the result
}

// One word per outcome everywhere on the page: a cancelled job is "CANCELLED" (ROS says PREEMPTED).
function resultWord(errorName) {
  return errorName === 'PREEMPTED' ? 'CANCELLED' : errorName;
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
  const cancelled = outcome.error_name === 'PREEMPTED';
  showBanner(resultWord(outcome.error_name), message, cancelled ? null : summary.succeeded);
  showSummary(summary, job.stages);
  if (job.artifacts.includes('state_machine.svg')) drawStateMachine(job);
  showDownloads(job);
  showSpecification(outcome.ltl_specification);
  shownJob = job;
  offerSimulation(job);
}

function describeSuccess(job) {
  const goals = job.request.unordered ? `${job.request.goals.join(', ')} (in any order)` : job.request.goals.join(', then ');
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

async function drawStateMachine(job) {
  const response = await fetch(`/api/jobs/${job.id}/artifacts/state_machine.svg?inline=1`);
  $('graph-section').hidden = false;
  if (!response.ok) {
    const data = await response.json().catch(() => ({}));
    $('graph').replaceChildren(element('p', { className: 'bad', text: data.message || 'no picture' }));
    return;
  }
  StateMachineView.show($('graph'), await response.text(), job.outcome.states, showStateDetails);
  showStateDetails(null);
}

// What FlexBE's editor shows for a state: class, parameters, userdata, outcomes, autonomy.
function showStateDetails(state, children = []) {
  const panel = $('state-details');
  if (!state) {
    panel.replaceChildren(element('p', { className: 'muted', text: 'Click a state to see its class, parameters, userdata, outcomes and autonomy.' }));
    return;
  }
  const row = (name, ...values) => element('tr', {}, element('th', { text: name }), element('td', {}, ...values));
  const className = state.state_class === ':BEHAVIOR' ? `${state.behavior_class} (behavior)`
    : state.state_class === ':CONCURRENCY' ? 'concurrency container' : state.state_class;
  const parameters = state.parameter_names.map((n, i) => `${n} = ${state.parameter_values[i]}`);
  const userdata = state.userdata_keys.map((k, i) => `${k} ← ${state.userdata_remapping[i] || k}`);
  const outcomes = state.outcomes.map((o, i) => element('li', { text: `${o} → ${state.transitions[i]}` +
    (state.autonomy.length ? ` (autonomy ${AUTONOMY[state.autonomy[i]] ?? state.autonomy[i]})` : '') }));
  panel.replaceChildren(
    element('h3', { text: state.state_path.replace(/^\//, '') }),
    element('table', { className: 'details' },
      row('Class', className),
      row('Parameters', parameters.join(', ') || '—'),
      row('Userdata', userdata.join(', ') || '—'),
      row('Outcomes', element('ul', {}, ...outcomes)),
      ...(children.length ? [row('Contains', children.map((c) => `${c.state_path.split('/').pop()} (${c.state_class})`).join(', '))] : [])));
}

const AUTONOMY = { 0: 'Off', 1: 'Low', 2: 'High', 3: 'Full' };

function showDownloads(job) {
  const exportable = job.artifacts.includes('flexbe_behavior.zip');
  $('export-flexbe-offer').hidden = !exportable;  // the button and its caption, or neither
  if (exportable) $('export-flexbe').href = `/api/jobs/${job.id}/artifacts/flexbe_behavior.zip`;
  const listed = job.artifacts.filter((name) => name !== 'flexbe_behavior.zip');  // offered once, above
  $('downloads').replaceChildren(...listed.map((name) => element('li', {},
    element('a', { href: `/api/jobs/${job.id}/artifacts/${name}`, download: '', 'data-artifact': name,
      text: job.download_labels[name] || name }))));
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
  if (!job.artifacts.includes('state_machine.yaml')) return;
  const support = choices.simulation || { available: canSimulate, note: '' };
  $('simulation-note').textContent = support.note;
  $('simulation-note').hidden = support.available;
  $('simulation-controls').hidden = !support.available;
  if (!support.available) {
    $('simulation-section').hidden = false;
    return;
  }
  const names = [...choices.actions, ...choices.control_modes].map((c) => c.name);
  $('fail-first').replaceChildren(element('option', { value: '', text: 'nothing (no faults)' }),
    ...names.map((name) => element('option', { value: name, text: name })));
  $('simulation-section').hidden = false;
}

function resetSimulation() {
  if (simulationEvents) simulationEvents.close();
  simulationEvents = null;
  stopPlaying();
  $('simulate').disabled = false;
  $('simulation-status').textContent = '';
  $('simulation-live').textContent = '';
  $('simulation-view').hidden = true;
  $('robot-view').hidden = true;
  $('graph-layout').classList.remove('simulating');
  $('simulation-steps').replaceChildren();
  $('simulation-frames').replaceChildren();
  frameList = [];
  $('frame-scrubber').value = '0';
  $('frame-scrubber').max = '0';
  StateMachineView.markRun([], false);
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
  // Follow the robot: the drawing and the robot side by side, in view.
  $('graph-section').scrollIntoView({ block: 'start', behavior: 'instant' });
  const end = () => {
    simulationEvents = null;
    $('simulate').disabled = false;
  };
  simulationEvents = streamEvents(`/api/simulations/${simulation.id}/events`, {
    progress: showSimulation,
    finished: (last) => { end(); showSimulation(last); },
    // The stream broke (e.g. the server restarted): show what the server still knows, once.
    broken: () => api('GET', `/api/simulations/${simulation.id}`).then(
      (last) => { end(); showSimulation(last); },
      (error) => { end(); $('simulation-status').textContent = `${error.code}: ${error.message}`; }),
  });
}

// The one reader of the server-sent events of jobs and simulations: `progress` with each
// snapshot, `finished` with the last one, `broken` when the stream fails. Returns the EventSource.
function streamEvents(url, handlers) {
  const source = new EventSource(url);
  source.addEventListener('progress', (message) => handlers.progress(JSON.parse(message.data)));
  source.addEventListener('finished', (message) => {
    source.close();
    handlers.finished(JSON.parse(message.data));
  });
  source.onerror = () => {
    source.close();
    handlers.broken();
  };
  return source;
}

function showSimulation(simulation) {
  const base = `/api/simulations/${simulation.id}`;
  const running = simulation.state !== 'finished';
  let status = simulation.steps.length === 0 ? 'Starting the simulator…'
    : `Running: ${simulation.steps.length} states, robot time ${simulation.robot_time.toFixed(2)} s`;
  let outcomeClass = '';
  if (!running) {
    status = simulation.error
      ? `Stopped: ${simulation.error.code}: ${simulation.error.message}`
      : `Outcome: ${simulation.outcome} after ${simulation.steps.length} states ` +
        `(robot time ${simulation.robot_time.toFixed(2)} s, wall time ${simulation.wall_seconds.toFixed(2)} s)`;
    outcomeClass = simulation.error ? 'bad' : `outcome-${simulation.outcome}`;
  }
  $('simulation-status').textContent = status;
  $('simulation-status').className = `status ${outcomeClass}`;
  $('simulation-live').textContent = status;
  $('simulation-live').className = `status ${outcomeClass}`;
  $('simulation-view').hidden = false;
  $('robot-view').hidden = false;
  if (!$('graph-layout').classList.contains('simulating')) {
    $('graph-layout').classList.add('simulating');
    StateMachineView.fit();  // the drawing just got narrower
  }
  const outcomeCell = (step) => {
    if (!step.state_outcome) return element('td', { text: '…' });
    const ends = ['finished', 'failed'].includes(step.transition) ? ` outcome-${step.transition}` : '';
    return element('td', { className: `outcome${ends}`, text: `${step.state_outcome} → ${step.transition}` });
  };
  $('simulation-steps').replaceChildren(
    element('tr', {}, ...['#', 'state', 'activated', 'results', 'outcome', 'robot time (s)'].map((h) => element('th', { text: h }))),
    ...simulation.steps.map((step) => element('tr', { 'data-state': step.state },
      element('td', { text: String(step.index) }),
      element('td', { text: step.state.replace(/^\//, '') }),
      element('td', { text: step.capabilities.join(', ') }),
      element('td', { text: step.results.map((r) => `${r.capability} ${r.outcome}`).join(', ') }),
      outcomeCell(step),
      element('td', { text: `${step.entered_at.toFixed(2)}–${step.ended_at.toFixed(2)}` }))));
  StateMachineView.markRun(simulation.steps, running);
  showFrames(base, simulation.frames);
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

// Key frames: the latest one large with a caption, a scrubber over all of them, and
// captioned thumbnails.
let frameList = [];
let player = null;  // the timer of the frame player
function showFrames(base, frames) {
  if (!frames.length) return;
  const followLatest = Number($('frame-scrubber').value) >= frameList.length - 1;
  frameList = frames.map((frame) => ({ src: `${base}/frames/${frame.index}`, caption: frameCaption(frame.label),
    time: frameTime(frame.label) }));
  $('frame-scrubber').max = String(frames.length - 1);
  $('simulation-frames').replaceChildren(...frameList.map((frame, index) => {
    const figure = element('figure', { 'data-frame': String(index) },
      element('img', { src: frame.src, alt: frame.caption }), element('figcaption', { text: frame.caption }));
    figure.addEventListener('click', () => showFrame(index));
    return figure;
  }));
  if (!player) showFrame(followLatest ? frames.length - 1 : Number($('frame-scrubber').value));
}

// Play the key frames as the run went: each stays up for the robot time until the next one.
function playFrames() {
  if (player) { stopPlaying(); return; }
  if (!frameList.length) return;
  $('play-frames').textContent = '❚❚ Pause';
  let index = Number($('frame-scrubber').value) >= frameList.length - 1 ? 0 : Number($('frame-scrubber').value);
  const next = () => {
    showFrame(index);
    if (index >= frameList.length - 1) { stopPlaying(); return; }
    const gap = frameList[index + 1].time - frameList[index].time;  // robot seconds (NaN: no time in the name)
    const wait = Number.isFinite(gap) ? Math.max(0.05, gap) : 0.5;
    index += 1;
    player = setTimeout(next, wait * 1000);
  };
  player = -1;
  next();
}

function stopPlaying() {
  if (player) clearTimeout(player);
  player = null;
  $('play-frames').textContent = '▶ Play';
}

function showFrame(index) {
  const frame = frameList[index];
  if (!frame) return;
  $('frame-scrubber').value = String(index);
  $('simulation-frame').src = frame.src;
  $('simulation-frame').alt = frame.caption;
  $('simulation-frame-label').textContent = `Frame ${index + 1} of ${frameList.length}: ${frame.caption}`;
  document.querySelectorAll('#simulation-frames figure').forEach((f) =>
    f.classList.toggle('current', f.dataset.frame === String(index)));
}

// key frame files are named <index>_<sim time>s_<capability>_<event>
function frameTime(label) {
  const match = label.match(/^\d+_0*(\d+\.\d+)s_/);
  return match ? Number(match[1]) : NaN;
}

function frameCaption(label) {
  const match = label.match(/^\d+_0*(\d+\.\d+)s_(.*)$/);
  return match ? `t = ${match[1]} s: ${match[2].replace(/_/g, ' ')}` : label.replace(/_/g, ' ');
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
  $('frame-scrubber').addEventListener('input', (event) => { stopPlaying(); showFrame(Number(event.target.value)); });
  $('play-frames').addEventListener('click', playFrames);
  $('behavior-name').addEventListener('input', () => $('behavior-name-hint').classList.remove('bad'));
  $('initial-conditions').addEventListener('change', checkGoals);
  $('unordered').addEventListener('change', checkGoals);
  loadSystems().then(() => document.body.classList.add('ready'),
    (error) => { $('status').textContent = `Cannot load the systems: ${error.message}`; });
});
