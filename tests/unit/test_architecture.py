"""The package layering, read from the sources (ast, nothing imported):

    multilift_msgs <- multilift_sim <- multilift_control <- multilift_tools <- multilift_learning

- no cycle between packages;
- every package imported by a package's code is declared in its package.xml (`<depend>` or
  `<exec_depend>`), third-party modules by their rosdep key (THIRD_PARTY below);
- the pure core (every module of multilift_sim and multilift_control outside their `ros`
  sub-package) reaches neither rclpy nor a message package, directly or through the repo's own
  modules (transitively, function-level imports included);
- and, run for real, a headless run without a bag loads no rclpy.

Imports are every `import` / `from ... import` anywhere in a module (in functions too; those
under `if TYPE_CHECKING:` count for the declarations but load nothing at run time, so not for
the core's purity) and string constants naming a repo module (what `importlib.import_module`
gets).
"""
from __future__ import annotations

import ast
import sys
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

from conftest import ROOT

SRC = ROOT / 'ros_ws' / 'src'
CORE_PACKAGES = ('multilift_sim', 'multilift_control')  # pure outside their `ros` sub-package
ADAPTER_SUBPACKAGE = 'ros'

# import name -> rosdep key of the package that provides it
THIRD_PARTY = {
    'numpy': 'python3-numpy', 'scipy': 'python3-scipy', 'yaml': 'python3-yaml',
    'matplotlib': 'python3-matplotlib', 'mpl_toolkits': 'python3-matplotlib',
    'PIL': 'python3-pil', 'mcap': 'python3-mcap', 'mcap_ros2': 'python3-mcap-ros2-support',
    'rosbags': 'python3-rosbags', 'foxglove': 'python3-foxglove-sdk', 'dask': 'python3-dask',
    'websockets': 'python3-websockets', 'pytest': 'python3-pytest',
    'distributed': 'python3-distributed', 'pyarrow': 'python3-pyarrow',
    'pandas': 'python3-pandas', 'psutil': 'python3-psutil', 'jinja2': 'python3-jinja2',
    'numba': 'python3-numba',
    'zstandard': 'python3-zstandard', 'tqdm': 'python3-tqdm', 'lark': 'python3-lark',
    'gymnasium': 'python3-gymnasium', 'pettingzoo': 'python3-pettingzoo',
    'stable_baselines3': 'python3-stable-baselines3',
}
# ROS packages imported by their own name that are the ROS runtime (not messages)
ROS_RUNTIME = frozenset({'rclpy', 'rosidl_runtime_py', 'rpyutils', 'rosbag2_py'})


def is_message_package(name: str) -> bool:
    """A ROS interface package: its Python module is generated message code."""
    return name.endswith(('_msgs', '_interfaces', '_srvs')) or name == 'builtin_interfaces'


def reaches_ros(name: str) -> bool:
    return name in ROS_RUNTIME or is_message_package(name)


@dataclass
class Module:
    name: str                      # dotted, e.g. multilift_sim.ros.common
    package: str                   # the ament package it belongs to
    path: Path
    imports: set[str] = field(default_factory=set)          # dotted names, absolute
    runtime_imports: set[str] = field(default_factory=set)  # without TYPE_CHECKING ones


@dataclass
class Workspace:
    declared: dict[str, set[str]]  # package -> keys of <depend>/<exec_depend>
    modules: dict[str, Module]

    @property
    def packages(self) -> set[str]:
        return set(self.declared)


def _declared(package_xml: Path) -> set[str]:
    root = ET.parse(package_xml).getroot()
    return {e.text.strip() for tag in ('depend', 'exec_depend') for e in root.iter(tag)
            if e.text}


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == 'TYPE_CHECKING') or (
        isinstance(test, ast.Attribute) and test.attr == 'TYPE_CHECKING')


def _imports(module: Module, tree: ast.Module, repo_modules: set[str]) -> None:
    """Fill module.imports / runtime_imports from the tree."""
    is_init = module.path.name == '__init__.py'
    base = module.name.split('.') if is_init else module.name.split('.')[:-1]

    def visit(node: ast.AST, typing_only: bool) -> None:
        found: list[str] = []
        if isinstance(node, ast.Import):
            found = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                parent = base[:len(base) - node.level + 1]
                stem = '.'.join(parent + ([node.module] if node.module else []))
            else:
                stem = node.module or ''
            found = [stem] + [f'{stem}.{alias.name}' for alias in node.names
                              if f'{stem}.{alias.name}' in repo_modules]
        elif isinstance(node, ast.Constant) and isinstance(node.value, str):
            if '.' in node.value and node.value in repo_modules:
                found = [node.value]  # importlib.import_module('multilift_x.y')
        for name in found:
            module.imports.add(name)
            if not typing_only:
                module.runtime_imports.add(name)
        for child in ast.iter_child_nodes(node):
            visit(child, typing_only or (isinstance(node, ast.If)
                                         and _is_type_checking(node.test)
                                         and child in node.body))

    visit(tree, False)


def load_workspace(src: Path) -> Workspace:
    """Every ament package under `src` with its declared dependencies and Python modules
    (`src/<pkg>/<pkg>/**.py`)."""
    declared: dict[str, set[str]] = {}
    files: dict[str, tuple[str, Path]] = {}
    for xml in sorted(src.glob('*/package.xml')):
        package = xml.parent.name
        declared[package] = _declared(xml)
        code = xml.parent / package
        for path in sorted(code.rglob('*.py')):
            parts = path.relative_to(xml.parent).with_suffix('').parts
            name = '.'.join(parts[:-1] if parts[-1] == '__init__' else parts)
            files[name] = (package, path)
    modules = {name: Module(name, package, path) for name, (package, path) in files.items()}
    for module in modules.values():
        _imports(module, ast.parse(module.path.read_text(), str(module.path)), set(modules))
    return Workspace(declared, modules)


def _top(name: str) -> str:
    return name.split('.')[0]


def _repo_targets(name: str, modules: dict[str, Module]) -> list[str]:
    """The repo modules an import of `name` executes: the module and its parent packages."""
    parts = name.split('.')
    return [m for m in ('.'.join(parts[:k]) for k in range(1, len(parts) + 1)) if m in modules]


def package_cycles(ws: Workspace) -> list[list[str]]:
    """Every elementary cycle of the package graph, as [a, b, ..., a] (one per rotation)."""
    edges = {p: sorted({_top(i) for m in ws.modules.values() if m.package == p
                        for i in m.imports if _top(i) in ws.packages and _top(i) != p})
             for p in ws.packages}
    cycles = []

    def walk(path: list[str]) -> None:
        for nxt in edges.get(path[-1], []):
            if nxt == path[0]:
                cycles.append(path + [nxt])
            elif nxt not in path and nxt > path[0]:
                walk(path + [nxt])

    for start in sorted(edges):
        walk([start])
    return cycles


def undeclared(ws: Workspace) -> list[str]:
    """'module imports X (needs <exec_depend>key</exec_depend> in pkg/package.xml)' lines."""
    stdlib = set(sys.stdlib_module_names) | {'__future__'}
    problems = []
    for module in ws.modules.values():
        keys: dict[str, str] = {}
        for name in sorted(module.imports):
            top = _top(name)
            if top in stdlib or top == module.package or not top:
                continue
            keys.setdefault(THIRD_PARTY.get(top, top), name)  # ROS packages: key = import name
        for key, name in sorted(keys.items()):
            if key not in ws.declared[module.package]:
                problems.append(f'{module.name} imports {name}: {module.package}/package.xml '
                                f'does not declare <exec_depend>{key}</exec_depend>')
    return problems


def is_core(module: Module) -> bool:
    parts = module.name.split('.')
    return module.package in CORE_PACKAGES and (len(parts) < 2
                                                  or parts[1] != ADAPTER_SUBPACKAGE)


def impure_core(ws: Workspace) -> list[str]:
    """Core modules that load rclpy or a message package, with the chain of imports."""
    problems = []
    for start in sorted(m for m, module in ws.modules.items() if is_core(module)):
        chain_to: dict[str, list[str]] = {start: [start]}
        queue = [start]
        while queue:
            current = queue.pop(0)
            for name in sorted(ws.modules[current].runtime_imports):
                if reaches_ros(_top(name)):
                    problems.append(' -> '.join(chain_to[current] + [name]))
                    queue = []
                    break
                for target in _repo_targets(name, ws.modules):
                    if target not in chain_to:
                        chain_to[target] = chain_to[current] + [target]
                        queue.append(target)
    return problems


# -- the repository --------------------------------------------------------------------------

WORKSPACE = load_workspace(SRC)


def test_the_workspace_is_read():
    assert WORKSPACE.packages >= {'multilift_msgs', 'multilift_sim', 'multilift_control',
                                  'multilift_tools', 'multilift_learning'}
    assert 'multilift_sim.ros.common' in WORKSPACE.modules
    assert 'rclpy' in WORKSPACE.modules['multilift_sim.ros.common'].imports


def test_no_cycle_between_packages():
    assert package_cycles(WORKSPACE) == []


def test_every_import_is_declared_in_package_xml():
    assert undeclared(WORKSPACE) == []


def test_the_core_reaches_no_rclpy_and_no_message_type():
    assert impure_core(WORKSPACE) == []


def test_packages_import_one_way():
    order = ['multilift_msgs', 'multilift_sim', 'multilift_control', 'multilift_tools',
             'multilift_learning']
    for module in WORKSPACE.modules.values():
        for name in module.imports:
            if _top(name) in order:
                assert order.index(_top(name)) <= order.index(module.package), (
                    f'{module.name} imports {name} (against the layering {" <- ".join(order)})')


# -- the checker can fail ----------------------------------------------------------------------

def _package(src: Path, name: str, depends: list[str], modules: dict[str, str]) -> None:
    root = src / name
    (root / name).mkdir(parents=True)
    (root / 'package.xml').write_text(
        '<package format="3"><name>' + name + '</name>'
        + ''.join(f'<exec_depend>{d}</exec_depend>' for d in depends) + '</package>')
    for rel, text in modules.items():
        path = root / name / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)


def test_the_checker_reports_a_cycle_an_undeclared_import_and_an_impure_core(tmp_path):
    _package(tmp_path, 'multilift_sim', ['python3-numpy'], {
        '__init__.py': '',
        'physics.py': 'import numpy as np\nfrom .helpers import g\n',
        'helpers.py': 'def g():\n    from multilift_sim.ros import common\n',
        'ros/__init__.py': '',
        'ros/common.py': 'import rclpy\n',
        'state.py': 'from geometry_msgs.msg import Point\n',
        'clean.py': 'from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n'
                    '    import rclpy\nimport math\n',
        'plots.py': 'def f():\n    import importlib\n'
                    "    return importlib.import_module('multilift_control.laws')\n",
    })
    _package(tmp_path, 'multilift_control', ['multilift_sim', 'python3-scipy'], {
        '__init__.py': '',
        'laws.py': 'import scipy\nimport yaml\nfrom multilift_sim import physics\n'})
    ws = load_workspace(tmp_path)
    assert package_cycles(ws) == [['multilift_control', 'multilift_sim', 'multilift_control']]
    missing = undeclared(ws)
    assert any('multilift_sim.ros.common imports rclpy' in p for p in missing)
    assert any('geometry_msgs.msg' in p and '<exec_depend>geometry_msgs<' in p
               for p in missing)
    assert any('laws imports yaml' in p and 'python3-yaml' in p for p in missing)
    assert any("multilift_sim.plots imports multilift_control.laws" in p for p in missing)
    assert not any('numpy' in p or 'scipy' in p or 'math' in p for p in missing)
    impure = impure_core(ws)
    # through a relative import and a function-level import, then a message package's rclpy
    assert ('multilift_sim.physics -> multilift_sim.helpers -> multilift_sim.ros.common -> '
            'rclpy') in impure
    assert ('multilift_control.laws -> multilift_sim.physics -> multilift_sim.helpers -> '
            'multilift_sim.ros.common -> rclpy') in impure
    assert 'multilift_sim.state -> geometry_msgs.msg' in impure  # a message type, directly
    assert not any(p.startswith(('multilift_sim.clean ', 'multilift_sim.ros')) for p in impure)
