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


#: Arrays with at most this many values are shown whole by :func:`brief_repr` (a position, a stiffness vector).
SHOWN_WHOLE = 9


def brief_repr(obj: Any) -> str:
    """``Class(field=value, ...)`` on one line: arrays beyond :data:`SHOWN_WHOLE` values by their shape and
    type, nested dataclasses by their class, ``None`` fields left out. The dataclasses' own repr printed
    every sample (a TimeHistory of 20,001 samples, an FRF of 500 frequencies)."""
    shown = (f"{f.name}={_brief(getattr(obj, f.name))}" for f in dataclasses.fields(obj)
             if f.repr and getattr(obj, f.name) is not None)
    return f"{type(obj).__name__}({', '.join(shown)})"


def _brief(value: Any) -> str:
    if hasattr(value, "shape") and hasattr(value, "dtype"):  # an array (NumPy not imported here)
        if value.size <= SHOWN_WHOLE:
            return repr(value.tolist())
        return f"<array {tuple(value.shape)} {value.dtype}>"
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return f"<{type(value).__name__}>"
    if isinstance(value, (tuple, list)) and any(dataclasses.is_dataclass(v) for v in value):
        kinds = sorted({type(v).__name__ for v in value})
        return f"<{len(value)} x {' | '.join(kinds)}>"
    if isinstance(value, dict) and len(value) > SHOWN_WHOLE:
        return f"<{len(value)} entries>"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k!r}: {_brief(v)}" for k, v in value.items()) + "}"
    return repr(value)


class BriefRepr:
    """Base of dataclasses that print on one line (:func:`brief_repr`): the model objects and the results."""

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        # Put in the class itself before @dataclass runs, which then keeps it (it adds a __repr__ only where the
        # class defines none).
        if "__repr__" not in cls.__dict__:
            cls.__repr__ = brief_repr


class Frozen(BriefRepr):
    """Base of the validated frozen dataclasses: runs every field's check, then :meth:`__check__`; a one-line
    repr (:class:`BriefRepr`)."""

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
