// The state machine drawing: Graphviz' SVG (sm_generation.export.to_dot, FlexBE-like boxes)
// shown in a viewport with zoom and pan, states that explain themselves when clicked, and
// the simulation's active state and path taken marked on it. The clicked state is looked up
// in the machine's tree (GET /api/jobs/{id}/state-machine), which the server builds.
import { element } from './dom.js';

const ZOOM_STEP = 1.25;
const MIN_SCALE = 0.1;   // px per SVG unit (Graphviz units are points)
const MAX_SCALE = 6;
const NATURAL_SCALE = 4 / 3;  // 1 pt = 4/3 px: "100 %"
const MIN_TEXT_PX = 11;       // no text of the drawing is shown smaller, unless the user zooms out
const FOLD_FORM_BELOW_PX = 1600;  // window widths at which a run or play folds the form away

let svg = null;
let viewport = null;
let full = null;     // the drawing's own viewBox {x, y, w, h}
let view = null;     // the part shown now
let machine = null;  // the shown machine's tree: its root node
let onSelect = null;
let outcomePicker = null;  // during a play: (outcome names of the clicked cell) => whether one was taken
let readableScale = 1;     // px per SVG unit at which the drawing's smallest text is MIN_TEXT_PX

function scale() { return viewport.clientWidth / view.w; }

function apply() {
  view.h = view.w * (viewport.clientHeight / viewport.clientWidth);
  svg.setAttribute('viewBox', `${view.x} ${view.y} ${view.w} ${view.h}`);
  viewport.dataset.scale = scale().toFixed(3);
}

function zoomAt(factor, clientX, clientY) {
  const target = Math.min(MAX_SCALE, Math.max(MIN_SCALE, scale() * factor));
  const rect = viewport.getBoundingClientRect();
  const fx = clientX === undefined ? 0.5 : (clientX - rect.left) / rect.width;
  const fy = clientY === undefined ? 0.5 : (clientY - rect.top) / rect.height;
  const px = view.x + fx * view.w;
  const py = view.y + fy * view.h;
  view.w = viewport.clientWidth / target;
  view.h = view.w * (viewport.clientHeight / viewport.clientWidth);
  view.x = px - fx * view.w;
  view.y = py - fy * view.h;
  apply();
}

// The whole drawing if its labels stay readable there; else a readable part of it: the
// top, around the initial state (drag or zoom out for the rest).
function fit(readableOnly = true) {
  let s = Math.min(viewport.clientWidth / full.w, viewport.clientHeight / full.h);
  const shrunk = readableOnly && s < readableScale;
  if (shrunk) s = readableScale;
  view = { x: full.x, y: full.y, w: viewport.clientWidth / s, h: 0 };
  const start = svg.querySelector('[id="start"]');
  if (view.w > full.w) view.x = full.x - (view.w - full.w) / 2;  // centre narrow drawings
  else if (shrunk && start) {
    // Graphviz draws inside a translated group: add its offset to the node's own box.
    const shift = svg.querySelector('g.graph').transform.baseVal.consolidate();
    const box = start.getBBox();
    const centre = box.x + box.width / 2 + (shift ? shift.matrix.e : 0);
    view.x = Math.min(full.x + full.w - view.w, Math.max(full.x, centre - view.w / 2));
  }
  apply();
}

function natural() {
  const cx = view.x + view.w / 2;
  view.w = viewport.clientWidth / NATURAL_SCALE;
  view.x = cx - view.w / 2;
  apply();
}

function enablePanning() {
  let drag = null;
  viewport.addEventListener('pointerdown', (event) => {
    // The pressed element is remembered: once the pointer is captured, events go to the viewport.
    drag = { x: event.clientX, y: event.clientY, view: { ...view }, moved: false, target: event.target };
    viewport.setPointerCapture(event.pointerId);
  });
  viewport.addEventListener('pointermove', (event) => {
    if (!drag) return;
    const dx = event.clientX - drag.x;
    const dy = event.clientY - drag.y;
    if (Math.abs(dx) + Math.abs(dy) > 4) drag.moved = true;
    if (!drag.moved) return;
    view.x = drag.view.x - dx / scale();
    view.y = drag.view.y - dy / scale();
    apply();
    viewport.classList.add('panning');
  });
  viewport.addEventListener('pointerup', () => {
    const clicked = drag && !drag.moved ? drag : null;
    drag = null;
    viewport.classList.remove('panning');
    if (clicked) select(clicked.target, clicked.x, clicked.y);
  });
  viewport.addEventListener('wheel', (event) => {
    event.preventDefault();
    zoomAt(event.deltaY < 0 ? ZOOM_STEP : 1 / ZOOM_STEP, event.clientX, event.clientY);
  }, { passive: false });
  viewport.addEventListener('keydown', (event) => {
    if ((event.key === 'Enter' || event.key === ' ') && event.target.closest && event.target.closest('g.node')) {
      event.preventDefault();
      select(event.target);
      return;
    }
    if (event.key === '+' || event.key === '=') zoomAt(ZOOM_STEP);
    else if (event.key === '-') zoomAt(1 / ZOOM_STEP);
    else if (event.key === '0') fit(false);
  });
}

// A clicked SVG element -> the top-level state it belongs to (id "state:<name>"); during a play
// or a run, a click anywhere in an outcome cell of the active state reports that cell's outcomes
// instead (``x``, ``y``: where the click was, in the window).
function select(target, x, y) {
  const node = target.closest ? target.closest('g.node') : null;
  const active = outcomePicker ? svg.querySelector('g.node.active') : null;
  const cell = active ? cellAt(active, x, y) : null;
  if (cell && outcomePicker(cell.dataset.outcomes.split(','))) return;
  svg.querySelectorAll('g.node.selected').forEach((g) => g.classList.remove('selected'));
  if (!node || !node.id.startsWith('state:')) { if (onSelect) onSelect(null); return; }
  node.classList.add('selected');
  const name = node.id.slice('state:'.length);
  if (onSelect) onSelect(machine.children.find((state) => state.name === name) || null);
}

// Graphviz draws a table cell of a state's label as its background polygon, then its border,
// then its text lines. Each polygon whose text names outcomes of the state is marked as that
// outcome cell (data-outcomes), so the whole cell can be clicked.
function markOutcomeCells(node, state) {
  let cell = null;
  let names = [];
  const close = () => {
    if (cell && names.length && names.every((name) => state.outcomes.includes(name))) {
      cell.classList.add('outcome-cell');
      cell.dataset.outcomes = names.join(',');
    }
    cell = null;
    names = [];
  };
  for (const child of node.children) {
    if (child.tagName === 'polygon') { close(); cell = child; }
    else if (child.tagName === 'text' && cell) names.push(...child.textContent.split(',').map((n) => n.trim()).filter(Boolean));
    else if (child.tagName !== 'polyline') close();
  }
  close();
}

// The outcome cell of ``node`` at window point (x, y); the cell's highlighted border (drawn
// half outside it) counts as the cell.
function cellAt(node, x, y) {
  if (x === undefined) return null;
  const border = 3;
  return [...node.querySelectorAll('polygon.outcome-cell')].find((cell) => {
    const box = cell.getBoundingClientRect();
    return x >= box.left - border && x <= box.right + border && y >= box.top - border && y <= box.bottom + border;
  }) || null;
}

// The outcomes of top-level state ``path`` ('/look_down') in the order FlexBE lists them ([] unknown).
export function outcomesOf(path) {
  const state = machine && machine.children.find((node) => node.state_path === path);
  return state ? [...state.outcomes] : [];
}

// Focus the drawing (keys 1-9 force outcomes there) without scrolling the page.
export function focusDrawing() {
  if (viewport) viewport.focus({ preventScroll: true });
}

// Draw ``svgText`` in ``container``; ``tree`` is the machine's root node, and ``selectCallback``
// is called with the node of the state clicked (null: none).
export function show(container, svgText, tree, selectCallback) {
  machine = tree;
  onSelect = selectCallback;
  const parsed = new DOMParser().parseFromString(svgText, 'image/svg+xml').documentElement;
  svg = document.importNode(parsed, true);
  const box = svg.viewBox.baseVal;
  full = { x: box.x, y: box.y, w: box.width, h: box.height };
  svg.removeAttribute('width');
  svg.removeAttribute('height');
  svg.setAttribute('id', 'state-machine-svg');
  svg.setAttribute('preserveAspectRatio', 'xMinYMin meet');
  // Graphviz adds a tooltip <title> to every node and edge; the ids say enough.
  svg.querySelectorAll('g > title').forEach((title) => title.remove());
  // States are reached with Tab and explained with Enter, as with a click.
  svg.querySelectorAll('g.node[id^="state:"]').forEach((node) => {
    const state = tree.children.find((child) => child.name === node.id.slice('state:'.length));
    if (state) markOutcomeCells(node, state);
    node.setAttribute('tabindex', '0');
    node.setAttribute('role', 'button');
    node.setAttribute('aria-label', `state ${node.id.slice('state:'.length)}: show its details`);
    node.addEventListener('focus', () => revealNode(node));
  });
  viewport = element('div', { className: 'graph-viewport', tabindex: '0', 'aria-label': 'state machine drawing; drag to pan, wheel or + and - to zoom' }, svg);
  const button = (text, label, action) => {
    const b = element('button', { type: 'button', className: 'small', title: label, 'aria-label': label, text });
    b.addEventListener('click', action);
    return b;
  };
  const tools = element('div', { className: 'graph-tools' },
    button('−', 'zoom out', () => zoomAt(1 / ZOOM_STEP)),
    button('+', 'zoom in', () => zoomAt(ZOOM_STEP)),
    button('Fit', 'show the whole machine', () => fit(false)),
    button('100 %', 'natural size', natural));
  container.replaceChildren(tools, viewport);
  const smallest = Math.min(...[...svg.querySelectorAll('text')].map((t) => parseFloat(t.getAttribute('font-size')) || 14));
  readableScale = MIN_TEXT_PX / smallest;
  enablePanning();
  sizeViewport();
  fit();
}

// The drawing as high as the window below the section's header row: once the section is
// scrolled to the window's top (after Synthesize, Simulate, Play), all of it is in view.
function sizeViewport() {
  const section = document.getElementById('graph-section');
  const above = viewport.getBoundingClientRect().top - section.getBoundingClientRect().top;
  const below = 16;  // the section's padding and border, and a margin
  viewport.style.height = `${Math.max(300, Math.floor(window.innerHeight - above - below))}px`;
}

// Scroll the page so that the drawing's section starts at the window's top.
export function scrollIntoView() {
  const section = document.getElementById('graph-section');
  if (section && !section.hidden) section.scrollIntoView({ block: 'start', behavior: 'instant' });
}

// During a run or a play, fold the request form away on windows where it would squeeze the
// drawing (false: unfold it); the drawing is sized and fitted again.
export function foldForm(fold) {
  const folded = fold && window.innerWidth < FOLD_FORM_BELOW_PX;
  document.body.classList.toggle('form-folded', folded);
  const button = document.getElementById('show-form');
  if (button) button.hidden = !folded;
  if (svg) { sizeViewport(); fit(); }
}

window.addEventListener('resize', () => { if (svg) { sizeViewport(); fit(); } });

// Mark the simulation on the drawing: the states visited, the transitions taken and the
// active state (the last one; "ended" once the run has finished).
export function markRun(steps, running) {
  if (!svg) return;
  svg.querySelectorAll('.visited, .active, .taken, .ended').forEach((g) =>
    g.classList.remove('visited', 'active', 'taken', 'ended'));
  const topName = (path) => path.split('/')[1];
  steps.forEach((step, index) => {
    const name = topName(step.state);
    const node = document.getElementById(`state:${name}`);
    if (node) node.classList.add(index === steps.length - 1 ? (running ? 'active' : 'ended') : 'visited');
    if (step.transition) {
      const edge = document.getElementById(`edge:${name}->${step.transition}`);
      if (edge) edge.classList.add('taken');
      const outcome = outcomeBox(step.transition, name);
      if (outcome && !running && index === steps.length - 1) outcome.classList.add('ended');
    }
  });
  if (steps.length) {
    const start = document.getElementById('edge:start');
    if (start) start.classList.add('taken');
  }
  const current = svg.querySelector('g.node.active, g.node.ended');
  if (current) revealNode(current);  // follow the robot through a machine larger than the view
  afterMarking.forEach((callback) => callback());
}

const afterMarking = [];
// Call ``callback`` each time the run or play marked on the drawing changed.
export function whenMarked(callback) { afterMarking.push(callback); }

// Pan so that ``node`` is not under ``rect`` (a panel over the drawing), by the shorter of a
// move to its left or below it.
export function moveOutFrom(node, rect) {
  if (!svg) return;
  const box = node.getBoundingClientRect();
  const left = box.right - rect.left + 8;   // px to move the node left
  const down = rect.bottom - box.top + 8;   // px to move it down
  if (left <= down) view.x += left / scale();
  else view.y -= down / scale();
  apply();
}

// Mark a play of the environment on the drawing as markRun marks a simulation: ``history`` the
// (state path, outcome) pairs reported so far, ``active`` the active state's path (null: ended).
export function markPlay(history, active) {
  if (!machine) return;
  const steps = history.map(([path, outcome]) => {
    const state = machine.children.find((node) => node.state_path === path);
    return { state: path, transition: state ? state.transitions[state.outcomes.indexOf(outcome)] : null };
  });
  if (active) steps.push({ state: active, transition: null });
  markRun(steps, active !== null);
}

// Pan a focused state into view (keyboard users cannot drag).
function revealNode(node) {
  const box = node.getBoundingClientRect();
  const area = viewport.getBoundingClientRect();
  if (box.left >= area.left && box.right <= area.right && box.top >= area.top && box.bottom <= area.bottom) return;
  view.x += (box.left + box.width / 2 - (area.left + area.width / 2)) / scale();
  view.y += (box.top + box.height / 2 - (area.top + area.height / 2)) / scale();
  apply();
}

// The box of machine outcome ``name`` under the column of state ``stateName`` (long machines
// repeat failure outcomes per column: outcome:<name>:<column>), else the only one.
function outcomeBox(name, stateName) {
  const state = document.getElementById(`state:${stateName}`);
  const column = state ? [...state.classList].find((c) => c.startsWith('column-')) : null;
  const number = column ? Number(column.slice('column-'.length)) : 0;
  return document.getElementById(number ? `outcome:${name}:${number}` : `outcome:${name}`)
    || document.getElementById(`outcome:${name}`);
}

// Highlight the outcome of ``waiting`` ({state, outcome}: a transition waiting for the
// operator's confirmation) in its state's outcome cells; null: none waits.
export function markPending(waiting) {
  if (!svg) return;
  svg.querySelectorAll('.pending').forEach((g) => g.classList.remove('pending'));
  if (!waiting) return;
  const node = document.getElementById(`state:${waiting.state.split('/')[1]}`);
  if (!node) return;
  node.classList.add('pending');
  node.querySelectorAll('text').forEach((text) => {
    if (text.textContent.split(',').map((name) => name.trim()).includes(waiting.outcome)) text.classList.add('pending');
  });
}

export function clear() { svg = null; viewport = null; machine = null; }

// During a play the active state's outcome cells can be clicked: ``picker(names)`` gets the
// outcome names of the clicked cell and says whether it took one (null: no play).
export function pickOutcomes(picker) {
  outcomePicker = picker;
  if (viewport) viewport.classList.toggle('picking', Boolean(picker));
}

// Fit the drawing to its viewport again (it changed size), if one is shown.
export function refit(readableOnly = true) {
  if (svg) { sizeViewport(); fit(readableOnly); }
}
