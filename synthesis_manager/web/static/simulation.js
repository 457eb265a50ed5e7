// The closed-loop simulation of a finished job's machine on atlas_sim: offer it, run it,
// follow its steps on the drawing and in a table, show its key frames and trace check.
import { api, streamEvents } from './api.js';
import * as drawing from './drawing.js';
import { $, element } from './dom.js';
import { capabilityNames, sensors, simulationSupport } from './form.js';
import { resetFrames, showFrames } from './frames.js';
import { command, controlRun, startingAutonomy } from './runtime_control.js';
import { vocabulary } from './vocabulary.js';

let offeredJob = null;        // the job whose machine the Simulate button runs
let simulationEvents = null;  // the EventSource of the run being followed

export function offerSimulation(job) {
  offeredJob = job;
  if (!job.artifacts.includes('state_machine.yaml')) return;
  const support = simulationSupport();
  $('simulation-note').textContent = support.note;
  $('simulation-note').hidden = support.available;
  if (support.simulator) $('simulator-name').textContent = `(${support.simulator})`;
  if (support.faults) document.querySelector('label[for="fail-first"]').title = support.faults;
  $('simulation-controls').hidden = !support.available;
  if (!support.available) {
    $('simulation-section').hidden = false;
    return;
  }
  $('fail-first').replaceChildren(element('option', { value: '', text: 'nothing (no faults)' }),
    ...capabilityNames().map((name) => element('option', { value: name, text: name })));
  // A capability robot's sensors: free (the environment reads what the assumptions allow), or
  // held true or false for the whole run.
  $('simulation-sensors').replaceChildren(...sensors().map((sensor) => {
    const id = `simulation-sensor-${sensor.name}`;
    return element('span', { className: 'inline' },
      element('label', { for: id, className: 'inline-label', text: sensor.name,
        title: `a sensor, reported by ${sensor.reported_by.join(', ') || 'no capability'}` }),
      element('select', { id, name: 'simulation-sensor', 'data-sensor': sensor.name },
        element('option', { value: '', text: 'as the environment reads it' }),
        element('option', { value: 'true', text: 'true' }), element('option', { value: 'false', text: 'false' })));
  }));
  $('simulation-sensors').hidden = !sensors().length;
  // During a run a change holds from the state's next answer on (Runtime Control's sensor command).
  for (const select of $('simulation-sensors').querySelectorAll('select')) {
    select.addEventListener('change', () => command({ command: 'sensor', name: select.dataset.sensor,
      value: select.value ? select.value === 'true' : null }));
  }
  $('simulation-section').hidden = false;
}

// A new job is on its way: no run of the old one stays on the page.
export function withdrawSimulation() {
  offeredJob = null;
  $('simulation-controls').hidden = true;
  resetSimulation();
}

function resetSimulation() {
  if (simulationEvents) simulationEvents.close();
  simulationEvents = null;
  $('simulate').disabled = false;
  $('simulation-status').textContent = '';
  $('simulation-live').textContent = '';
  $('simulation-view').hidden = true;
  $('robot-view').hidden = true;
  $('graph-layout').classList.remove('simulating');
  $('simulation-steps').replaceChildren();
  resetFrames();
  drawing.markRun([], false);
  $('simulation-check').textContent = '';
  $('simulation-timeline').hidden = true;
}

export async function simulate() {
  if (!offeredJob) return;
  resetSimulation();
  $('simulate').disabled = true;
  const failing = $('fail-first').value;
  let simulation;
  try {
    simulation = await api('POST', `/api/jobs/${offeredJob.id}/simulations`,
      { fail_first: failing ? [failing] : [], autonomy: startingAutonomy(), ...simulationSensors() });
  } catch (error) {
    $('simulation-status').textContent = `${error.code}: ${error.message}`;
    $('simulate').disabled = false;
    return;
  }
  showSimulation(simulation);
  // Follow the robot: the drawing and the robot side by side, in view; the keys (1-9 force an
  // outcome, + and - zoom) go to the drawing, not to the page's body (Simulate is disabled now).
  drawing.scrollIntoView();
  drawing.refit();
  drawing.focusDrawing();
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

// The sensors the operator set for the run (a capability robot's), if it has any.
function simulationSensors() {
  const held = [...document.querySelectorAll('select[name="simulation-sensor"]')].filter((s) => s.value);
  return held.length ? { sensors: Object.fromEntries(held.map((s) => [s.dataset.sensor, s.value === 'true'])) } : {};
}

// When a step ran in robot time: a step that has not ended runs on ("1.50–…") or, once the
// run stopped in it, ended when the run did.
function stepTimes(step, simulation, running) {
  const ended = Boolean(step.state_outcome) || step.ended_at > step.entered_at;
  // The run's robot time is reported with its frames, so it may lag the step's entry by a frame.
  const stopped = Math.max(step.entered_at, simulation.robot_time);
  const end = ended ? step.ended_at.toFixed(2) : running ? '…' : `${stopped.toFixed(2)} (stopped)`;
  return `${step.entered_at.toFixed(2)}–${end}`;
}

function showSimulation(simulation) {
  const base = `/api/simulations/${simulation.id}`;
  const running = simulation.state !== 'finished';
  const waiting = simulation.operator && simulation.operator.waiting;
  // A robot simulated without physics (a capability robot) has neither frames nor robot time.
  const physics = simulationSupport().frames;
  const robotTime = physics ? `, robot time ${simulation.robot_time.toFixed(2)} s` : '';
  let status = simulation.steps.length === 0 ? 'Starting the simulator…'
    : `Running: ${simulation.steps.length} states${robotTime}`;
  if (running && waiting) status += waiting.kind === 'resume' ? ' (paused)' : ' (waiting for you)';
  let outcomeClass = '';
  if (!running) {
    status = simulation.error
      ? `Stopped: ${simulation.error.code}: ${simulation.error.message}`
      : `Outcome: ${simulation.outcome} after ${simulation.steps.length} states (` +
        `${physics ? `robot time ${simulation.robot_time.toFixed(2)} s, ` : ''}wall time ${simulation.wall_seconds.toFixed(2)} s)`;
    outcomeClass = simulation.error ? 'bad' : `outcome-${simulation.outcome}`;
  }
  $('simulation-status').textContent = status;
  $('simulation-status').className = `status ${outcomeClass}`;
  $('simulation-live').textContent = status;
  $('simulation-live').className = `status ${outcomeClass}`;
  $('simulation-view').hidden = false;
  $('robot-view').hidden = false;
  $('robot-view').classList.toggle('no-frames', !physics);
  if (!$('graph-layout').classList.contains('simulating')) {
    $('graph-layout').classList.add('simulating');
    drawing.foldForm(true);  // the drawing just got narrower: give it the form's width
  }
  const machineOutcomes = Object.values(vocabulary().sm_outcomes);
  const outcomeCell = (step) => {
    if (!step.state_outcome) return element('td', { text: '…' });
    const ends = machineOutcomes.includes(step.transition) ? ` outcome-${step.transition}` : '';
    return element('td', { className: `outcome${ends}`, text: `${step.state_outcome} → ${step.transition}` });
  };
  $('simulation-steps').replaceChildren(
    element('tr', {}, ...['#', 'state', 'activated', 'results', 'outcome', 'robot time (s)'].map((h) => element('th', { text: h }))),
    ...simulation.steps.map((step) => element('tr', { 'data-state': step.state },
      element('td', { text: String(step.index) }),
      element('td', { text: step.state.replace(/^\//, '') }),
      element('td', { text: step.capabilities.join(', ') }),
      element('td', { text: step.results.map((r) => `${r.capability} ${r.outcome}`).join(', ') +
        (step.chosen_by && step.state_outcome ? ` (chosen by ${step.chosen_by})` : '') }),
      outcomeCell(step),
      element('td', { text: physics ? stepTimes(step, simulation, running) : '—' }))));
  drawing.markRun(simulation.steps, running);
  controlRun(simulation);
  showFrames(base, simulation.frames, simulation.steps, running);
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
