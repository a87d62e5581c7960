"""A kind of part's registry (issue 31): its parts by name, in order, the shipped ones first;
`register` checks a part declares the names its kind requires, `unregister` removes only what
`register` added, `registered` holds a part for a block (a test's toy part). A kind that
compiles its parts into the tick passes `changed`, called after every change."""
from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterable
from typing import Any, Iterator


def one_of(what: str, value: Any, choices: Iterable[Any]) -> None:
    """Unless `value` is among `choices`: ValueError naming `what`, the value and the choices
    (one wording for every parameter that names one of some things)."""
    choices = tuple(choices)
    if value not in choices:
        raise ValueError(f'unknown {what} {value!r}: one of {", ".join(map(str, choices))}')


class Registry(dict):
    """name -> part, in registration order."""

    def __init__(self, kind: str, required: tuple[str, ...], shipped: Iterable[Any],
                 changed: Callable[[], None] | None = None,
                 check: Callable[[Any], None] | None = None):
        super().__init__((part.NAME, part) for part in shipped)
        self.kind, self.required = kind, required
        self.shipped = tuple(self.values())
        self._changed, self._check = changed, check

    def register(self, part: Any) -> None:
        """Add `part` (an object with the kind's required names) after the others."""
        missing = [name for name in self.required if not hasattr(part, name)]
        if missing:
            raise ValueError(f'{self.kind} {part!r} lacks {", ".join(missing)}')
        if part.NAME in self:
            raise ValueError(f'{self.kind} {part.NAME!r} is registered already')
        if self._check is not None:
            self._check(part)
        self[part.NAME] = part
        if self._changed is not None:
            self._changed()

    def unregister(self, name: str) -> None:
        """Remove the part `name` (one `register` added)."""
        if any(part.NAME == name for part in self.shipped):
            raise ValueError(f'{self.kind} {name!r} ships with multilift')
        del self[name]
        if self._changed is not None:
            self._changed()

    @contextlib.contextmanager
    def registered(self, part: Any) -> Iterator[Any]:
        """`part` registered for the block."""
        self.register(part)
        try:
            yield part
        finally:
            self.unregister(part.NAME)
