"""The state machine's picture as SVG: Graphviz' ``dot`` where it is installed, else Graphviz
compiled to WebAssembly (``@viz-js/viz``, put into ``build/graphviz-wasm`` by ``make setup``
from npm) run with Node.js. Why this design: docs/gui.md, "Drawing without Graphviz".

PNG is made by ``dot`` only: without it the page rasterizes the SVG it shows (the browser has
fonts; a bare server may have none), so ``png_in_page()`` tells the page to.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from pathlib import Path

from sm_generation.export import RenderError, to_dot

# The npm install of `make setup`; BEHAVIOR_SYNTHESIS_GRAPHVIZ_WASM names another one.
DEFAULT_WASM_PREFIX = Path(__file__).resolve().parents[2] / 'build' / 'graphviz-wasm'
RENDER_SCRIPT = Path(__file__).with_name('render_dot.mjs')
RENDER_TIMEOUT_S = 60


# The GUI's drawing shows no text smaller than 11 px (drawing.js) and fits the paper's machine
# in a 1280x720 window: with the class names at 12 pt instead of 11 (and a container's inner
# states' at 12 instead of 10) the drawing may shrink to 11/12 of its natural size.
MIN_POINT_SIZE = 12
_POINT_SIZE = re.compile(r'POINT-SIZE="(\d+(?:\.\d+)?)"')


def picture_dot(machine) -> str:
    """The DOT text the GUI draws and offers (``sm_generation.export.to_dot``), its smallest
    labels raised to MIN_POINT_SIZE so that Graphviz lays the boxes out around them."""
    return _POINT_SIZE.sub(lambda m: f'POINT-SIZE="{max(float(m.group(1)), MIN_POINT_SIZE):g}"', to_dot(machine))


def wasm_package() -> Path:
    """The folder of the installed ``@viz-js/viz`` package (it may be missing)."""
    prefix = Path(os.environ.get('BEHAVIOR_SYNTHESIS_GRAPHVIZ_WASM') or DEFAULT_WASM_PREFIX)
    return prefix / 'node_modules' / '@viz-js' / 'viz'


def png_in_page() -> bool:
    """Whether the page must make the PNG itself (no ``dot`` here to make it)."""
    return shutil.which('dot') is None


def render_svg(dot_text: str) -> bytes:
    """``dot_text`` laid out as SVG, by ``dot`` if installed, else by the WebAssembly Graphviz."""
    program = shutil.which('dot')
    if program:
        return _run([program, '-Tsvg'], dot_text, 'dot')
    node, package = shutil.which('node'), wasm_package()
    if node is None or not (package / 'dist' / 'viz.js').is_file():
        missing = 'Node.js (node)' if node is None else f'the WebAssembly Graphviz in {package.parent.parent.parent}'
        raise RenderError(f"no program can draw: Graphviz' 'dot' is not installed and {missing} is missing "
                          '(`make setup` installs @viz-js/viz with npm; or apt-get install graphviz)',
                          'node' if node is None else str(package))
    return _run([node, str(RENDER_SCRIPT), str(package)], dot_text, 'the WebAssembly Graphviz')


def render_png(dot_text: str) -> bytes:
    program = shutil.which('dot')
    if program is None:
        raise RenderError("Graphviz' 'dot' is not installed: the page makes the PNG from its drawing "
                          '(the Picture (PNG) download on the result page)', 'dot')
    return _run([program, '-Tpng'], dot_text, 'dot')


def _run(command: list[str], dot_text: str, who: str) -> bytes:
    result = subprocess.run(command, input=dot_text.encode(), capture_output=True, check=False,
                            timeout=RENDER_TIMEOUT_S)
    if result.returncode != 0:
        raise RenderError(f'{who} failed: {result.stderr.decode(errors="replace").strip()}', command[0])
    return result.stdout
