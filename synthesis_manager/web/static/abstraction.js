// The chosen robot's abstraction drawn beside the form: its control-mode graph (which mode
// can change to which) and its action-precondition graph (what each action needs first),
// from the system's choices (GET /api/systems/{name}), with the task's path highlighted:
// from the initial control mode through the modes the goals need, and the goals with what
// they need that is not completed yet. A capability system (CNU) has no control modes and
// its preconditions are clauses: the page says so and lists them.
import { $, element } from './dom.js';

const SVG = 'http://www.w3.org/2000/svg';
const MIN_NODE_W = 118;
const CHAR_W = 7.3;    // px per character of the 12 px monospace labels (style.css)
const NODE_H = 24;
let NODE_W = MIN_NODE_W;  // wide enough for the system's longest name ("footstep_execution")

function svgElement(tag, attributes = {}, ...children) {
  const node = document.createElementNS(SVG, tag);
  for (const [name, value] of Object.entries(attributes)) node.setAttribute(name, String(value));
  for (const child of children) node.append(child);
  return node;
}

function arrowMarker(id) {
  return svgElement('defs', {}, svgElement('marker', { id, viewBox: '0 0 10 10', refX: 9, refY: 5, markerWidth: 7,
    markerHeight: 7, orient: 'auto-start-reverse' }, svgElement('path', { d: 'M0,0 L10,5 L0,10 z' })));
}

// Modes on the path from ``start`` through each of ``targets`` (shortest changes between
// them): {modes: Set, edges: Set of 'a->b', visits: the modes in the order the robot is in
// them, each once per visit}.
export function modePath(modes, start, targets) {
  const next = new Map(modes.map((m) => [m.name, m.next]));
  const path = { modes: new Set(start ? [start] : []), edges: new Set(), visits: start ? [start] : [] };
  let here = start;
  for (const target of targets) {
    if (!here && next.has(target)) path.visits.push(target);
    if (!here || here === target || !next.has(target)) { here = here || target; continue; }
    const from = new Map([[here, null]]);
    const queue = [here];
    while (queue.length && !from.has(target)) {
      const mode = queue.shift();
      for (const other of next.get(mode) || []) {
        if (!from.has(other)) { from.set(other, mode); queue.push(other); }
      }
    }
    if (!from.has(target)) continue;  // unreachable: the goal check says why
    const route = [];
    for (let mode = target; from.get(mode) !== null; mode = from.get(mode)) {
      path.edges.add(`${from.get(mode)}->${mode}`);
      path.modes.add(mode);
      route.unshift(mode);
    }
    path.visits.push(...route);
    here = target;
  }
  return path;
}

function drawModes(modes, path) {
  const count = modes.length;
  const radius = 40 + 18 * count;
  const width = 2 * radius + NODE_W + 10;
  const height = 1.6 * radius + NODE_H + 8;  // an ellipse: the graph is wider than tall, as labels are
  const place = new Map(modes.map((m, i) => {
    const angle = -Math.PI / 2 + (2 * Math.PI * i) / count;
    return [m.name, { x: width / 2 + radius * Math.cos(angle), y: height / 2 + radius * 0.8 * Math.sin(angle) }];
  }));
  const svg = svgElement('svg', { id: 'mode-graph', viewBox: `0 0 ${width} ${height}`, width, height,
    role: 'img', 'aria-label': 'control-mode graph' }, arrowMarker('mode-arrow'));
  for (const mode of modes) {
    for (const other of mode.next) {
      if (other === mode.name || !place.has(other)) continue;
      const a = place.get(mode.name);
      const b = place.get(other);
      // Both directions of a pair are bent apart, each to its own side.
      const dx = b.x - a.x;
      const dy = b.y - a.y;
      const length = Math.hypot(dx, dy) || 1;
      const bend = 14;
      const cx = (a.x + b.x) / 2 - (dy / length) * bend;
      const cy = (a.y + b.y) / 2 + (dx / length) * bend;
      const shorten = (p, q) => {  // from p towards q, stop at the node's edge
        const ux = q.x - p.x;
        const uy = q.y - p.y;
        const t = Math.min(0.45, 1 / Math.max(Math.abs(ux) / (NODE_W / 2 + 4), Math.abs(uy) / (NODE_H / 2 + 4), 1e-6));
        return { x: p.x + ux * t, y: p.y + uy * t };
      };
      const from = shorten(a, { x: cx, y: cy });
      const to = shorten(b, { x: cx, y: cy });
      const id = `${mode.name}->${other}`;
      svg.append(svgElement('path', { id: `mode-edge:${id}`, class: `edge${path.edges.has(id) ? ' on-path' : ''}`,
        d: `M${from.x},${from.y} Q${cx},${cy} ${to.x},${to.y}`, 'marker-end': 'url(#mode-arrow)' }));
    }
  }
  for (const mode of modes) {
    const { x, y } = place.get(mode.name);
    svg.append(svgElement('g', { id: `mode:${mode.name}`, class: `node${path.modes.has(mode.name) ? ' on-path' : ''}` },
      svgElement('rect', { x: x - NODE_W / 2, y: y - NODE_H / 2, width: NODE_W, height: NODE_H, rx: 12 }),
      svgElement('text', { x, y: y + 4, 'text-anchor': 'middle' }, mode.name)));
  }
  return svg;
}

function drawPreconditions(actions, modeNames, needed, goals, completed) {
  const byName = new Map(actions.map((a) => [a.name, a]));
  const depth = new Map(modeNames.map((m) => [m, 0]));
  const depthOf = (name, seen = new Set()) => {
    if (depth.has(name)) return depth.get(name);
    if (seen.has(name) || !byName.has(name)) return 0;
    seen.add(name);
    const d = 1 + Math.max(-1, ...byName.get(name).preconditions.map((p) => depthOf(p, seen)));
    depth.set(name, d);
    return d;
  };
  actions.forEach((a) => depthOf(a.name));
  const used = new Set(actions.flatMap((a) => a.preconditions));
  const names = [...modeNames.filter((m) => used.has(m)), ...actions.map((a) => a.name)];
  const columns = [];
  for (const name of names) (columns[depth.get(name)] = columns[depth.get(name)] || []).push(name);
  const place = new Map();
  columns.forEach((column, c) => column.forEach((name, r) => place.set(name, { x: 6 + c * (NODE_W + 34), y: 6 + r * (NODE_H + 10) })));
  const width = 12 + columns.length * (NODE_W + 34);
  const height = 12 + Math.max(...columns.map((c) => c.length)) * (NODE_H + 10);
  const svg = svgElement('svg', { id: 'precondition-graph', viewBox: `0 0 ${width} ${height}`, width, height, role: 'img',
    'aria-label': 'action-precondition graph' }, arrowMarker('need-arrow'));
  for (const action of actions) {
    for (const need of action.preconditions) {
      if (!place.has(need)) continue;
      const a = place.get(need);
      const b = place.get(action.name);
      const [x1, y1, x2, y2] = [a.x + NODE_W, a.y + NODE_H / 2, b.x, b.y + NODE_H / 2];
      const on = needed.has(action.name) && needed.has(need);
      svg.append(svgElement('path', { id: `need:${need}->${action.name}`, class: `edge${on ? ' on-path' : ''}`,
        d: `M${x1},${y1} C${x1 + 20},${y1} ${x2 - 20},${y2} ${x2 - 2},${y2}`, 'marker-end': 'url(#need-arrow)' }));
    }
  }
  for (const name of names) {
    const { x, y } = place.get(name);
    const classes = ['node', modeNames.includes(name) ? 'mode' : 'action', needed.has(name) ? 'on-path' : '',
      goals.includes(name) ? 'goal' : '', completed.has(name) ? 'done' : ''].filter(Boolean).join(' ');
    svg.append(svgElement('g', { id: `need:${name}`, class: classes },
      svgElement('rect', { x, y, width: NODE_W, height: NODE_H, rx: modeNames.includes(name) ? 12 : 3 }),
      svgElement('text', { x: x + NODE_W / 2, y: y + 16, 'text-anchor': 'middle' }, name)));
  }
  return svg;
}

// What the goals need that is not done yet: the goals and their preconditions, transitively.
function neededFor(goals, actions, completed) {
  const byName = new Map(actions.map((a) => [a.name, a]));
  const needed = new Set();
  const visit = (name) => {
    if (needed.has(name) || completed.has(name)) return;
    needed.add(name);
    (byName.get(name) ? byName.get(name).preconditions : []).forEach(visit);
  };
  goals.forEach(visit);
  return needed;
}

// Draw ``choices`` (the system's modes and actions) for ``request`` (initial conditions, goals).
export function showAbstraction(choices, request) {
  if (!choices) return;
  $('abstraction-system').textContent = choices.system;
  const modes = choices.control_modes;
  const modeNames = modes.map((m) => m.name);
  const goals = request.goals.filter((g) => !g.startsWith('!'));
  if (choices.capability_graph) {
    showCapabilityGraph(choices.capability_graph, request, request.goals);
    return;
  }
  NODE_W = Math.max(MIN_NODE_W, Math.ceil(16 + CHAR_W * Math.max(...[...modeNames, ...choices.actions.map((a) => a.name)]
    .map((name) => name.length))));
  const completed = new Set(request.initial_conditions);
  const start = request.initial_conditions.find((c) => modeNames.includes(c)) || null;
  const byName = new Map(choices.actions.map((a) => [a.name, a]));
  const targets = goals.flatMap((g) => (modeNames.includes(g) ? [g]
    : (byName.get(g) ? byName.get(g).preconditions.filter((p) => modeNames.includes(p)) : [])));
  const path = modePath(modes, start, targets);
  const needed = neededFor(goals, choices.actions, new Set([...completed].filter((c) => !modeNames.includes(c))));
  $('abstraction-graphs').replaceChildren(
    element('figure', {}, drawModes(modes, path), element('figcaption', { text: 'Control modes: an arrow is a mode change' })),
    element('figure', {}, drawPreconditions(choices.actions, modeNames, needed, goals, completed),
      element('figcaption', { text: 'Preconditions: an arrow from what an action needs to the action' })));
  $('abstraction-path').textContent = goals.length
    ? `Task path: ${path.visits.join(' → ')} (modes); goals ${goals.join(', ')}`
    : 'Add goals to see the task\'s path.';
}

// The capability graph's nodes ('cap:NAME', 'prop:NAME', 'sensor:NAME') and edges (needs: a
// proposition to the capability whose precondition reads it; makes: a capability to what an
// outcome of it sets; reports: a capability to the sensor its outcome reports).
function capabilityEdges(graph, sensors) {
  const edges = [];
  for (const c of graph.capabilities) {
    for (const need of c.needs) edges.push({ from: `prop:${need.name}`, to: `cap:${c.name}`, kind: 'needs', negated: need.negated, label: need.negated ? 'not' : '' });
    for (const make of c.makes) edges.push({ from: `cap:${c.name}`, to: `prop:${make.name}`, kind: 'makes', negated: make.negated, label: `${make.outcome}${make.negated ? ': not' : ''}` });
  }
  for (const sensor of sensors) {
    for (const name of sensor.reported_by) edges.push({ from: `cap:${name}`, to: `sensor:${sensor.name}`, kind: 'reports', negated: false, label: 'reports' });
  }
  return edges;
}

// Columns by the shortest way from what needs nothing (back edges, such as a charge that makes
// its own precondition false again, go leftwards).
function capabilityLevels(nodes, edges) {
  const level = new Map();
  const targets = new Set(edges.map((e) => e.to));
  const queue = nodes.filter((n) => !targets.has(n));
  queue.forEach((n) => level.set(n, 0));
  while (queue.length) {
    const node = queue.shift();
    for (const edge of edges.filter((e) => e.from === node && !level.has(e.to))) {
      level.set(edge.to, level.get(node) + 1);
      queue.push(edge.to);
    }
  }
  nodes.filter((n) => !level.has(n)).forEach((n) => level.set(n, 0));  // a cycle nothing enters
  return level;
}

// What the goals need: the propositions they name, the capabilities that set them, what those
// need that does not hold at the start, and so on back.
function capabilityPath(graph, goals, holding) {
  const on = { nodes: new Set(), edges: new Set() };
  const visit = (name, negated) => {
    const id = `prop:${name}`;
    const key = `${id}:${negated}`;
    if (on.nodes.has(key)) return;
    on.nodes.add(key);
    on.nodes.add(id);
    if (!negated && holding.has(name)) return;
    for (const c of graph.capabilities.filter((capability) => capability.makes.some((m) => m.name === name && m.negated === negated))) {
      on.edges.add(`cap:${c.name}->${id}`);
      if (on.nodes.has(`cap:${c.name}`)) continue;
      on.nodes.add(`cap:${c.name}`);
      for (const need of c.needs) {
        on.edges.add(`prop:${need.name}->cap:${c.name}`);
        visit(need.name, need.negated);
      }
    }
  };
  goals.forEach((goal) => visit(goal.replace(/^!/, ''), goal.startsWith('!')));
  return on;
}

function showCapabilityGraph(graph, request, goals) {
  const sensors = graph.sensors;
  const edges = capabilityEdges(graph, sensors);
  const names = [...graph.capabilities.map((c) => `cap:${c.name}`),
    ...new Set(edges.filter((e) => e.from.startsWith('prop:')).map((e) => e.from)
      .concat(edges.filter((e) => e.to.startsWith('prop:')).map((e) => e.to))),
    ...sensors.map((s) => `sensor:${s.name}`)];
  const nodes = [...new Set(names)];
  const label = (id) => id.split(':').slice(1).join(':');
  NODE_W = Math.max(MIN_NODE_W, Math.ceil(16 + CHAR_W * Math.max(...nodes.map((n) => label(n).length))));
  // Top to bottom, a row per level (the panel is wider than tall, the graph deeper than wide).
  const level = capabilityLevels(nodes, edges);
  const rows = [];
  for (const node of nodes) (rows[level.get(node)] = rows[level.get(node)] || []).push(node);
  const COLUMN_W = NODE_W + 40;
  const ROW_H = NODE_H + 36;
  const widest = Math.max(...rows.map((row) => row.length));
  const width = 12 + widest * COLUMN_W + 60;  // room on the right for the edges that go back up
  const height = 12 + rows.length * ROW_H;
  const place = new Map();
  rows.forEach((row, r) => row.forEach((node, c) => place.set(node, {
    x: 6 + (widest - row.length) * COLUMN_W / 2 + c * COLUMN_W, y: 6 + r * ROW_H })));
  const holding = new Set([...graph.initially, ...request.initial_conditions]);
  const on = capabilityPath(graph, goals, holding);
  const svg = svgElement('svg', { id: 'capability-graph', viewBox: `0 0 ${width} ${height}`, width, height, role: 'img',
    'aria-label': 'capability graph' }, arrowMarker('capability-arrow'));
  const pairs = new Map();  // edges between the same two nodes are drawn apart
  edges.forEach((edge) => {
    const pair = [edge.from, edge.to].sort().join('|');
    pairs.set(pair, [...(pairs.get(pair) || []), edge]);
  });
  for (const edge of edges) {
    const a = place.get(edge.from);
    const b = place.get(edge.to);
    const siblings = pairs.get([edge.from, edge.to].sort().join('|'));
    const spread = (siblings.indexOf(edge) - (siblings.length - 1) / 2) * 26;
    const back = b.y <= a.y;
    let d;
    let labelAt;
    if (back) {  // up the right side
      const [x1, y1, x2, y2] = [a.x + NODE_W, a.y + NODE_H / 2, b.x + NODE_W, b.y + NODE_H / 2];
      const out = Math.max(x1, x2) + 40 + spread;
      d = `M${x1},${y1} C${out},${y1} ${out},${y2} ${x2 + 2},${y2}`;
      labelAt = { x: out - 4, y: (y1 + y2) / 2 };
    } else {
      const [x1, y1, x2, y2] = [a.x + NODE_W / 2 + spread, a.y + NODE_H, b.x + NODE_W / 2 + spread, b.y];
      d = `M${x1},${y1} C${x1},${y1 + 18} ${x2},${y2 - 18} ${x2},${y2 - 2}`;
      // a label beside its edge, on the left of the left one of a pair
      labelAt = { x: (x1 + x2) / 2 + (spread < 0 ? -6 : 6), y: (y1 + y2) / 2 + 4, anchor: spread < 0 ? 'end' : 'start' };
    }
    const id = `${edge.from}->${edge.to}`;
    const classes = ['edge', edge.kind, edge.negated ? 'negated' : '', on.edges.has(id) ? 'on-path' : ''].filter(Boolean).join(' ');
    svg.append(svgElement('path', { id: `capability-edge:${id}:${edge.label}`, class: classes, d,
      'marker-end': 'url(#capability-arrow)' }));
    if (edge.label) {
      svg.append(svgElement('text', { class: 'edge-label', x: labelAt.x, y: labelAt.y, 'text-anchor': labelAt.anchor || 'start' },
        edge.label));
    }
  }
  for (const node of nodes) {
    const { x, y } = place.get(node);
    const kind = node.split(':')[0];
    const name = label(node);
    const classes = ['node', { cap: 'capability', prop: 'proposition', sensor: 'sensor' }[kind],
      on.nodes.has(node) ? 'on-path' : '', kind === 'prop' && goals.some((g) => g.replace(/^!/, '') === name) ? 'goal' : '',
      kind === 'prop' && holding.has(name) ? 'done' : ''].filter(Boolean).join(' ');
    svg.append(svgElement('g', { id: `capability-${kind}:${name}`, class: classes },
      svgElement('rect', { x, y, width: NODE_W, height: NODE_H, rx: kind === 'cap' ? 3 : 12 }),
      svgElement('text', { x: x + NODE_W / 2, y: y + 16, 'text-anchor': 'middle' }, name)));
  }
  $('abstraction-graphs').replaceChildren(element('figure', {}, svg, element('figcaption', {
    text: 'Capabilities (squared) and the propositions (rounded) their preconditions read and their outcomes set; ' +
      'a sensor is reported by a capability\'s outcome' })));
  const path = graph.capabilities.map((c) => c.name).filter((c) => on.nodes.has(`cap:${c}`))
    .sort((a, b) => level.get(`cap:${a}`) - level.get(`cap:${b}`));
  $('abstraction-path').textContent = goals.length
    ? `Task path: ${path.join(' → ') || 'nothing to run'} (capabilities); goals ${request.goals.join(', ')}`
    : 'Add goals to see the task\'s path.';
}
