"""The settings tables of a scenario file, read into frozen, validated objects: ``[statics]``, ``[frf]`` and its
requests, ``[superposition]``, ``[output]`` and the ``[[points]]`` (:mod:`sixdof.io.scenario` reads the file)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sixdof.analysis.frf import parse_direction
from sixdof.errors import (
    InputError,
    Plain,
    boolean,
    check_frequencies,
    choice_check,
    direction_check,
    finite_array,
    integer_check,
    label_check,
    number_check,
    optional,
    point,
)
from sixdof.files import read_table_csv
from sixdof.frozen import Frozen, checked
from sixdof.results import DERIVED
from sixdof.schema import Table, build, make, unique


def _checked_direction(value: Any, field: str, rotations: bool = True):
    parse_direction(value, field, rotations)  # raises InputError naming the field
    return tuple(value) if isinstance(value, list) else value


def _checked_point(value: Any, field: str) -> tuple[float, float, float]:
    return tuple(point(value, field).tolist())


def checked_vector(value: Any, field: str) -> tuple[float, float, float]:
    direction_check("a non-zero 3-vector in body axes")(value, field)  # kept as given, not normalized
    return tuple(float(v) for v in value)


def _check_name(name: Any, field: str = "name") -> str:
    if not isinstance(name, str) or not name or "/" in name:
        raise InputError(field, "a non-empty string without '/'", name)
    return name


@dataclass(frozen=True)
class Point(Frozen):
    """A named body point whose motion is reported. ``position`` from the CG in body axes [m]."""

    name: str = checked(label_check)
    position: tuple[float, float, float] = checked(_checked_point)


@dataclass(frozen=True)
class StaticsSettings(Frozen):
    """Gravity for the static deflection: ``gravity`` [m/s^2] along ``direction`` (body axes); with
    ``geometric_stiffness``, the geometric stiffness of the mounts' preload under it is part of K
    (:attr:`sixdof.model.system.System.K_geometric`)."""

    gravity: float = checked(number_check("a positive acceleration in m/s^2", low=0.0, strict=True), default=9.80665)
    direction: tuple[float, float, float] = checked(checked_vector, default=(0.0, 0.0, -1.0))
    geometric_stiffness: bool = checked(boolean, default=False)

    @property
    def vector(self) -> np.ndarray:
        """Gravity in body axes (3,) [m/s^2]."""
        direction = np.asarray(self.direction, dtype=float)
        return self.gravity * direction / np.linalg.norm(direction)


@dataclass(frozen=True)
class PointFrfRequest(Frozen):
    """A point FRF to compute and store (``[[frf.point]]``): the response at ``response_point``
    along ``response_direction`` per unit load at ``load_point`` along ``load_direction``.
    Directions are ``"x"`` .. ``"rz"`` (``r*``: a moment in, a rotation out) or 3-vectors.
    ``quantity`` is ``"receptance"``, ``"mobility"`` or ``"accelerance"``."""

    name: str = checked(_check_name)
    load_point: tuple[float, float, float] = checked(_checked_point)
    load_direction: Any = checked(_checked_direction)
    response_point: tuple[float, float, float] = checked(_checked_point)
    response_direction: Any = checked(_checked_direction)
    quantity: str = checked(choice_check(("receptance", "mobility", "accelerance")), default="receptance")


@dataclass(frozen=True)
class ForceTransmissibilityRequest(Frozen):
    """Forces passed to the foundation per unit load at ``load_point`` along ``load_direction``
    (``[[frf.force_transmissibility]]``)."""

    name: str = checked(_check_name)
    load_point: tuple[float, float, float] = checked(_checked_point)
    load_direction: Any = checked(_checked_direction)


@dataclass(frozen=True)
class GroundTransmissibilityRequest(Frozen):
    """Motion of ``response_point`` per unit ground translation along ``ground_direction``
    (``[[frf.ground_transmissibility]]``)."""

    name: str = checked(_check_name)
    ground_direction: Any = checked(lambda value, field: _checked_direction(value, field, rotations=False))
    response_point: tuple[float, float, float] = checked(_checked_point)


_FRF_REQUESTS = {"point": PointFrfRequest, "force_transmissibility": ForceTransmissibilityRequest,
                 "ground_transmissibility": GroundTransmissibilityRequest}


def _frequency_range(value: Any, field: str) -> tuple[float, float]:
    expected = "two frequencies [low, high] in Hz with 0 <= low < high"
    low, high = finite_array(value, field, expected, (2,)).tolist()
    if not 0 <= low < high:
        raise InputError(field, expected, value)
    check_frequencies(high, field, value)
    return low, high


@dataclass(frozen=True)
class FrfSettings(Frozen):
    """Frequency grid of the frequency responses: ``points`` frequencies over ``f_hz`` [Hz], and
    the point FRFs and transmissibilities to compute beside the 6x6 receptance."""

    f_hz: tuple[float, float] = checked(_frequency_range, default=(0.1, 100.0))
    points: int = checked(integer_check("an integer >= 2", 2), default=2000)
    spacing: str = checked(choice_check(("log", "linear")), default="log")
    point: tuple[PointFrfRequest, ...] = ()
    force_transmissibility: tuple[ForceTransmissibilityRequest, ...] = ()
    ground_transmissibility: tuple[GroundTransmissibilityRequest, ...] = ()

    def __check__(self) -> None:
        if self.spacing == "log" and self.f_hz[0] == 0:
            raise InputError("f_hz", "a positive low frequency for log spacing", self.f_hz)

    def grid(self) -> np.ndarray:
        """The frequencies [Hz], shape (points,)."""
        return (np.geomspace if self.spacing == "log" else np.linspace)(*self.f_hz, self.points)


@dataclass(frozen=True)
class SuperpositionSettings(Frozen):
    """How ``sixdof run`` computes its modal-superposition cross-check (``[superposition]``).

    ``method`` is ``"auto"`` (real modes for classical damping, complex otherwise), ``"real"`` or
    ``"complex"``; ``n_modes`` or ``f_max_hz`` [Hz] truncate the modal basis, with the static
    ``residual`` correction for the modes left out. Truncation is for studying which modes carry a
    response: the cross-check then measures the truncation error, and warns when it is over 1e-6.
    """

    method: str = checked(choice_check(("auto", "real", "complex")), default="auto")
    n_modes: int | None = checked(optional(integer_check("an integer from 1 to 6", 1)), default=None)
    f_max_hz: float | None = checked(optional(number_check("a positive frequency in Hz", low=0.0, strict=True)),
                                     default=None)
    residual: bool = checked(boolean, default=True)

    def __check__(self) -> None:
        if self.n_modes is not None and self.n_modes > 6:
            raise InputError("n_modes", "an integer from 1 to 6", self.n_modes)
        if self.n_modes is not None and self.f_max_hz is not None:
            raise InputError("n_modes", "either n_modes or f_max_hz, not both", self.n_modes)


def _derived_check(value, field):
    if not isinstance(value, (list, tuple)) or not all(isinstance(v, str) for v in value):
        raise InputError(field, f"a list of names from {', '.join(DERIVED)} (or [] for none)", value)
    for i, name in enumerate(value):
        choice_check(DERIVED)(name, f"{field}[{i}]")
    return tuple(dict.fromkeys(value))


#: File formats a run's figures can be written in (``[output] formats``), each figure once per format.
FIGURE_FORMATS = ("png", "svg", "pdf")


def _formats_check(value, field):
    expected = f"a non-empty list of formats from {', '.join(repr(f) for f in FIGURE_FORMATS)}, e.g. [\"png\", \"pdf\"]"
    if not isinstance(value, (list, tuple)) or not value or not all(isinstance(v, str) for v in value):
        raise InputError(field, expected, value)
    for i, name in enumerate(value):
        choice_check(FIGURE_FORMATS)(name, f"{field}[{i}]")
    return tuple(dict.fromkeys(value))


def _dpi_check(value, field):
    # Below 50 dpi the labels are illegible; at 600 (a print's) the widest figure, 13 x 10 in, is already
    # 7800 x 6000 px, 190 MB of pixels to draw.
    if isinstance(value, bool) or not isinstance(value, int) or not 50 <= value <= 600:
        raise InputError(field, "a whole number of dots per inch from 50 to 600 (default 150)", value)
    return value


@dataclass(frozen=True)
class OutputSettings(Frozen):
    """What ``sixdof run`` stores in ``results.h5`` and how it writes its figures (``[output]``): ``derived``
    names the derived quantities written (default all of :data:`DERIVED`, today's file); those left out are
    derived again on reading. ``animate_modes`` (default false) also writes each mode shape as an animated GIF,
    ``mode_1.gif``... (:func:`sixdof.plots.modes.write_mode_animations`). ``formats`` (from
    :data:`FIGURE_FORMATS`, default ``("png",)``) are the files each figure is written as, and ``dpi`` (default
    150) the resolution of its PNG [dots per inch] (and of the images inside a PDF or SVG)."""

    derived: tuple[str, ...] = checked(_derived_check, default=DERIVED)
    animate_modes: bool = checked(boolean, default=False)
    formats: tuple[str, ...] = checked(_formats_check, default=("png",))
    dpi: int = checked(_dpi_check, default=150)

    @property
    def omitted(self) -> tuple[str, ...]:
        """The derived quantities left out of the file."""
        return tuple(name for name in DERIVED if name not in self.derived)


def stored_figure_settings(provenance) -> tuple[tuple[str, ...], int]:
    """The ``[output]`` ``formats`` and ``dpi`` of the scenario a results file was computed from (its
    ``provenance["scenario_text"]``), for ``sixdof plot`` to draw its figures as the run did; the defaults,
    PNG at 150 dpi, for a file without the text or whose text holds neither key (older files).

    Raises
    ------
    InputError
        A stored ``formats`` or ``dpi`` that is not valid (a file edited by hand), naming the field.
    """
    import tomllib  # noqa: PLC0415 (only sixdof plot reads a stored scenario's text)

    try:
        table = tomllib.loads(str(provenance.get("scenario_text", ""))).get("output", {})
    except tomllib.TOMLDecodeError:
        table = {}
    keys = {key: table[key] for key in ("formats", "dpi") if isinstance(table, dict) and key in table}
    settings = build(OutputSettings, keys, "output")
    return settings.formats, settings.dpi


def frf_settings(table: dict) -> FrfSettings:
    frf = Table(table, "frf", tuple(table))  # keys checked by build(FrfSettings) below
    requests = {key: tuple(build(cls, t, f"frf.{key}[{i}]") for i, t in enumerate(frf.tables(key)))
                for key, cls in _FRF_REQUESTS.items()}
    unique([r.name for group in requests.values() for r in group], "frf")
    return build(FrfSettings, {**table, **requests}, "frf")


#: The keys of ``[spectrum]``: the EN 1998-1 spectrum's, or a file's, then the analysis's.
_EC8_KEYS = ("type", "ground_type", "ag", "importance", "behaviour_factor")
_SPECTRUM_KEYS = ("code", "file", *_EC8_KEYS, "damping", "directions", "combination", "directional", "records")


def spectrum_settings(table: dict, base_dir: Path):
    """The ``[spectrum]`` table (:class:`sixdof.excitation.spectra.SpectrumSettings`): ``code = "ec8"`` with
    ``type``, ``ground_type``, ``ag``, ``importance``, ``behaviour_factor``, or ``file`` (period [s],
    pseudo-acceleration [m/s^2], relative to the scenario file ``base_dir``); ``damping``, ``directions``,
    ``combination``, ``directional``. Its ``records`` are read by :func:`record_settings`."""
    from sixdof.excitation.spectra import EC8Spectrum, SpectrumSettings, TabulatedSpectrum  # noqa: PLC0415 (the excitation package loads JAX)

    spectrum = Table(table, "spectrum", _SPECTRUM_KEYS)
    given = [key for key in ("code", "file") if key in table]
    if len(given) != 1:
        raise InputError("spectrum", 'either code = "ec8" or file = "<csv>" (period in s, pseudo-acceleration in '
                         "m/s^2)", Plain("both" if given else "neither"))
    analysis = {key: table[key] for key in ("damping", "directions", "combination", "directional") if key in table}
    damping = analysis.get("damping", 0.05)  # checked with the analysis's settings below
    if "code" in table:
        choice_check(("ec8",))(table["code"], "spectrum.code")
        for key in ("type", "ground_type", "ag"):
            spectrum.value(key)  # required: named before the others
        shape = build(EC8Spectrum, {key: table[key] for key in _EC8_KEYS if key in table}, "spectrum")
    else:
        extra = [key for key in _EC8_KEYS if key in table]
        if extra:
            raise InputError(f"spectrum.{extra[0]}", 'code = "ec8" (a file gives its spectrum whole)',
                             Plain(f"file = {table['file']!r}"))
        periods, values = read_table_csv(table["file"], base_dir, "spectrum.file",
                                         columns=("period in s", "pseudo-acceleration in m/s^2"), increasing=True)
        shape = make(TabulatedSpectrum, "spectrum.file", periods=periods, values=values,
                     damping=damping if isinstance(damping, (int, float)) and 0 <= damping < 1 else 0.05,
                     source=str(table["file"]))
    return make(SpectrumSettings, "spectrum", spectrum=shape, **analysis)


def record_settings(raw: Any, spectrum, field: str = "spectrum.records"):
    """The ``records`` of ``[spectrum]`` (:class:`sixdof.analysis.matching.RecordSettings`): spectrum-compatible
    accelerograms run against the spectrum ``spectrum`` (:class:`~sixdof.excitation.spectra.SpectrumSettings`).

    Their ``direction`` must be one of the spectrum's directions (its peaks there are what the records' are
    reported beside), and a tabulated spectrum must start at period 0 (its zero-period ordinate is the ``ag S``
    of EN 1998-1 3.2.3.1.2(4)b). Every error names ``field.<key>``.
    """
    from sixdof.analysis.matching import RecordSettings  # noqa: PLC0415 (it loads JAX: the excitation package)
    from sixdof.excitation.spectra import TabulatedSpectrum  # noqa: PLC0415 (the excitation package loads JAX)

    if not isinstance(raw, dict):
        raise InputError(field, "a table, e.g. { count = 7, seed = 1, duration = 20.0, dt = 0.01, direction = "
                         '"x" }', raw)
    settings = build(RecordSettings, raw, field)
    if settings.direction not in spectrum.directions:
        raise InputError(f"{field}.direction", "one of the spectrum's directions "
                         f"{', '.join(repr(d) for d in spectrum.directions)} (its peaks there are compared with the "
                         "records')", settings.direction)
    table = spectrum.spectrum
    if isinstance(table, TabulatedSpectrum) and table.periods[0] != 0.0:
        raise InputError(field, "a spectrum file starting at period 0 s: its zero-period ordinate is the ag S that "
                         "the records' peak ground acceleration is checked against (EN 1998-1 3.2.3.1.2(4)b)",
                         Plain(f"{table.source} starting at {table.periods[0]:g} s"))
    return settings
