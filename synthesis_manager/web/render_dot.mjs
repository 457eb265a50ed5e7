// Lay out DOT text (stdin) as SVG (stdout) with Graphviz compiled to WebAssembly (@viz-js/viz,
// installed by `make setup` from npm). Usage: node render_dot.mjs <path of @viz-js/viz's package>
// Run by synthesis_manager.web.picture when Graphviz' own `dot` is not installed.
import path from 'node:path';
import { pathToFileURL } from 'node:url';

const entry = pathToFileURL(path.join(process.argv[2], 'dist', 'viz.js')).href;
const { instance } = await import(entry);
let dot = '';
for await (const chunk of process.stdin) dot += chunk;
const result = (await instance()).render(dot, { format: 'svg' });
if (result.status !== 'success') {
  process.stderr.write(result.errors.map((error) => error.message).join('\n') + '\n');
  process.exit(1);
}
process.stdout.write(result.output);
