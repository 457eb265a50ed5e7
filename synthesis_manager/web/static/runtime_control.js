// The operator's side of a simulation run, as FlexBE's Runtime Control: the autonomy level,
// pause / resume / stop, confirming a transition that waits (highlighted on the drawing),
// forcing any outcome of the active state by clicking its outcome cell, and answering an
// InputState with the system's default offered. Commands go to POST /api/simulations/{id}/control;
// what the run waits for comes back in the run's events (simulation.operator).
import { api } from './api.js';
import * as drawing from './drawing.js';
import { $, element } from './dom.js';
import { vocabulary } from './vocabulary.js';

let run = null;       // {id, operator, active} of the run being controlled (null: none running)
let picking = false;  // the drawing's outcome cells force this run's outcomes

// Send ``body`` to the run being controlled (nothing when none runs).
export function command(body) {
  if (!run) return Promise.resolve();
  return api('POST', `/api/simulations/${run.id}/control`, body).catch((error) => {
    $('operator-question').textContent = `${error.code}: ${error.message}`;
  });
}

// The autonomy level the run starts at (the selector beside Simulate).
export function startingAutonomy() { return Number($('autonomy').value); }

// Follow a run's update: controls shown while it runs, what it waits for asked in the page.
export function controlRun(simulation) {
  const live = simulation.state !== 'finished';
  const operator = simulation.operator || {};
  const steps = simulation.steps;
  run = live ? { id: simulation.id, operator, active: steps.length ? steps[steps.length - 1].state : null } : null;
  $('runtime-control').hidden = !live;
  if (operator.autonomy !== undefined && document.activeElement !== $('autonomy')) {
    $('autonomy').value = String(operator.autonomy);
  }
  $('pause-run').textContent = operator.paused ? '▶ Resume' : '❚❚ Pause';
  $('pause-run').setAttribute('aria-pressed', String(Boolean(operator.paused)));
  const waiting = live ? operator.waiting : null;
  ask(waiting);
  // The cells are this run's while it goes on, unless a play of the machine has them.
  const mine = live && $('play-panel').hidden;
  if (mine || picking) drawing.pickOutcomes(mine ? forceFromDrawing : null);
  picking = mine;
  drawing.markPending(waiting && waiting.kind === 'confirm' ? waiting : null);
  offerOutcomes(mine ? run.active : null);
}

// The active state's outcomes as numbered buttons (keys 1-9), as Play lists them.
function offerOutcomes(active) {
  const outcomes = active ? drawing.outcomesOf(active) : [];
  const box = $('operator-outcomes');
  box.hidden = outcomes.length === 0;
  const key = `${active}:${outcomes.join(',')}`;
  if (box.dataset.offered === key) return;
  box.dataset.offered = key;
  $('operator-outcome-buttons').replaceChildren(...outcomes.map((outcome, index) => {
    const button = element('button', { type: 'button', className: 'small operator-outcome', 'data-outcome': outcome,
      text: index < 9 ? `${index + 1} ${outcome}` : outcome });
    button.addEventListener('click', () => forceFromDrawing([outcome]));
    return button;
  }));
}

// Keys 1-9 during a run force the active state's outcomes, in the order its buttons list them.
export function runKeys(event) {
  if (!run || !run.active || !$('play-panel').hidden || !/^[1-9]$/.test(event.key)) return;
  if (event.target.closest && event.target.closest('textarea, input, select')) return;
  const outcome = drawing.outcomesOf(run.active)[Number(event.key) - 1];
  if (!outcome) return;
  event.preventDefault();
  forceFromDrawing([outcome]);
}

function ask(waiting) {
  const request = $('operator-request');
  const asking = waiting && waiting.kind !== 'resume';
  if (!asking) {
    request.hidden = true;
    request.dataset.asked = '';
    return;
  }
  const key = JSON.stringify(waiting);
  if (request.dataset.asked === key) return;  // the same question: keep what the user typed
  request.dataset.asked = key;
  request.hidden = false;
  const state = waiting.state.replace(/^\//, '');
  $('operator-confirm-row').hidden = waiting.kind !== 'confirm';
  $('operator-input-form').hidden = waiting.kind !== 'input';
  if (waiting.kind === 'confirm') {
    const level = vocabulary().autonomy_levels[waiting.required] || String(waiting.required);
    $('operator-question').textContent = `${state} returned “${waiting.outcome}”, a transition of ${level} ` +
      'autonomy: confirm it (or click its highlighted outcome), or click another outcome of the state to force it.';
  } else {
    $('operator-question').textContent = `${state} asks: ${waiting.prompt} (JSON; the system's answer is offered)`;
    $('operator-input').value = JSON.stringify(waiting.default);
    $('operator-input').focus();
  }
}

// A click on an outcome cell of the active state: confirm it if it is the one that waits, else force it.
function forceFromDrawing(names) {
  if (!run || !run.active || !names.length) return false;
  const waiting = run.operator.waiting;
  if (waiting && waiting.kind === 'confirm' && names.includes(waiting.outcome)) {
    command({ command: 'confirm', state: waiting.state });
  } else {
    command({ command: 'force', state: run.active, outcome: names[0] });
  }
  return true;
}

function answer(value) {
  const waiting = run && run.operator.waiting;
  if (waiting && waiting.kind === 'input') command({ command: 'input', state: waiting.state, value });
}

// The autonomy selector's levels, as the server names them (Full, the unattended run, selected).
export function fillAutonomyLevels() {
  const levels = vocabulary().autonomy_levels;
  $('autonomy').replaceChildren(...levels.map((name, level) => new Option(name, String(level), false,
    level === levels.length - 1)));
}

export function connectRuntimeControl() {
  $('autonomy').addEventListener('change', () => command({ command: 'autonomy', level: startingAutonomy() }));
  $('pause-run').addEventListener('click', () => command({ command: run && run.operator.paused ? 'resume' : 'pause' }));
  $('stop-run').addEventListener('click', () => command({ command: 'stop' }));
  $('operator-confirm').addEventListener('click', () => {
    const waiting = run && run.operator.waiting;
    if (waiting) command({ command: 'confirm', state: waiting.state });
  });
  $('operator-input-form').addEventListener('submit', (event) => {
    event.preventDefault();
    const text = $('operator-input').value.trim();
    let value;
    try { value = JSON.parse(text); } catch { value = text; }  // the run says what it makes of it
    answer(value);
  });
  $('operator-abort').addEventListener('click', () => answer(null));
}
