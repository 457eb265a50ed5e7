// The request form: the system's own names to choose from, the ordered goal list with the
// server's live goal check, and the request it makes. It owns the chosen system's choices.
import { showAbstraction } from './abstraction.js';
import { api } from './api.js';
import { $, element } from './dom.js';
import { vocabulary } from './vocabulary.js';

let choices = null;      // the current system's control modes and actions (GET /api/systems/{system})
let canSimulate = false; // the server can run atlas_sim (GET /api/info)
let repairBudget = 0;    // seconds a "Suggest fixes" search may take (GET /api/info)
let goalChecks = 0;      // replies can overtake each other: only the newest check's is shown

export async function loadSystems() {
  const [{ systems }, info] = await Promise.all([api('GET', '/api/systems'), api('GET', '/api/info')]);
  $('backend-description').textContent = info.description || '';
  canSimulate = info.simulation;
  repairBudget = info.repair_time_budget || 0;
  const select = $('system');
  select.replaceChildren(...systems.map((name) => element('option', { value: name, text: name })));
  const preferred = vocabulary().preferred_system;
  if (systems.includes(preferred)) select.value = preferred;
  await loadChoices();
}

export async function loadChoices() {
  choices = await api('GET', `/api/systems/${encodeURIComponent($('system').value)}`);
  // What the robot may start from, as its view offers it: one control mode (radio buttons) and
  // completed actions, or a capability robot's memories and sensors (checkboxes); a group
  // with nothing to offer is not shown.
  const choice = (type, group, name, hint, checked) => {
    const box = element('input', { type, value: name, name: group });
    box.checked = checked;
    return element('label', { className: 'choice', title: hint }, box, ` ${name}`);
  };
  const defaults = new Set(choices.default_initial_conditions);
  const groupOf = (type) => choices.initial_groups.filter((g) => g.type === type && g.items.length).flatMap((g) => [
    element('span', { className: 'group-title', text: g.title }),
    ...g.items.map((item) => choice(type, type === 'radio' ? 'initial-mode' : 'initial-condition', item.name, item.hint,
      defaults.has(item.name)))]);
  $('initial-control-modes').replaceChildren(...groupOf('radio'));
  $('initial-actions').replaceChildren(...groupOf('checkbox'),
    ...(choices.initial_note ? [element('p', { className: 'muted', id: 'initial-note', text: choices.initial_note })] : []));
  $('initial-control-modes').hidden = !$('initial-control-modes').children.length;
  showSensors(choices.sensors);

  // The goals the robot can be asked for: its actions and modes, or what its capabilities make true.
  $('goal-choice').replaceChildren(...choices.goal_groups.filter((g) => g.items.length).map((g) => element('optgroup',
    { label: g.label }, ...g.items.map((item) => element('option', { value: item.name, title: item.hint, text: item.name })))));
  $('goals').replaceChildren();
  updateGoalsHint();
}

// The names a simulation can make fail: the system's actions then control modes, or its capabilities.
export function capabilityNames() {
  return choices.failure_names;
}

// The robot's sensors (a capability robot's spec INPUTs), each with the capabilities that report it.
export function sensors() {
  return choices.sensors;
}

function showSensors(list) {
  $('robot-sensors').hidden = !list.length;
  $('robot-sensor-list').replaceChildren(...list.map((sensor) => element('li', { 'data-sensor': sensor.name },
    element('code', { text: sensor.name }),
    ` reported by ${sensor.reported_by.join(', ') || 'no capability (the diagnosis says what to add)'}`)));
}

export function repairTimeBudget() {
  return repairBudget;
}

// Whether the simulated robot can run the chosen system's machines, and if not, why.
export function simulationSupport() {
  return choices.simulation || { available: canSimulate, note: '' };
}

// Ask the server which goals cannot come next (and which chosen goals can never be
// achieved) and say so in the picker and the list, before anything is synthesized.
export async function checkGoals() {
  const request = currentRequest();
  showAbstraction(choices, request);
  const number = ++goalChecks;
  let check;
  try {
    check = await api('POST', '/api/goal-check', { system: request.system, initial_conditions: request.initial_conditions,
      goals: request.goals, unordered: request.unordered });
  } catch (error) {
    // Too many checks at once (429, with Retry-After): ask again then, unless a newer check went out.
    if (error.status === 429 && number === goalChecks) {
      setTimeout(() => { if (number === goalChecks) checkGoals(); }, 1000 * (error.retryAfter || 1));
    }
    return;  // otherwise the synthesis itself will report what is wrong
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
  revealFlaggedGoal();
}

// A goal flagged red stays in view above the form's controls, also as they grow (the job's
// timeline) or the result's banner comes.
export function revealFlaggedGoal() {
  const flagged = $('goals').querySelector('li.impossible');
  if (flagged) revealInForm(flagged);
}
new ResizeObserver(revealFlaggedGoal).observe($('request-form').querySelector('section.controls'));

// Scroll the page so that ``item`` (a goal) is in view above the form's controls, which stay at
// the window's bottom (the form has no scroll of its own).
function revealInForm(item) {
  const box = item.getBoundingClientRect();
  const floor = Math.min(window.innerHeight, $('request-form').querySelector('section.controls').getBoundingClientRect().top);
  if (box.bottom > floor - 8) window.scrollBy({ top: box.bottom - floor + 8, behavior: 'instant' });
  else if (box.top < 8) window.scrollBy({ top: box.top - 8, behavior: 'instant' });
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

export function addGoal() {
  const name = $('goal-choice').value;
  if (!name) return;
  const goals = [...$('goals').children].map((goal) => goal.dataset.goal);
  if (goals.includes(name)) {  // one memory proposition per goal: the same goal twice cannot be asked
    $('form-problem').textContent = duplicateGoal(name, goals);
    $('goal-choice').focus();
    return;
  }
  $('form-problem').textContent = '';
  const item = goalItem(name);
  $('goals').append(item);
  revealInForm(item);
  updateGoalsHint();
}

function updateGoalsHint() {
  $('goals-empty').hidden = $('goals').children.length > 0;
  checkGoals();
}

export function currentRequest() {
  const checked = (selector) => document.querySelector(selector).value;
  const custom = customLtl();
  return {
    ...(custom.value ? { custom_ltl: custom.value } : {}),
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

// What the form can tell before asking the server: no goals (every option the page offers
// needs them), a behavior name it would refuse.
export function requestProblem(request) {
  if (!request.goals.length) {
    return { field: 'goal-choice', message: 'Add at least one goal: pick it in the list and press “Add goal”.' };
  }
  const repeated = request.goals.find((goal, index) => request.goals.indexOf(goal) !== index);
  if (repeated) return { field: 'goal-choice', message: duplicateGoal(repeated, request.goals) };
  const custom = customLtl();
  $('custom-ltl-problem').textContent = custom.problem;
  if (custom.problem) {
    $('custom-ltl-box').open = true;
    return { field: 'custom-ltl', message: `Custom LTL: ${custom.problem}` };
  }
  const name = $('behavior-name');
  if (!name.checkValidity()) {
    return { field: 'behavior-name', message: `Behavior name “${name.value}”: ${$('behavior-name-hint').textContent.trim()}` };
  }
  return null;
}

function duplicateGoal(name, goals) {
  return `“${name}” is already goal ${goals.indexOf(name) + 1}: each goal can be asked once ` +
    '(remove it there to move it, or reorder with ↑ ↓).';
}

// The custom LTL field: empty, or a JSON object of sections to lists of formulas (the server
// checks the sections and the compiler the formulas).
function customLtl() {
  const text = $('custom-ltl').value.trim();
  if (!text) return { value: null, problem: '' };
  let value;
  try {
    value = JSON.parse(text);
  } catch (error) {
    return { value: null, problem: `not JSON (${error.message})` };
  }
  if (value === null || typeof value !== 'object' || Array.isArray(value)) {
    return { value: null, problem: 'write a JSON object of sections to lists of formulas, as in the example above' };
  }
  return { value: Object.keys(value).length ? value : null, problem: '' };
}

// Fill the form with ``request`` (a suggested fix): its initial conditions, goals, outcomes,
// order and custom LTL; the system, stop-after option and behavior name stay as they are.
export async function fillForm(request) {
  if ($('system').value !== request.system) {
    $('system').value = request.system;
    await loadChoices();
  }
  const chosen = new Set(request.initial_conditions);
  for (const box of document.querySelectorAll('input[name="initial-mode"], input[name="initial-condition"]')) {
    box.checked = chosen.has(box.value);
  }
  $('goals').replaceChildren(...request.goals.map(goalItem));
  const outcomes = document.querySelector(`input[name="sm-outcomes"][value="${request.sm_outcomes.join(',')}"]`);
  if (outcomes) outcomes.checked = true;
  $('unordered').checked = Boolean(request.unordered);
  $('custom-ltl').value = request.custom_ltl ? JSON.stringify(request.custom_ltl) : '';
  $('custom-ltl-box').open = Boolean(request.custom_ltl);
  updateGoalsHint();
}
