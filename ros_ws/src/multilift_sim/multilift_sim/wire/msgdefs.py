"""Message definitions as rosbag2 stores them in an MCAP schema (no rclpy).

rosbag2's MCAP storage plugin (Jazzy, `message_definition_cache.cpp`) writes, for a type
`pkg/msg/Type`, a schema of encoding `ros2msg` whose data is the type's own `.msg` file, verbatim,
followed by every type it depends on, each once: a line of 80 `=`, a line `MSG: dep_pkg/DepType`,
then that `.msg` file verbatim. This module builds the same text from the `.msg` files installed
under the ament prefixes of `AMENT_PREFIX_PATH` (`<prefix>/share/<pkg>/msg/<Type>.msg`).

Order of the dependencies: exactly rosbag2's, which is depth first (pre-order): the dependencies
of one file are visited in sorted order of their names, and each dependency's own dependencies
follow it before the next sibling. Readers (mcap-ros2-support, rosbags, Foxglove) accept any
order; matching rosbag2 keeps our bags byte-comparable with ones `ros2 bag record` writes.

Dependency names are written as in the `.msg` file (`std_msgs/Header`); a short name without a
package (`Header` inside std_msgs, `Point` inside geometry_msgs) belongs to the package of the file
that uses it. Builtin types (`bool`, `byte`, `char`, `float32/64`, `[u]int8..64`, `string`,
`wstring`, and bounded strings `string<=N`) are not dependencies; array suffixes (`[]`, `[N]`,
`[<=N]`), default values and constants (`int32 FOO=1`) do not change the field's type.
"""

from __future__ import annotations

import json
import os
import re
from pathlib import Path

SEPARATOR = '=' * 80
SCHEMA_ENCODING = 'ros2msg'

BUILTIN_TYPES = frozenset({
    'bool', 'byte', 'char', 'float32', 'float64', 'int8', 'uint8', 'int16', 'uint16',
    'int32', 'uint32', 'int64', 'uint64', 'string', 'wstring',
})

# `pkg/Type` or `pkg/msg/Type` (rosbag2 also accepts `srv/` in the middle).
_TYPE_NAME = re.compile(r'^([a-zA-Z][a-zA-Z0-9_]*)/(?:(msg|srv)/)?([a-zA-Z][a-zA-Z0-9_]*)$')
# The type token of a field line: `pkg/Type[<=3] name`, `string<=10 name`, `float64 X=1.0`.
_FIELD_TYPE = re.compile(r'^([a-zA-Z][a-zA-Z0-9_/]*)(?:<=\d+)?(?:\[[^\]]*\])?$')
_MAX_DEPTH = 50


class MessageDefinitionError(LookupError):
    """A message type could not be resolved to `.msg` files on the ament prefix path."""


def split_type_name(type_name: str) -> tuple[str, str, str]:
    """Split `pkg/msg/Type` or `pkg/Type` into `(pkg, 'msg', 'Type')`."""
    match = _TYPE_NAME.match(type_name)
    if match is None:
        raise MessageDefinitionError(
            f'message type name {type_name!r} is not of the form pkg/msg/Type or pkg/Type')
    return match.group(1), match.group(2) or 'msg', match.group(3)


def ament_prefixes() -> list[Path]:
    """The prefixes of `AMENT_PREFIX_PATH`, in order (empty entries dropped)."""
    return [Path(p) for p in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep) if p]


def package_share_directory(package: str) -> Path:
    """`<prefix>/share/<package>` of the first prefix whose ament index lists `package`."""
    for prefix in ament_prefixes():
        marker = prefix / 'share' / 'ament_index' / 'resource_index' / 'packages' / package
        if marker.is_file():
            return prefix / 'share' / package
    raise MessageDefinitionError(
        f'package {package!r} is not in the ament index of any prefix of AMENT_PREFIX_PATH '
        f'({os.environ.get("AMENT_PREFIX_PATH", "")!r}); source scripts/env.sh first')


def interface_file(type_name: str, extension: str = '.msg') -> Path:
    """Path of the installed interface file of `type_name` (`.msg`, `.json`, `.idl`)."""
    package, namespace, name = split_type_name(type_name)
    path = package_share_directory(package) / namespace / f'{name}{extension}'
    if not path.is_file():
        raise MessageDefinitionError(f'no {extension} file for {type_name!r}: {path} is missing')
    return path


def field_type_names(text: str, package: str) -> list[str]:
    """Sorted, unique non-builtin field types of a `.msg` text, as `pkg/Type`.

    `package` is the package of the file, used for short names without a package.
    """
    dependencies: set[str] = set()
    for line in text.splitlines():
        code = line.split('#', 1)[0].strip()
        if not code:
            continue
        match = _FIELD_TYPE.match(code.split()[0])
        if match is None:
            raise MessageDefinitionError(f'cannot parse field line {line!r} of package {package}')
        base = match.group(1)
        if base in BUILTIN_TYPES:
            continue
        dependencies.add(base if '/' in base else f'{package}/{base}')
    return sorted(dependencies)


def message_definition(type_name: str) -> str:
    """Full ros2msg schema text of `type_name` (`pkg/msg/Type`), as rosbag2 writes it."""
    seen: set[str] = set()

    def append(name: str, depth: int) -> str:
        if depth <= 0:
            raise MessageDefinitionError(f'dependencies of {type_name!r} nest deeper than '
                                         f'{_MAX_DEPTH} levels (a cycle?)')
        package = split_type_name(name)[0]
        text = interface_file(name).read_text(encoding='utf-8')
        result = text
        for dependency in field_type_names(text, package):
            if dependency not in seen:
                seen.add(dependency)
                result += f'\n{SEPARATOR}\nMSG: {dependency}\n' + append(dependency, depth - 1)
        return result

    return append(type_name, _MAX_DEPTH)


def type_description_hash(type_name: str) -> str:
    """The `RIHS01_...` type hash rosidl generated for `type_name`, or '' if not installed.

    Read from `<share>/<pkg>/msg/<Type>.json` (field `type_hashes`), the value Jazzy publishers
    advertise and rosbag2 stores as `type_description_hash`.
    """
    package, namespace, name = split_type_name(type_name)
    full_name = f'{package}/{namespace}/{name}'
    try:
        data = json.loads(interface_file(type_name, '.json').read_text(encoding='utf-8'))
    except MessageDefinitionError:
        return ''
    for entry in data.get('type_hashes', []):
        if entry.get('type_name') == full_name:
            return str(entry.get('hash_string', ''))
    return ''
