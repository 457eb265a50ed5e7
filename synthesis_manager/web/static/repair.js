// "Suggest fixes" for a refused job (POST /api/repair): verified changes that make the task
// possible, each with what it changes. A change of the request or the custom LTL is applied
// with one click (the form takes it and synthesizes); a change of the robot is shown as the
// patch of its file and never applied.
import { lineError, postForLines } from './api.js';
import { $, element, formatSeconds } from './dom.js';
import { repairTimeBudget } from './form.js';
import { vocabulary } from './vocabulary.js';

let refusedJob = null;   // the job whose request the fixes are for
let applyHandler = null; // (request) => fill the form with it and synthesize
let searches = 0;        // a newer job or search makes an older answer stale
let ticker = null;

export function onApplyFix(handler) {
  applyHandler = handler;
}

// Offer "Suggest fixes" under the banner of a refusal a change of the task can fix.
export function offerRepair(job) {
  withdrawRepair();
  const repairable = vocabulary().repairable.includes(job.outcome.error_name);
  refusedJob = repairable ? job : null;
  $('refusal-actions').hidden = !repairable;
  $('suggest-fixes').disabled = false;
}

export function withdrawRepair() {
  refusedJob = null;
  searches += 1;
  clearInterval(ticker);
  $('refusal-actions').hidden = true;
  $('repair-section').hidden = true;
  $('proposals').replaceChildren();
}

export async function suggestFixes() {
  if (!refusedJob) return;
  const job = refusedJob;
  const number = ++searches;
  $('suggest-fixes').disabled = true;
  $('repair-section').hidden = false;
  $('repair-problem').textContent = '';
  $('repair-note').textContent = '';
  $('proposals').replaceChildren();
  $('repair-section').classList.add('searching');
  const started = performance.now();
  const tick = () => {
    const seconds = ((performance.now() - started) / 1000).toFixed(1);
    const timeBudget = repairTimeBudget();
    $('repair-status').textContent = `Searching for fixes… ${seconds} s` +
      (timeBudget ? ` (at most ${timeBudget} s): each candidate is synthesized before it is offered` : '');
  };
  tick();
  clearInterval(ticker);
  ticker = setInterval(tick, 200);
  $('repair-section').scrollIntoView({ block: 'nearest' });
  let repairs = null;
  const found = [];
  try {
    // Proposals are shown as they are verified; the last line is the whole answer.
    await postForLines('/api/repair', job.request, (line) => {
      if (number !== searches) return;
      if (line.error) throw lineError(line.error);
      if (line.result) {
        repairs = line.result;
        return;
      }
      found.push(line.proposal);
      $('proposals').append(proposalItem(job, line.proposal, found.length - 1));
      $('repair-note').textContent = `${found.length} found so far…`;
    });
    if (number === searches && !repairs) throw new Error('the server ended the search without an answer');
  } catch (error) {
    if (number !== searches) return;
    clearInterval(ticker);
    $('repair-section').classList.remove('searching');
    $('suggest-fixes').disabled = false;
    $('repair-status').textContent = error.status === 429
      ? `The server is busy with other searches: try again in ${error.retryAfter || 10} s.`
      : `No fixes: ${error.message}`;
    return;
  }
  if (number !== searches) return;
  clearInterval(ticker);
  $('repair-section').classList.remove('searching');
  $('suggest-fixes').disabled = false;
  showRepairs(job, repairs);
}

function showRepairs(job, repairs) {
  const count = repairs.proposals.length;
  $('repair-status').textContent = repairs.realizable ? 'The task can be done as asked: nothing to fix.'
    : count ? `${count} verified fix${count === 1 ? '' : 'es'} (found in ${formatSeconds(repairs.seconds)}):`
      : `No verified fix found (${repairs.tried} changes tried in ${formatSeconds(repairs.seconds)}).`;
  $('repair-problem').textContent = repairs.problem ? `The problem: ${repairs.problem}` : '';
  $('repair-note').textContent = repairs.note || '';
  const focused = [...$('proposals').querySelectorAll('button')].indexOf(document.activeElement);
  $('proposals').replaceChildren(...repairs.proposals.map((proposal, index) => proposalItem(job, proposal, index)));
  const buttons = $('proposals').querySelectorAll('button');
  const target = buttons[Math.max(0, focused)];   // keep a focus the search's progress found there
  if (target && (focused >= 0 || document.activeElement === $('suggest-fixes'))) target.focus();
}

function proposalItem(job, proposal, index) {
  const item = element('li', { className: `proposal${proposal.changes_robot ? ' changes-robot' : ''}`,
    'data-kind': proposal.kind },
  element('strong', { text: proposal.summary }));
  const changes = [];
  if (proposal.request) changes.push(...requestChanges(job.request, proposal.request));
  if (proposal.custom_ltl) changes.push(`custom LTL becomes ${JSON.stringify(proposal.custom_ltl)}`);
  if (changes.length) item.append(element('ul', { className: 'changes' }, ...changes.map((text) => element('li', { text }))));
  if (proposal.config_patch) {
    const patch = proposal.config_patch;
    item.append(element('p', { className: 'robot-change', text: 'Changes the robot — not applied' }),
      element('pre', { className: 'config-patch', text: `in ${patch.file}, set ${patch.path.join('.')}: ` +
        `${JSON.stringify(patch.value)}\n(was ${JSON.stringify(patch.previous)})` }));
  }
  const verified = `verified: realizable, synthesized in ${formatSeconds(proposal.synthesis_seconds)}`;
  item.append(element('p', { className: 'muted verified', text: verified }));
  if (!proposal.changes_robot && (proposal.request || proposal.custom_ltl)) {
    const apply = element('button', { type: 'button', className: 'primary apply-fix',
      'aria-label': `apply fix ${index + 1} and synthesize: ${proposal.summary}`, text: 'Apply and synthesize' });
    apply.addEventListener('click', () => {
      const request = { ...job.request, ...(proposal.request || {}) };
      if (proposal.custom_ltl) request.custom_ltl = proposal.custom_ltl;
      if (applyHandler) applyHandler(request);
    });
    item.append(apply);
  }
  return item;
}

// What a proposal's request changes, field by field, in words.
function requestChanges(before, after) {
  const list = (names) => (names.length ? names.join(', ') : 'none');
  const changes = [];
  const fields = [['initial_conditions', 'initial conditions'], ['goals', 'goals'], ['sm_outcomes', 'outcomes']];
  for (const [field, label] of fields) {
    if (list(before[field]) !== list(after[field])) changes.push(`${label}: ${list(before[field])} → ${list(after[field])}`);
  }
  if (Boolean(before.unordered) !== Boolean(after.unordered)) {
    changes.push(after.unordered ? 'goals in any order' : 'goals in the given order');
  }
  return changes;
}
