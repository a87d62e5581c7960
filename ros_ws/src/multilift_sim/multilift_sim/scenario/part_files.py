"""A scenario's `parts:` (multilift_sim.parts): its part files imported before the rest of the
scenario is read, as absolute paths."""
from __future__ import annotations

from pathlib import Path

from multilift_sim.parts import PartsError, import_part, resolve_part
from multilift_sim.scenario.reading import Section


def scenario_parts(top: Section) -> tuple[str, ...]:
    """`parts:` imported (multilift_sim.parts), as absolute paths: files relative to the
    scenario file's folder (a scenario given as text: the working directory's)."""
    source = Path(top.where)
    base = source.parent if source.is_file() else Path.cwd()
    paths = []
    for entry in top.sequence('parts', []):
        if not isinstance(entry, str):
            raise top.fail('parts', entry, 'must be a list of Python file paths')
        try:
            path = resolve_part(entry, base)
            import_part(path)
        except PartsError as exc:
            raise top.fail('parts', entry, str(exc)) from None
        paths.append(str(path))
    return tuple(paths)
