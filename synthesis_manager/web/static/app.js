// The behavior synthesis page: build a request from the system's own names, run it as a
// job on the server, follow its progress (server-sent events) and show the result.
//
// Plain ES modules, each with one job and its own state (no build step):
//   api.js            the JSON API and the event streams
//   dom.js            DOM helpers
//   vocabulary.js     the Python names the page needs (GET /api/vocabulary)
//   form.js           the request form and its live goal check
//   job.js            running a job: progress, reconnecting, cancelling
//   result.js         the result: banner, summary, drawing, downloads, specification
//   drawing.js        the state machine drawing (zoom, pan, clicks, the simulation's path)
//   state_details.js  the panel explaining a clicked state
//   simulation.js     the closed-loop simulation view
//   frames.js         its key frames and their player
//   runtime_control.js the operator's side of a run (autonomy, confirm, force, input, pause, stop)
//   repair.js         "Suggest fixes" for a refused job, and applying one
//   play.js           playing a finished job: the environment against its machine, or the robot
// This module only connects the page's controls to them and starts the page.
import { $ } from './dom.js';
import { foldForm } from './drawing.js';
import { addGoal, checkGoals, fillForm, loadChoices, loadSystems } from './form.js';
import { playFrames, showFrame, stopPlaying } from './frames.js';
import { cancel, synthesize } from './job.js';
import { back, closePlay, playKeys, reset, startPlay } from './play.js';
import { onApplyFix, suggestFixes } from './repair.js';
import { connectRuntimeControl, fillAutonomyLevels, runKeys } from './runtime_control.js';
import { simulate } from './simulation.js';
import { loadVocabulary } from './vocabulary.js';

$('system').addEventListener('change', loadChoices);
$('add-goal').addEventListener('click', addGoal);
$('request-form').addEventListener('submit', synthesize);
$('cancel').addEventListener('click', cancel);
$('simulate').addEventListener('click', () => { closePlay(); simulate(); });
$('show-form').addEventListener('click', () => foldForm(false));
$('frame-scrubber').addEventListener('input', (event) => { stopPlaying(); showFrame(Number(event.target.value)); });
$('play-frames').addEventListener('click', playFrames);
connectRuntimeControl();
$('behavior-name').addEventListener('input', () => $('behavior-name-hint').classList.remove('bad'));
$('initial-conditions').addEventListener('change', checkGoals);
$('unordered').addEventListener('change', checkGoals);
$('suggest-fixes').addEventListener('click', suggestFixes);
onApplyFix(async (request) => { await fillForm(request); synthesize(); });
$('play-environment').addEventListener('click', () => startPlay(false));
$('play-robot').addEventListener('click', () => startPlay(true));
$('play-back').addEventListener('click', back);
$('play-reset').addEventListener('click', reset);
$('play-close').addEventListener('click', closePlay);
$('graph-layout').addEventListener('keydown', playKeys);     // the panel and the drawing beside it
$('graph-layout').addEventListener('keydown', runKeys);      // a simulation's operator, as in Play
$('robot-play-section').addEventListener('keydown', playKeys);
loadVocabulary().then(fillAutonomyLevels).then(loadSystems).then(() => document.body.classList.add('ready'),
  (error) => { $('status').textContent = `Cannot load the systems: ${error.message}`; });
