// A simulation's frames: the one shown large with a caption, a scrubber over all of them,
// captioned thumbnails, and a player that plays them as continuous motion at robot speed with
// the state active at each frame's robot time highlighted on the drawing. Until the first
// frame arrives the view says the simulator is starting (no empty image).
import * as drawing from './drawing.js';
import { $, element } from './dom.js';

let frameList = [];  // {src, caption, time} of each frame shown (time: robot seconds)
let runSteps = [];   // the run's steps (for the active state at a frame's time)
let runLive = false; // the run still goes on: the drawing follows the run, not the frame shown
let player = null;   // the animation frame request of the player

// ``frames``: [{index, label, time?}] (time: the frame's robot time when the server gives it);
// ``steps``: the run's steps so far; ``live``: whether the run still goes on.
export function showFrames(base, frames, steps = [], live = false) {
  runSteps = steps;
  runLive = live;
  if (!frames.length) return;
  const followLatest = Number($('frame-scrubber').value) >= frameList.length - 1;
  const times = frameTimes(frames, steps);
  frameList = frames.map((frame, i) => ({ src: `${base}/frames/${frame.index}`, caption: frameCaption(frame.label, times[i]),
    time: times[i] }));
  $('frame-scrubber').max = String(frames.length - 1);
  $('simulation-frames').replaceChildren(...frameList.map((frame, index) => {
    const figure = element('figure', { 'data-frame': String(index) },
      element('img', { src: frame.src, alt: frame.caption, loading: 'lazy' }), element('figcaption', { text: frame.caption }));
    figure.addEventListener('click', () => { stopPlaying(); showFrame(index); });
    return figure;
  }));
  if (!player) showFrame(followLatest ? frames.length - 1 : Number($('frame-scrubber').value));
}

// No frames: a new run starts (the simulator is starting), or the result went away.
export function resetFrames() {
  stopPlaying();
  $('simulation-frames').replaceChildren();
  frameList = [];
  runSteps = [];
  $('frame-scrubber').value = '0';
  $('frame-scrubber').max = '0';
  $('simulation-frame').hidden = true;
  $('simulation-frame').removeAttribute('src');
  $('robot-starting').hidden = false;
  $('simulation-frame-label').textContent = '';
}

// Play the frames as the run went, at robot speed: a robot clock runs from the frame shown
// (the first one after the end) and each animation frame shows the next frame it has reached.
export function playFrames() {
  if (player) { stopPlaying(); return; }
  if (!frameList.length) return;
  $('play-frames').textContent = '❚❚ Pause';
  $('play-frames').dataset.playing = 'true';
  let index = Number($('frame-scrubber').value) >= frameList.length - 1 ? 0 : Number($('frame-scrubber').value);
  const startTime = frameList[index].time;
  const startWall = performance.now();
  showFrame(index);
  const tick = (now) => {
    const robotTime = startTime + (now - startWall) / 1000;
    // One frame further per animation frame (each is shown, also those of the same instant),
    // more only to catch up when the page falls over 0.1 s behind the robot clock.
    if (index < frameList.length - 1 && frameList[index + 1].time <= robotTime) index += 1;
    while (index < frameList.length - 1 && frameList[index + 1].time <= robotTime - 0.1) index += 1;
    if (Number($('frame-scrubber').value) !== index) showFrame(index);
    if (index >= frameList.length - 1) { stopPlaying(); return; }
    player = requestAnimationFrame(tick);
  };
  player = requestAnimationFrame(tick);
}

export function stopPlaying() {
  if (player) cancelAnimationFrame(player);
  player = null;
  $('play-frames').textContent = '▶ Play';
  delete $('play-frames').dataset.playing;
}

export function showFrame(index) {
  const frame = frameList[index];
  if (!frame) return;
  $('frame-scrubber').value = String(index);
  $('robot-starting').hidden = true;
  $('simulation-frame').hidden = false;
  $('simulation-frame').src = frame.src;
  $('simulation-frame').alt = frame.caption;
  $('simulation-frame').dataset.time = String(frame.time);
  $('simulation-frame-label').textContent = `Frame ${index + 1} of ${frameList.length}: ${frame.caption}`;
  document.querySelectorAll('#simulation-frames figure').forEach((f) =>
    f.classList.toggle('current', f.dataset.frame === String(index)));
  if (!runLive) markStateAt(frame.time, index === frameList.length - 1);
}

// The drawing shows the run as it was at robot time ``time``: the steps entered by then, the
// one running then active (the whole run, ended, at the last frame).
function markStateAt(time, last) {
  if (!runSteps.length) return;
  if (last) { drawing.markRun(runSteps, false); return; }
  const entered = runSteps.filter((step) => step.entered_at <= time);
  const shown = entered.map((step, i) => (i === entered.length - 1 ? { ...step, transition: null } : step));
  drawing.markRun(shown.length ? shown : runSteps.slice(0, 1).map((s) => ({ ...s, transition: null })), true);
}

// Each frame's robot time: the server's, else the one in its name, else the frames spread
// evenly over the robot time the steps took.
function frameTimes(frames, steps) {
  const named = frames.map((frame) => (Number.isFinite(frame.time) ? frame.time : frameTime(frame.label)));
  if (named.every(Number.isFinite)) return named;
  const start = steps.length ? steps[0].entered_at : 0;
  const ends = steps.map((s) => (Number.isFinite(s.ended_at) ? s.ended_at : s.entered_at));
  const end = ends.length ? Math.max(...ends) : start;
  return frames.map((frame, i) => (Number.isFinite(named[i]) ? named[i]
    : start + (frames.length > 1 ? (i / (frames.length - 1)) * (end - start) : 0)));
}

// frame files are named <index>_<sim time>s_<what>
function frameTime(label) {
  const match = label.match(/^\d+_0*(\d+\.\d+)s_/);
  return match ? Number(match[1]) : NaN;
}

function frameCaption(label, time) {
  const match = label.match(/^\d+_0*(\d+\.\d+)s_(.*)$/);
  if (match) return `t = ${match[1]} s: ${match[2].replace(/_/g, ' ')}`;
  return Number.isFinite(time) ? `t = ${time.toFixed(2)} s: ${label.replace(/_/g, ' ')}` : label.replace(/_/g, ' ');
}
