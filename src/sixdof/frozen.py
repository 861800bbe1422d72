"""The one way sixdof makes frozen, validated objects: frozen dataclasses whose fields are checked once.

A field declared with :func:`checked` passes its value through its check when the object is built (the
check gets the value and the field's name, and returns the converted value or raises an
:class:`~sixdof.errors.InputError` naming the field); :meth:`Frozen.__check__` then does what involves
several fields. Nothing changes an object after that::

    @dataclass(frozen=True, eq=False)
    class Pulse(Frozen):
        start: float = checked(number_check("a finite time in s"))
        duration: float = checked(number_check("a positive duration in s", low=0.0, strict=True))
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

Check = Callable[[Any, str], Any]


def checked(check: Check, *, default: Any = dataclasses.MISSING, default_factory: Any = dataclasses.MISSING,
            metadata: dict | None = None) -> Any:
    """A dataclass field whose value is ``check(value, field_name)`` once the object is built (defaults
    included); ``metadata`` adds to the field's (storage descriptions of results)."""
    return dataclasses.field(default=default, default_factory=default_factory,
                             metadata={**(metadata or {}), "check": check})


class Frozen:
    """Base of the validated frozen dataclasses: runs every field's check, then :meth:`__check__`."""

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            check = f.metadata.get("check")
            if check is not None:
                object.__setattr__(self, f.name, check(getattr(self, f.name), f.name))
        self.__check__()

    def __check__(self) -> None:
        """Checks involving several fields, and derived values (:meth:`_derive`); none by default."""

    def _derive(self, **values: Any) -> None:
        """Set values computed from the checked fields (only from :meth:`__check__`)."""
        for name, value in values.items():
            object.__setattr__(self, name, value)
