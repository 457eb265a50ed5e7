// Play a finished job (POST /api/jobs/{id}/play): the user plays the environment against a
// synthesized machine (reports each active state's outcome; the drawing shows where it goes),
// or the robot against the environment's winning strategy of an unrealizable task (picks the
// robot's moves; the environment answers, and the panel says why each choice loses).
// The server is stateless: each step sends every move so far. Keys: 1-9 choose, Backspace
// goes back, Escape closes.
import { api } from './api.js';
import * as drawing from './drawing.js';
import { $, element } from './dom.js';

let job = null;        // the job being played
let moves = [];        // the moves so far (outcome names or move indices)
let turn = null;       // the server's answer for them
let requests = 0;      // answers can overtake each other: only the newest is shown

// A finished job with a machine can be played as the environment; an unrealizable one as the robot.
export function offerPlay(finishedJob, unrealizable) {
  closePlay();
  job = finishedJob;
  $('play-environment').hidden = !finishedJob.artifacts.includes('state_machine.svg');
  $('play-robot').hidden = !unrealizable;
}

// A new job is on its way: nothing of the old one stays on the page.
export function withdrawPlay() {
  closePlay();
  job = null;
}

export function closePlay() {
  moves = [];
  turn = null;
  requests += 1;
  $('play-panel').hidden = true;
  $('robot-play-section').hidden = true;
  $('graph-layout').classList.remove('playing');
  drawing.markRun([], false);
  drawing.pickOutcomes(null);
}

// Start a play of the offered job: the panel beside the drawing (environment) or under the banner (robot).
export async function startPlay(asRobot) {
  if (!job) return;
  closePlay();
  const panel = $('play-panel');
  if (asRobot) {
    $('robot-play-section').append(panel);
    $('robot-play-section').hidden = false;
  } else {
    $('graph-layout').append(panel);
    // The panel takes the robot's place beside the drawing (the run's table stays below).
    $('graph-layout').classList.remove('simulating');
    $('robot-view').hidden = true;
    $('graph-layout').classList.add('playing');
  }
  panel.hidden = false;
  if (!asRobot) {  // the drawing beside the panel, as wide as the window lets it be, in view
    drawing.foldForm(true);
    drawing.scrollIntoView();
    drawing.refit();
  }
  $('play-title').textContent = asRobot ? 'You play the robot against the environment'
    : 'You play the environment against the machine';
  panel.hidden = false;
  await step([]);
  if (asRobot) panel.scrollIntoView({ block: 'nearest' });
  panel.focus({ preventScroll: true });
}

async function step(nextMoves) {
  const number = ++requests;
  const keepFocus = $('play-panel').contains(document.activeElement);
  let answer;
  try {
    answer = await api('POST', `/api/jobs/${job.id}/play`, { moves: nextMoves });
  } catch (error) {
    if (number !== requests) return;
    $('play-verdict').textContent = `${error.code}: ${error.message}`;
    return;
  }
  if (number !== requests) return;
  moves = nextMoves;
  turn = answer;
  if (turn.play === 'robot') showRobotTurn(); else showMachineTurn();
  $('play-back').disabled = moves.length === 0;
  $('play-reset').disabled = moves.length === 0;
  const first = $('play-choices').querySelector('button');
  if (keepFocus && !$('play-panel').contains(document.activeElement)) (first || $('play-back')).focus();
}

function choice(number, label, detail, move, className = '') {
  const button = element('button', { type: 'button', className: `play-choice ${className}`, 'data-move': String(move),
    'aria-keyshortcuts': number <= 9 ? String(number) : '' },
  element('span', { className: 'key-number', text: number <= 9 ? `${number}` : '' }), ` ${label}`);
  button.addEventListener('click', () => step([...moves, move]));
  return element('li', {}, button, ...(detail ? [element('span', { className: 'play-why', text: detail })] : []));
}

// The environment's side: the active state's outcomes, the machine's path on the drawing.
function showMachineTurn() {
  const name = (path) => path.replace(/^\//, '');
  $('play-position').textContent = turn.ended === null
    ? `Step ${turn.step}: ${name(turn.active)} is active.`
    : `Step ${turn.step}: the machine ended in ${turn.ended}.`;
  $('play-environment-next').textContent = '';
  $('play-verdict').textContent = '';
  $('play-verdict').className = turn.ended === null ? '' : `outcome-${turn.ended}`;
  $('play-prompt').textContent = turn.ended === null
    ? `Which outcome does ${name(turn.active)} return? Click it on the drawing or below (keys ` +
      `1–${Math.min(9, turn.outcomes.length)}).`
    : 'Back or Reset to play again.';
  $('play-choices').replaceChildren(...turn.outcomes.map((outcome, index) => choice(index + 1, outcome, '', outcome)));
  $('play-history').replaceChildren(...turn.history.map(([state, outcome]) =>
    element('li', { text: `${name(state)} → ${outcome}` })));
  drawing.markPlay(turn.history, turn.active);
  drawing.pickOutcomes(turn.ended === null ? pickFromDrawing : null);
}

// An outcome cell of the active state clicked on the drawing (outcomes sharing a cell share
// their target: the first is reported).
function pickFromDrawing(names) {
  const outcome = names.find((name) => turn && turn.outcomes.includes(name));
  if (outcome === undefined) return false;
  step([...moves, outcome]);
  return true;
}

// The robot's side, a game with an end: what happened, what the environment does next, the
// moves (progress first) and why they lose, and the verdict once the play is over (a deadlock,
// a loop, every goal reached, or the most moves a play has).
function showRobotTurn() {
  $('play-position').textContent = `Step ${turn.step} of at most ${turn.max_moves}: ${turn.happened}.`;
  const over = Boolean(turn.verdict);
  $('play-environment-next').textContent = over ? '' : `The environment does next: ${turn.environment_next}.`;
  const won = turn.verdict === 'you reached every goal';
  $('play-verdict').className = won ? 'good' : 'bad';
  $('play-verdict').textContent = over ? `Verdict: ${turn.verdict}.`
    : turn.blocked_goal ? `Why it cannot win: ${turn.blocked_goal}.` : '';
  $('play-prompt').textContent = over ? 'The play is over: Back or Reset to try other moves.'
    : `Choose the robot's response (keys 1–${Math.min(9, turn.moves.length)}); a play ends within ` +
      `${turn.max_moves} moves. Goals: ${turn.goals.map((goal, index) =>
        `${index + 1} ${goal.words}${goal.reached ? ' (reached)' : ''}`).join('; ')}.`;
  const items = turn.moves.map((move, index) => choice(index + 1, move.words, move.dead_end
    ? 'dead end: the environment can answer so that no response is allowed'
    : move.repeats ? 'loop: it returns to a position of this play, which ends the play (the environment wins)' : '',
  move.index, move.dead_end ? 'dead-end' : move.repeats ? 'repeats' : ''));
  // Dead ends (listed last) lose at once: folded, so that the moves worth trying stand out.
  const live = items.filter((_, index) => !turn.moves[index].dead_end);
  const dead = items.filter((_, index) => turn.moves[index].dead_end);
  const folded = element('details', { className: 'dead-ends' },
    element('summary', { text: `${dead.length} move${dead.length === 1 ? '' : 's'} that lose at once (dead ends)` }),
    element('ol', { className: 'play-choices' }, ...dead));
  folded.open = live.length === 0;
  $('play-choices').replaceChildren(...live, ...(dead.length ? [element('li', {}, folded)] : []),
    ...(turn.more_moves ? [element('li', { className: 'muted', text: `(${turn.more_moves} more moves not listed)` })] : []));
  $('play-history').replaceChildren(...turn.history.map((words) => element('li', { text: words })));
}

export function back() {
  if (job && moves.length) step(moves.slice(0, -1));
}

export function reset() {
  if (job && moves.length) step([]);
}

// While a play is shown, keys on the panel or the drawing beside it: 1-9 choose the numbered
// choice, Backspace goes back, Escape closes the panel.
export function playKeys(event) {
  if ($('play-panel').hidden || event.target.closest('textarea, input, select')) return;
  if (/^[1-9]$/.test(event.key)) {
    const buttons = $('play-choices').querySelectorAll('button.play-choice');
    const button = buttons[Number(event.key) - 1];
    if (button) { event.preventDefault(); button.click(); }
  } else if (event.key === 'Backspace') {
    event.preventDefault();
    back();
  } else if (event.key === 'Escape') {
    closePlay();
  }
}
