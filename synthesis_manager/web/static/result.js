// The result of a finished job: the banner, the summary, the drawing, the downloads and the
// specification; the simulation is offered from here.
import * as drawing from './drawing.js';
import { $, element, formatSeconds } from './dom.js';
import { offerPlay, withdrawPlay } from './play.js';
import { offerRepair, withdrawRepair } from './repair.js';
import { offerSimulation, withdrawSimulation } from './simulation.js';
import { showStateDetails } from './state_details.js';
import { vocabulary } from './vocabulary.js';

export function resetResult() {
  $('result').hidden = true;
  withdrawSimulation();
  withdrawRepair();
  withdrawPlay();
  for (const id of ['graph-section', 'downloads-section', 'specification-section', 'simulation-section']) {
    $(id).hidden = true;
  }
  $('graph').replaceChildren();
  drawing.clear();
  $('timeline').replaceChildren();
  $('progress').value = 0;
}

// A message's first line is its plain sentence; the rest (e.g. the unrealizable core and the
// synthesizer's own account) goes into a collapsed "Details".
export function showBanner(code, message, good) {
  $('result').hidden = false;
  $('abstraction').open = false;  // folded to one line above the result (a click opens it)
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
export function resultWord(errorName) {
  return errorName === vocabulary().job_results.cancelled ? 'CANCELLED' : errorName;
}

export function showRequestError(error) {
  withdrawRepair();
  showBanner(error.code, error.message, false);
  $('summary').replaceChildren();
}

export function showResult(job) {
  const { outcome, summary } = job;
  const message = outcome.message || (summary.succeeded ? describeSuccess(job) : '');
  const cancelled = outcome.error_name === vocabulary().job_results.cancelled;
  showBanner(resultWord(outcome.error_name), message, cancelled ? null : summary.succeeded);
  offerRepair(job);
  offerPlay(job, summary.realizable === false);
  showSummary(summary, job.stages);
  if (job.artifacts.includes('state_machine.svg')) drawStateMachine(job);
  showDownloads(job);
  showSpecification(outcome.ltl_specification);
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

// The picture (Graphviz' SVG) and the machine it shows as a tree of states, which explains
// the state clicked on it.
async function drawStateMachine(job) {
  const [picture, machine] = await Promise.all([
    fetch(`/api/jobs/${job.id}/artifacts/state_machine.svg?inline=1`),
    fetch(`/api/jobs/${job.id}/state-machine`)]);
  $('graph-section').hidden = false;
  const failed = [picture, machine].find((response) => !response.ok);
  if (failed) {
    const data = await failed.json().catch(() => ({}));
    $('graph').replaceChildren(element('p', { className: 'bad', text: data.message || 'no picture' }));
    return;
  }
  drawing.show($('graph'), await picture.text(), await machine.json(), showStateDetails);
  showStateDetails(null);
  drawing.scrollIntoView();  // the machine in view and fitted, the verdict beside it in the form's panel
  drawing.refit();
}

function showDownloads(job) {
  const exportable = job.artifacts.includes('flexbe_behavior.zip');
  $('export-flexbe-offer').hidden = !exportable;  // the button and its caption, or neither
  if (exportable) $('export-flexbe').href = `/api/jobs/${job.id}/artifacts/flexbe_behavior.zip`;
  const listed = job.artifacts.filter((name) => name !== 'flexbe_behavior.zip');  // offered once, above
  $('downloads').replaceChildren(...listed.map((name) => {
    const link = element('a', { href: `/api/jobs/${job.id}/artifacts/${name}`, download: '', 'data-artifact': name,
      text: job.download_labels[name] || name });
    if ((job.made_in_page || []).includes(name)) {
      link.addEventListener('click', (event) => { event.preventDefault(); downloadPng(job, name); });
    }
    return element('li', {}, link);
  }));
  $('downloads-section').hidden = job.artifacts.length === 0;
}

// The PNG when the server has no Graphviz `dot` to make it: the server's SVG (its WebAssembly
// Graphviz) rasterized here at twice its natural size, with the browser's fonts.
async function downloadPng(job, name) {
  const response = await fetch(`/api/jobs/${job.id}/artifacts/state_machine.svg?inline=1`);
  if (!response.ok) return;
  const url = URL.createObjectURL(new Blob([await response.text()], { type: 'image/svg+xml' }));
  try {
    const image = new Image();
    image.src = url;
    await image.decode();
    const canvas = document.createElement('canvas');
    canvas.width = image.naturalWidth * 2;
    canvas.height = image.naturalHeight * 2;
    const context = canvas.getContext('2d');
    context.fillStyle = 'white';
    context.fillRect(0, 0, canvas.width, canvas.height);
    context.drawImage(image, 0, 0, canvas.width, canvas.height);
    const png = await new Promise((resolve) => canvas.toBlob(resolve, 'image/png'));
    const save = element('a', { href: URL.createObjectURL(png), download: `${job.request.name || 'behavior'}_${name}` });
    document.body.append(save);
    save.click();
    save.remove();
    setTimeout(() => URL.revokeObjectURL(save.href), 10_000);
  } finally {
    URL.revokeObjectURL(url);
  }
}

function showSpecification(sections) {
  const shown = vocabulary().specification_sections.filter(({ name }) => (sections[name] || []).length);
  $('specification').replaceChildren(...shown.map(({ name, title }) => element('details', { 'data-section': name },
    element('summary', { text: `${title} — ${sections[name].length}` }),
    element('pre', { text: sections[name].join('\n') }))));
  $('specification-section').hidden = shown.length === 0;
}
