// Running a job: send the form's request, follow the job's progress (server-sent events,
// reconnecting when the stream breaks), cancel it, and hand the finished job to the result.
import { api, streamEvents } from './api.js';
import { foldForm } from './drawing.js';
import { $, element, formatSeconds } from './dom.js';
import { currentRequest, requestProblem, revealFlaggedGoal } from './form.js';
import { resetResult, resultWord, showBanner, showRequestError, showResult } from './result.js';
import { vocabulary } from './vocabulary.js';

let currentJob = null;   // id of the job being followed
let events = null;       // its EventSource
let shownProgress = { id: null, revision: -1 };  // newest job snapshot shown: replies can overtake
let startedAt = 0;       // performance.now() when the followed job was started
let elapsedTimer = null;

// Send the form's request (``event``: the form's submit, none when called to apply a fix).
export async function synthesize(event) {
  if (event) event.preventDefault();
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
  foldForm(false);
  resetResult();
  let job;
  try {
    job = await api('POST', '/api/jobs', request);
  } catch (error) {
    setRunning(false);
    $('progress').value = 1;
    $('progress').classList.add('refused');
    $('status').textContent = 'The request was not accepted.';
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
    if (error.code === vocabulary().request_errors.not_found) {
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

export async function cancel() {
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
    $('progress').classList.remove('refused');
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
  // A finished job's bar is full, whether it succeeded or was refused at some stage (the
  // banner says which); red when refused.
  if (job.state === 'finished') {
    $('progress').value = 1;
    $('progress').classList.toggle('refused', !(job.summary && job.summary.succeeded));
  }
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
  revealFlaggedGoal();
}
