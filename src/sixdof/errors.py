"""Exceptions raised by sixdof: bad input names its field, failed numerics say what failed."""

from __future__ import annotations

import math
import os
import re
from typing import Any

import numpy as np


class InputError(ValueError):
    """A value given by the user is not acceptable.

    Parameters
    ----------
    field : str
        Path of the offending field, for example ``"mounts[2].stiffness"``.
    expected : str
        What was expected, with its unit where it has one.
    got : object
        The value received; shown with :func:`describe`.
    """

    def __init__(self, field: str, expected: str, got: object) -> None:
        self.field = field
        self.expected = expected
        self.got = got
        where = f"{field}: " if field else ""
        super().__init__(f"{where}expected {expected}, got {describe(got)}")

    def within(self, prefix: str) -> InputError:
        """The same error with ``prefix`` (a parent field path) put before its field."""
        joined = prefix if not self.field else (
            f"{prefix}{self.field}" if self.field.startswith("[") else f"{prefix}.{self.field}"
        )
        return InputError(joined, self.expected, self.got)


class ScenarioError(InputError):
    """An :class:`InputError` found in a scenario file; the message starts with the file name."""

    def __init__(self, file: str, error: InputError) -> None:
        self.file = file
        ValueError.__init__(self, f"{file}: {error}")
        self.field, self.expected, self.got = error.field, error.expected, error.got


def finite_array(value: object, field: str, expected: str, shape: tuple[int, ...]) -> np.ndarray:
    """``value`` as a read-only float64 array of ``shape`` (-1: any length along that axis) with finite entries.

    The one check behind every "3 coordinates in m" / "6 finite values" field of the library.

    Raises
    ------
    InputError
        Naming ``field`` and ``expected`` when ``value`` is not numeric, has another shape, or holds
        a NaN or an infinity.
    """
    array = real_array(value, field, expected, len(shape))
    fits = array.ndim == len(shape) and all(n in (-1, m) for n, m in zip(shape, array.shape))  # -1: any length
    if not fits or not np.all(np.isfinite(array)):
        raise InputError(field, expected, value)
    return array


#: The highest frequency accepted [Hz] (signals, bands, FRF and PSD grids, rotation speeds): far above any
#: rigid-body mode, and low enough that (2 pi f)^2 times a mass, a stiffness or a PSD stays within float64.
MAX_FREQUENCY_HZ = 1e9
#: The shortest pulse, ramp or sweep accepted [s]: 1 / :data:`MAX_FREQUENCY_HZ`.
MIN_DURATION_S = 1e-9


def frequency_band(value: object, field: str, expected: str = "a band [low, high] in Hz with 0 < low < high"
                   ) -> tuple[float, float]:
    """``value`` as a frequency band ``(low, high)`` [Hz] with ``0 < low < high <=`` :data:`MAX_FREQUENCY_HZ`."""
    low, high = finite_array(value, field, expected, (2,)).tolist()
    if not 0 < low < high:
        raise InputError(field, expected, value)
    check_frequencies(high, field, value)
    return low, high


def short(x: float) -> str:
    """``x`` as ``:g`` writes it, without the exponent's sign and zeros: ``1e9``, ``6e10``, ``1e-9``."""
    return re.sub(r"e([+-])0*(\d)", lambda m: f"e{'-' if m[1] == '-' else ''}{m[2]}", f"{x:g}")


def check_frequencies(highest: float, field: str, got: object) -> None:
    """Refuse frequencies beyond :data:`MAX_FREQUENCY_HZ` (``highest`` [Hz], ``got`` as given)."""
    if highest > MAX_FREQUENCY_HZ:
        raise InputError(field, f"frequencies up to {short(MAX_FREQUENCY_HZ)} Hz", got)


def real_array(value: object, field: str, expected: str, max_ndim: int) -> np.ndarray:
    """``value`` as a read-only float64 array of at most ``max_ndim`` dimensions, built only from real
    numbers: Python or numpy integers and floats, never strings or booleans (``"500"`` and ``true`` are
    typing mistakes in a scenario file, not numbers). Nesting is followed no deeper than ``max_ndim``,
    so a 10,000-deep list is refused, not recursed into."""
    if not _real_numbers(value, max_ndim):
        raise InputError(field, expected, value)
    try:
        return readonly(value)
    except ValueError:  # ragged nesting
        raise InputError(field, expected, value) from None


def _real_numbers(value: object, depth: int) -> bool:
    if isinstance(value, (list, tuple)):
        return depth > 0 and all(_real_numbers(item, depth - 1) for item in value)
    if isinstance(value, (bool, np.bool_)):
        return False
    if isinstance(value, (int, float, np.integer, np.floating)):
        return True
    if hasattr(value, "__array__") and not isinstance(value, (str, bytes)):  # numpy and JAX arrays
        array = np.asarray(value)
        return array.ndim <= depth and array.dtype.kind in "iuf"
    return False


class Owned:
    """An array given up by the computation that made it, for a result to hold as it is.

    ``readonly(Owned(array))`` is ``array`` itself, marked read-only, not a copy: for an array that nothing else
    references (no view of it survives), which its maker passes straight to a result's constructor (the exact
    engine's q, q', q'': three copies of ~1 MB spared a call). The caller states the ownership; nothing records it.
    """

    __slots__ = ("array",)

    def __init__(self, array: np.ndarray) -> None:
        self.array = array


def readonly(value: Any, dtype: Any = float) -> np.ndarray:
    """A read-only copy of ``value`` as an array of ``dtype`` (``None``: keep the dtype): what every
    result object holds, so that no caller can change a result in place. An array given up as
    :class:`Owned` is held as it is when it has that dtype."""
    if isinstance(value, Owned):
        if dtype is None or value.array.dtype == dtype:
            value.array.flags.writeable = False
            return value.array
        value = value.array
    array = np.array(value, dtype=dtype)
    array.flags.writeable = False
    return array


def number(value: Any, field: str, expected: str, *, low: float | None = None, strict: bool = False,
           allow_inf: bool = False, high: float | None = None) -> float:
    """``value`` as a float: a real number (not a bool, not a string), not NaN, finite unless
    ``allow_inf``, ``>= low`` (``> low`` when ``strict``) and ``<= high``.

    Raises
    ------
    InputError
        Naming ``field`` and ``expected``.
    """
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise InputError(field, expected, value)
    x = float(value)
    if math.isnan(x) or (math.isinf(x) and not allow_inf):
        raise InputError(field, expected, value)
    if low is not None and (x < low or (strict and x == low)):
        raise InputError(field, expected, value)
    if high is not None and x > high:
        raise InputError(field, expected, value)
    return x


def integer(value: Any, field: str, expected: str, low: int) -> int:
    """``value`` as an int ``>= low`` (a real integer: not a bool, not a float)."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
        raise InputError(field, expected, value)
    return int(value)


def boolean(value: Any, field: str) -> bool:
    """``value`` as a bool: ``True`` or ``False`` (numpy's too), never a number or a string."""
    if not isinstance(value, (bool, np.bool_)):
        raise InputError(field, "true or false", value)
    return bool(value)


def label(value: Any, field: str = "name") -> str:
    """``value`` as a non-empty string (a name used in tables, files and figures)."""
    if not isinstance(value, str) or not value:
        raise InputError(field, "a non-empty string", value)
    return value


#: A name that becomes a file or folder name: one path component, the same on every filesystem.
FILE_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,99}")


def file_name(value: Any, field: str = "name") -> str:
    """``value`` as a name that is one safe path component (a scenario's results folder)."""
    if not isinstance(value, str) or not FILE_NAME.fullmatch(value):
        raise InputError(field, "a name of 1 to 100 letters, digits, '.', '_' or '-' that starts with a letter or "
                         "digit (it names the results folder)", value)
    return value


def instance(value: Any, field: str, *kinds: type | None) -> Any:
    """``value`` when it is an instance of one of ``kinds`` (``None`` among them lets ``None`` through): the
    check of a public function's model arguments, so that one given in another's place
    (``simulate(excitation, system, settings)``) is named with the kind expected and the kind received, not met
    later as an AttributeError deep inside the computation."""
    if (value is None and None in kinds) or isinstance(value, tuple(k for k in kinds if k is not None)):
        return value
    expected = " or ".join(_a(k.__name__) if k is not None else "None" for k in kinds)
    raise InputError(field, expected, kind_of(value))


def tuple_of(value: Any, field: str, expected: str) -> tuple:
    """``value``'s items as a tuple: a list, tuple or other iterable of items, not one item alone (nor a string,
    whose characters are not items, nor a mapping, whose keys are not). Each item is checked by the caller."""
    if isinstance(value, (str, bytes, dict)):
        raise InputError(field, expected, kind_of(value))
    try:
        items = iter(value)
    except TypeError:  # one item alone, as ``Excitation(loads=Load(...))``
        raise InputError(field, expected, kind_of(value)) from None
    return tuple(items)


def kind_of(value: Any) -> Any:
    """A received value for a message about its kind: strings, numbers and None as they are, an object as
    "a Load" (the repr of a model object runs over several lines of arrays, its class is what is wrong)."""
    if value is None or isinstance(value, (str, bytes, int, float, complex, np.number, np.bool_)):
        return value
    if isinstance(value, np.ndarray):
        return Plain(f"an array of shape {value.shape}")
    return Plain(_a(type(value).__name__))


def _a(noun: str) -> str:
    """``noun`` with its indefinite article: "a System", "an Excitation"."""
    return f"{'an' if noun[:1].lower() in 'aeiou' else 'a'} {noun}"


def memory_check(field: str, needed_bytes: float, expected: str, got: str) -> None:
    """Refuse up front a size that cannot fit in this machine's physical memory, with the numbers: better
    than a solve that swaps for an hour or is killed at its end.

    The message reads "expected ``expected`` that fits in this machine's N GiB of memory, got ``got``, about
    M GiB"."""
    total = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    if needed_bytes > total:
        raise InputError(field, f"{expected} that fits in this machine's {total / 2**30:.1f} GiB of memory",
                         Plain(f"{got}, about {needed_bytes / 2**30:.3g} GiB"))


def vector3(value: Any, field: str, expected: str) -> np.ndarray:
    """``value`` as a read-only (3,) float array of finite entries."""
    return finite_array(value, field, expected, (3,))


def point(value: Any, field: str = "position") -> np.ndarray:
    """``value`` as a body point: 3 finite coordinates [m] from the CG in body axes (read-only)."""
    return finite_array(value, field, "3 coordinates [x, y, z] in m from the CG in body axes", (3,))


def increasing_times(value: Any, field: str) -> np.ndarray:
    """``value`` as a read-only 1-D array of at least 2 finite, strictly increasing times [s]."""
    expected = "at least 2 finite, strictly increasing times in s"
    times = real_array(value, field, expected, 1)
    if times.ndim != 1 or times.size < 2 or not np.all(np.isfinite(times)):
        raise InputError(field, expected, value)
    if np.any(np.diff(times) <= 0):
        bad = int(np.flatnonzero(np.diff(times) <= 0)[0])
        raise InputError(field, expected, Plain(f"{field}[{bad + 1}] = {times[bad + 1]:g} after "
                                                f"{field}[{bad}] = {times[bad]:g}"))
    return times


class SolverError(RuntimeError):
    """A numerical solve failed (diverged, hit its step limit, or produced non-finite values)."""


class Plain(str):
    """A received "value" that is really a description (``Plain("nothing")``): shown without quotes."""


def describe(value: object) -> str:
    """Short, readable rendering of a received value for error messages."""
    if isinstance(value, Plain):
        return str(value)
    if isinstance(value, str):
        return repr(value)
    if isinstance(value, np.ndarray):
        value = value.tolist()
    text = repr(value)
    return text if len(text) <= 120 else text[:117] + "..."


# ----------------------------------------------------------------------------------------------------
# The same validators as field checks (sixdof.frozen.checked): functions of (value, field name).
# ----------------------------------------------------------------------------------------------------


def number_check(expected: str, **limits: Any):
    """Check of a real number (see :func:`number` for ``low``, ``strict``, ``allow_inf``)."""
    return lambda value, field: number(value, field, expected, **limits)


def integer_check(expected: str, low: int):
    """Check of an integer ``>= low``."""
    return lambda value, field: integer(value, field, expected, low)


def vector3_check(expected: str):
    """Check of 3 finite values (read-only array)."""
    return lambda value, field: vector3(value, field, expected)


def array_check(expected: str, shape: tuple[int, ...]):
    """Check of finite values of ``shape`` (read-only array)."""
    return lambda value, field: finite_array(value, field, expected, shape)


def tuple_check(expected: str):
    """Check of a sequence of items, returned as a tuple (see :func:`tuple_of`)."""
    return lambda value, field: tuple_of(value, field, expected)


def choice_check(choices: tuple[str, ...]):
    """Check of one of ``choices`` (strings)."""
    quoted = [f"'{c}'" for c in choices]
    expected = quoted[0] if len(quoted) == 1 else f"{', '.join(quoted[:-1])} or {quoted[-1]}"

    def check(value, field):
        if value not in choices:
            raise InputError(field, expected, value)
        return value

    return check


def label_check(value: Any, field: str) -> str:
    """Check of a non-empty name."""
    return label(value, field)


def point_check(value: Any, field: str) -> np.ndarray:
    """Check of a body point [m]."""
    return point(value, field)


def direction_check(expected: str):
    """Check of a non-zero 3-vector, returned normalized (read-only)."""
    def check(value, field):
        vector = vector3(value, field, expected)
        if not np.any(vector):
            raise InputError(field, expected, value)
        vector = vector / np.abs(vector).max()  # so that a tiny vector's norm cannot underflow
        return readonly(vector / np.linalg.norm(vector))

    return check


def optional(check):
    """The same check, letting ``None`` (not given) through."""
    return lambda value, field: None if value is None else check(value, field)
