// A simulation's key frames: the latest one large with a caption, a scrubber over all of
// them, captioned thumbnails, and a player that shows them at robot speed.
import { $, element } from './dom.js';

let frameList = [];  // {src, caption, time} of each key frame shown
let player = null;   // the timer of the frame player

export function showFrames(base, frames) {
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

// No frames: a new run starts, or the result went away.
export function resetFrames() {
  stopPlaying();
  $('simulation-frames').replaceChildren();
  frameList = [];
  $('frame-scrubber').value = '0';
  $('frame-scrubber').max = '0';
}

// Play the key frames as the run went: each stays up for the robot time until the next one.
export function playFrames() {
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

export function stopPlaying() {
  if (player) clearTimeout(player);
  player = null;
  $('play-frames').textContent = '▶ Play';
}

export function showFrame(index) {
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
