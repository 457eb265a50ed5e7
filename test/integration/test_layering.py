"""Imports point one way: the ROS-free cores never import the shell, and packages form a DAG.

Read with ``ast`` (nothing is imported), so a forbidden import is found even inside a
function or behind a try. Every import counts, function-local ones included: a cycle cannot
be hidden by importing late.

A Python package is the files reachable from its folder through ``__init__.py`` files. A ROS
package folder (a directory with a ``package.xml``, e.g. the FlexBE state package in
``atlas_sim/flexbe/``, which no ``__init__.py`` joins to ``atlas_sim``) is a package of its own:
it may import flexbe_core and rclpy, and no core may import it. Every Python file in the
packages' folders belongs to exactly one of them, so none escapes the checks.
"""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
CORES = ('respec', 'ltl_specification', 'ltl_synthesizer', 'sm_generation', 'atlas_sim')
SHELL = 'synthesis_manager'
PACKAGES = (*CORES, SHELL)
# What no core may import: the shell, ROS, the interface package, the web stack, FlexBE.
SHELL_ONLY = ('synthesis_manager', 'rclpy', 'rcl_interfaces', 'action_msgs', 'synthesis_msgs',
              'domain_coordinator', 'fastapi', 'starlette', 'uvicorn', 'flexbe_core')


def ros_package_folders(root: Path = ROOT) -> list[Path]:
    """Directories with a package.xml inside the Python packages (not the repository's own)."""
    return sorted(path.parent for package in PACKAGES for path in (root / package).rglob('package.xml'))


def package_modules(folder: Path) -> list[Path]:
    """The Python files of the package in ``folder``: those reached through ``__init__.py`` files."""
    if not (folder / '__init__.py').exists():
        return []
    files = sorted(folder.glob('*.py'))
    for child in sorted(path for path in folder.iterdir() if path.is_dir()):
        files += package_modules(child)
    return files


def packages(root: Path = ROOT) -> dict[str, list[Path]]:
    """Every package (a Python package or a ROS package folder) and its Python files."""
    found = {package: package_modules(root / package) for package in PACKAGES}
    for folder in ros_package_folders(root):
        found[folder.relative_to(root).as_posix()] = sorted(folder.rglob('*.py'))
    return found


def imported_modules(path: Path, root: Path) -> list[tuple[str, int]]:
    """Every module ``path`` imports (relative imports resolved), with its line number."""
    tree = ast.parse(path.read_text(), filename=str(path))
    here = list(path.relative_to(root).with_suffix('').parts)
    if here[-1] == '__init__':
        here.pop()
    else:
        here = here[:-1]  # the package containing the module
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(alias.name, node.lineno) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = here[:len(here) - (node.level - 1)]
                module = '.'.join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ''
            found.append((module, node.lineno))
    return found


def ros_python_names(folder: Path) -> set[str]:
    """The top-level Python package names a ROS package folder provides."""
    return {child.name for child in folder.iterdir() if (child / '__init__.py').exists()}


def unowned_files(root: Path = ROOT) -> list[str]:
    """Python files in the packages' folders that belong to no package (no check would see them)."""
    owned = {path for files in packages(root).values() for path in files}
    return sorted(path.relative_to(root).as_posix() for package in PACKAGES
                  for path in (root / package).rglob('*.py') if path not in owned)


def import_graph(root: Path = ROOT):
    """(package -> {imported project package: first 'file:line'}, forbidden imports of the cores)."""
    ros_folders = ros_package_folders(root)
    ros_names = {name: folder.relative_to(root).as_posix()
                 for folder in ros_folders for name in ros_python_names(folder)}
    graph: dict[str, dict[str, str]] = {}
    forbidden = []
    for source, files in packages(root).items():
        edges = graph.setdefault(source, {})
        for path in files:
            for module, line in imported_modules(path, root):
                where = f'{path.relative_to(root).as_posix()}:{line}'
                target = _target(module, ros_folders, ros_names, root)
                if target is not None and target != source:
                    edges.setdefault(target, where)
                into_ros_folder = target is not None and target not in PACKAGES
                if source in CORES and (module.split('.')[0] in SHELL_ONLY or into_ros_folder):
                    forbidden.append(f'{where}: {source} imports {module}')
    return graph, forbidden


def _target(module: str, ros_folders, ros_names: dict[str, str], root: Path) -> str | None:
    """The project package ``module`` belongs to, or None for third-party modules."""
    parts = module.split('.')
    if parts[0] in ros_names:
        return ros_names[parts[0]]
    for folder in ros_folders:  # imported by its path inside the package, e.g. atlas_sim.flexbe_x
        dotted = folder.relative_to(root).as_posix().replace('/', '.')
        if module == dotted or module.startswith(dotted + '.'):
            return folder.relative_to(root).as_posix()
    return parts[0] if parts[0] in PACKAGES else None


def find_cycle(graph: dict[str, dict[str, str]]) -> list[str]:
    """One cycle of the package graph as [a, b, ..., a], or [] when it is a DAG."""
    state: dict[str, str] = {}

    def visit(package: str, path: list[str]) -> list[str]:
        state[package] = 'open'
        for successor in sorted(graph.get(package, {})):
            if state.get(successor) == 'open':  # on the current path: a cycle
                return path[path.index(successor):] + [successor]
            if successor not in state:
                cycle = visit(successor, path + [successor])
                if cycle:
                    return cycle
        state[package] = 'done'
        return []

    for package in sorted(graph):
        if package not in state:
            cycle = visit(package, [package])
            if cycle:
                return cycle
    return []


def test_every_python_file_belongs_to_one_package():
    assert unowned_files() == []
    assert {'atlas_sim/flexbe/atlas_sim_flexbe_states', 'atlas_sim/flexbe/atlas_sim_flexbe_behaviors'} <= set(packages())


def test_cores_import_neither_the_shell_nor_ros_nor_the_web_stack():
    _graph, forbidden = import_graph()
    assert forbidden == []


def test_packages_import_each_other_without_cycles():
    graph, _forbidden = import_graph()
    cycle = find_cycle(graph)
    assert cycle == [], ' -> '.join(cycle) + ': ' + ', '.join(
        graph[a][b] for a, b in zip(cycle, cycle[1:]))


def test_the_cores_sit_below_the_shell():
    graph, _forbidden = import_graph()
    assert set(graph[SHELL]) >= {'ltl_specification', 'ltl_synthesizer', 'sm_generation', 'atlas_sim'}
    assert set(graph['respec']) == set()
    assert SHELL not in {target for core in CORES for target in graph[core]}


# --- modules: no import circle between two files either ----------------------------------

def module_name(path: Path, root: Path) -> str:
    """The dotted module a source file is (a package's ``__init__.py`` is the package)."""
    parts = list(path.relative_to(root).with_suffix('').parts)
    if parts[-1] == '__init__':
        parts.pop()
    return '.'.join(parts)


def module_graph(root: Path = ROOT) -> dict[str, dict[str, str]]:
    """module -> {project module it imports: first 'file:line'}, function-local imports included.

    ``from a.b import c`` is an edge to ``a.b.c`` when that is a module, else to ``a.b``.
    """
    paths = {module_name(path, root): path for package in PACKAGES for path in (root / package).rglob('*.py')}
    graph: dict[str, dict[str, str]] = {}
    for name, path in sorted(paths.items()):
        edges = graph.setdefault(name, {})
        tree = ast.parse(path.read_text(), filename=str(path))
        imported = dict(imported_modules(path, root))
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                base = next((m for m, line in imported.items() if line == node.lineno), None)
                for alias in node.names:
                    if base is not None and f'{base}.{alias.name}' in paths:
                        imported.setdefault(f'{base}.{alias.name}', node.lineno)
        for target, line in imported.items():
            if target in paths and target != name and not name.startswith(target + '.'):
                edges.setdefault(target, f'{path.relative_to(root).as_posix()}:{line}')
    return graph


def test_modules_import_each_other_without_circles():
    graph = module_graph()
    cycle = find_cycle(graph)
    assert cycle == [], ' -> '.join(cycle) + ': ' + ', '.join(
        graph[a][b] for a, b in zip(cycle, cycle[1:]))


def test_checker_finds_a_circle_between_two_modules_of_one_package(tmp_path):
    root = _write(tmp_path, {
        'ltl_synthesizer/__init__.py': '',
        'ltl_synthesizer/cli.py': 'from ltl_synthesizer.serve import serve\n',
        'ltl_synthesizer/serve.py': 'def f():\n    from ltl_synthesizer import cli\n',
    })
    assert find_cycle(module_graph(root)) in (
        ['ltl_synthesizer.cli', 'ltl_synthesizer.serve', 'ltl_synthesizer.cli'],
        ['ltl_synthesizer.serve', 'ltl_synthesizer.cli', 'ltl_synthesizer.serve'])



def test_respec_parsing_modules_import_only_those_listed_before_them():
    """respec/parsing/__init__.py lists its modules in import order: each one imports only
    modules listed above it, and every module is listed."""
    package = ROOT / 'respec' / 'parsing'
    docstring = ast.get_docstring(ast.parse((package / '__init__.py').read_text()))
    listed = [line.split()[0] for line in docstring.split('Modules, each importing only those above it:')[1]
              .split('\n\n')[1].splitlines()]
    assert sorted(listed) == sorted(path.stem for path in package.glob('*.py') if path.stem != '__init__')
    later_imports = [f'{name}.py:{line} imports {module}'
                     for position, name in enumerate(listed)
                     for module, line in imported_modules(package / f'{name}.py', ROOT)
                     if module.startswith('respec.parsing')
                     and module.removeprefix('respec.parsing.').split('.')[0] not in listed[:position]]
    assert later_imports == []


# --- the checker itself, on small made-up trees ------------------------------------------

def _write(root: Path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return root


def test_checker_finds_a_cycle_hidden_in_a_function(tmp_path):
    root = _write(tmp_path, {
        'respec/__init__.py': '',
        'sm_generation/__init__.py': 'from respec import x\n',
        'respec/late.py': 'def f():\n    from sm_generation import y\n',
    })
    graph, _ = import_graph(root)
    assert find_cycle(graph) in (['respec', 'sm_generation', 'respec'], ['sm_generation', 'respec', 'sm_generation'])


def test_checker_reports_a_core_importing_rclpy_or_the_shell(tmp_path):
    root = _write(tmp_path, {
        'atlas_sim/__init__.py': '',
        'atlas_sim/node.py': 'import rclpy\n',
        'ltl_synthesizer/__init__.py': '',
        'ltl_synthesizer/cli.py': 'try:\n    from synthesis_manager.ros import env\nexcept ImportError:\n    pass\n',
        'synthesis_manager/__init__.py': 'import rclpy\nimport fastapi\n',
    })
    _, forbidden = import_graph(root)
    assert sorted(forbidden) == ['atlas_sim/node.py:1: atlas_sim imports rclpy',
                         'ltl_synthesizer/cli.py:2: ltl_synthesizer imports synthesis_manager.ros']


def test_checker_lets_a_ros_package_folder_import_flexbe_but_not_the_cores_import_it(tmp_path):
    root = _write(tmp_path, {
        'atlas_sim/__init__.py': '',
        'atlas_sim/flexbe/flexbe_states/package.xml': '<package/>',
        'atlas_sim/flexbe/flexbe_states/flexbe_states/__init__.py': '',
        'atlas_sim/flexbe/flexbe_states/flexbe_states/mode_state.py':
            'from flexbe_core import EventState\nimport rclpy\nfrom atlas_sim import executor\n',
        'atlas_sim/executor.py': 'from flexbe_states.mode_state import ModeState\n',
    })
    graph, forbidden = import_graph(root)
    assert forbidden == ['atlas_sim/executor.py:1: atlas_sim imports flexbe_states.mode_state']
    assert graph['atlas_sim/flexbe/flexbe_states'] == {'atlas_sim': 'atlas_sim/flexbe/flexbe_states/flexbe_states/mode_state.py:3'}


def test_a_folder_without_init_is_no_part_of_the_package_around_it(tmp_path):
    root = _write(tmp_path, {
        'atlas_sim/__init__.py': '',
        'atlas_sim/flexbe/flexbe_states/package.xml': '<package/>',
        'atlas_sim/flexbe/flexbe_states/flexbe_states/__init__.py': 'import rclpy\n',
        'atlas_sim/scripts/tool.py': 'import rclpy\n',
    })
    assert {name: [p.relative_to(root).as_posix() for p in files] for name, files in packages(root).items()
            if files} == {'atlas_sim': ['atlas_sim/__init__.py'],
                          'atlas_sim/flexbe/flexbe_states': ['atlas_sim/flexbe/flexbe_states/flexbe_states/__init__.py']}
    assert unowned_files(root) == ['atlas_sim/scripts/tool.py']
