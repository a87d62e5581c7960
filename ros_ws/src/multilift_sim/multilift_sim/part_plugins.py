"""Parts from outside the packages, in every process of a run (issue 31: a part in one file,
flown through ROS too). MULTILIFT_PARTS names Python files (`.py`) or importable modules,
separated by os.pathsep; each is imported once per process, a file as the module
`multilift_parts_<its stem>`, and its `register_parts()` called (which registers its parts:
`sensors.register`, `events.register`), before the process reads its first scenario
(`scenario.scenario_of`). `multilift run` passes its environment to the simulator, the
controllers and the recorder, so they all know the same parts. numba's cached code names the
modules of the functions it links, so a process loads from numba's cache what another compiled
for the same registries only where the parts come from modules of the same names: a test that
flies a part of its own file headless and through ROS registers the module `import_parts` gives
(`multilift_parts_<stem>`), as the run's processes do."""
from __future__ import annotations

import importlib
import importlib.util
import os
import sys
from pathlib import Path
from types import ModuleType

VARIABLE = 'MULTILIFT_PARTS'
_loaded: dict[str, ModuleType] = {}


def import_parts(entry: str) -> ModuleType:
    """The module of `entry` (a `.py` file's path, or a module's name), imported once."""
    if entry not in _loaded:
        if entry.endswith('.py'):
            path = Path(entry).resolve()
            if not path.is_file():
                raise ValueError(f'{VARIABLE}: no file {entry}')
            name = f'multilift_parts_{path.stem}'
            spec = importlib.util.spec_from_file_location(name, path)
            module = importlib.util.module_from_spec(spec)
            sys.modules[name] = module
            spec.loader.exec_module(module)
        else:
            module = importlib.import_module(entry)
        _loaded[entry] = module
    return _loaded[entry]


def load_parts() -> list[ModuleType]:
    """Every MULTILIFT_PARTS entry imported and its `register_parts()` called, once per
    process; the modules."""
    modules = []
    for entry in filter(None, os.environ.get(VARIABLE, '').split(os.pathsep)):
        fresh = entry not in _loaded
        module = import_parts(entry)
        if fresh:
            register = getattr(module, 'register_parts', None)
            if register is None:
                raise ValueError(f'{VARIABLE}: {entry} has no register_parts()')
            register()
        modules.append(module)
    return modules
