"""Design spectra as inputs (issue 48, point 4): the elastic and design response spectra of EN 1998-1:2004 and
spectra tabulated in a file, as the pseudo-acceleration a mode of period T and damping ratio xi receives.

EN 1998-1:2004 (Eurocode 8, part 1):

- horizontal elastic spectrum Se(T), 3.2.2.2 eqs. (3.2)-(3.5), with S, TB, TC, TD of Table 3.2 (type 1) or
  Table 3.3 (type 2) for ground types A-E (S1 and S2 need special studies: refused);
- damping correction eta = sqrt(10 / (5 + xi)) >= 0.55, xi in percent, 3.2.2.2(3) eq. (3.6);
- vertical elastic spectrum Sve(T), 3.2.2.3 eqs. (3.8)-(3.11), with avg/ag, TB, TC, TD of Table 3.4;
- design spectrum Sd(T) for a behaviour factor q, 3.2.2.5 eqs. (3.13)-(3.16), lower bound beta ag with
  beta = 0.2 (the recommended value); vertically with avg for ag, S = 1, the periods of Table 3.4 (3.2.2.5(6))
  and q at most 1.5 (3.2.2.5(5): "a behaviour factor q up to 1.5 should generally be adopted for all materials
  and structural systems" for the vertical component): a larger q is taken as 1.5 there, and said so.

The key ``ag`` is the reference peak ground acceleration on type A ground agR [m/s^2]; the design ground
acceleration is ``ag = importance * agR`` (gamma_I agR, 3.2.1(3)). Eqs. (3.5) and (3.11) are stated up to 4 s
(3.2.2.2(1)P; Annex A beyond): they are used beyond it as written, and an analysis notes each mode there.
The design spectrum takes no damping correction (q accounts for the dissipation; 3.2.2.5(3)): the damping
ratio then only enters the modal combination.

A tabulated spectrum gives the pseudo-acceleration [m/s^2] at increasing periods [s] for the damping ratio of
the analysis; it is interpolated linearly, refused outside its periods, and applied to every direction. A mode
of another damping ratio (the isolation modes of an effective linearization) gets it times
``eta(xi) / eta(damping)``, the same EN 1998-1 correction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sixdof.dofs import AXES
from sixdof.errors import InputError, Plain, choice_check, number_check, optional, readonly
from sixdof.frozen import Frozen, checked

#: EN 1998-1:2004 Table 3.2 (type 1 spectrum): ground type -> (S, TB [s], TC [s], TD [s]).
EC8_TYPE_1 = {"A": (1.0, 0.15, 0.4, 2.0), "B": (1.2, 0.15, 0.5, 2.0), "C": (1.15, 0.20, 0.6, 2.0),
              "D": (1.35, 0.20, 0.8, 2.0), "E": (1.4, 0.15, 0.5, 2.0)}
#: EN 1998-1:2004 Table 3.3 (type 2 spectrum): ground type -> (S, TB [s], TC [s], TD [s]).
EC8_TYPE_2 = {"A": (1.0, 0.05, 0.25, 1.2), "B": (1.35, 0.05, 0.25, 1.2), "C": (1.5, 0.10, 0.25, 1.2),
              "D": (1.8, 0.10, 0.30, 1.2), "E": (1.6, 0.05, 0.25, 1.2)}
#: EN 1998-1:2004 Table 3.4 (vertical spectrum): type -> (avg / ag, TB [s], TC [s], TD [s]).
EC8_VERTICAL = {1: (0.90, 0.05, 0.15, 1.0), 2: (0.45, 0.05, 0.15, 1.0)}
#: Lower bound factor beta of the design spectrum (EN 1998-1 3.2.2.5(4)P, recommended value).
EC8_LOWER_BOUND = 0.2
#: The largest behaviour factor of the vertical design spectrum (EN 1998-1 3.2.2.5(5)).
EC8_VERTICAL_Q = 1.5
#: Eqs. (3.5) and (3.11) of EN 1998-1 are stated up to this period [s] (3.2.2.2(1)P).
EC8_PERIOD_LIMIT = 4.0
#: The floor of the damping correction eta (EN 1998-1 eq. (3.6)).
ETA_FLOOR = 0.55
#: The directions of a response-spectrum analysis: body axes, z the vertical.
DIRECTIONS = AXES


def damping_correction(xi) -> np.ndarray | float:
    """EN 1998-1 eq. (3.6): ``eta = sqrt(10 / (5 + 100 xi)) >= 0.55``.

    Parameters
    ----------
    xi : float or array_like
        Viscous damping ratio [1] (0.05 for 5 %).

    Returns
    -------
    float or ndarray
        eta [1]: 1 at 5 %.
    """
    eta = np.maximum(np.sqrt(10.0 / (5.0 + 100.0 * np.asarray(xi, dtype=float))), ETA_FLOOR)
    return float(eta) if eta.ndim == 0 else eta


def _damping_ratio(value, field: str) -> float:
    expected = "a viscous damping ratio in [0, 1) (0.05 for 5 %)"
    ratio = number_check(expected, low=0.0)(value, field)
    if ratio >= 1.0:
        raise InputError(field, expected, value)
    return ratio


def _spectrum_type(value, field: str) -> int:
    if isinstance(value, bool) or value not in (1, 2):
        raise InputError(field, "1 or 2 (EN 1998-1 3.2.2.2(2)P: type 1 for surface-wave magnitudes above 5.5, "
                         "type 2 below)", value)
    return int(value)


def _ground_type(value, field: str) -> str:
    if value in ("S1", "S2"):
        raise InputError(field, "a ground type A, B, C, D or E (S1 and S2 need special studies, EN 1998-1 "
                         "3.1.2(4))", value)
    return choice_check(tuple(EC8_TYPE_1))(value, field)


def _behaviour_factor(value, field: str) -> float:
    return number_check("a behaviour factor q >= 1", low=1.0)(value, field)


def _branches(T, a, S, TB, TC, TD, plateau, lower=0.0, start=1.0) -> np.ndarray:
    """The four branches shared by eqs. (3.2)-(3.5), (3.8)-(3.11) and (3.13)-(3.16): from ``a S start`` at T = 0
    rising linearly to the plateau ``a S plateau`` at TB, then ``* TC / T`` from TC and ``* TC TD / T^2`` from TD,
    never below ``lower`` beyond TC."""
    T = np.asarray(T, dtype=float)
    top = a * S * plateau
    rising = a * S * (start + T / TB * (plateau - start))
    with np.errstate(divide="ignore"):
        value = np.where(T <= TB, rising, np.where(T <= TC, top, np.where(T <= TD, top * TC / T,
                                                                             top * TC * TD / T**2)))
    return np.where(T > TC, np.maximum(value, lower), value)


@dataclass(frozen=True)
class EC8Spectrum(Frozen):
    """The EN 1998-1:2004 spectra (see the module): elastic, or design with ``behaviour_factor``.

    Parameters
    ----------
    type : int
        1 or 2 (Tables 3.2 and 3.3; the vertical Table 3.4).
    ground_type : str
        ``"A"`` to ``"E"``.
    ag : float
        Reference peak ground acceleration on type A ground agR [m/s^2].
    importance : float
        Importance factor gamma_I [1]: the design ground acceleration is ``importance * ag``. Default 1.
    behaviour_factor : float or None
        q >= 1 [1] for the design spectrum Sd of 3.2.2.5; ``None`` (default): the elastic spectrum Se.
    """

    type: int = checked(_spectrum_type)
    ground_type: str = checked(_ground_type)
    ag: float = checked(number_check("a reference peak ground acceleration agR > 0 in m/s^2", low=0.0, strict=True))
    importance: float = checked(number_check("an importance factor gamma_I > 0", low=0.0, strict=True), default=1.0)
    behaviour_factor: float | None = checked(optional(_behaviour_factor), default=None)

    @property
    def design_ag(self) -> float:
        """The design ground acceleration ``gamma_I agR`` [m/s^2]."""
        return self.importance * self.ag

    @property
    def parameters(self) -> tuple[float, float, float, float]:
        """(S, TB [s], TC [s], TD [s]) of the horizontal spectrum (Table 3.2 or 3.3)."""
        return (EC8_TYPE_1 if self.type == 1 else EC8_TYPE_2)[self.ground_type]

    @property
    def vertical_parameters(self) -> tuple[float, float, float, float]:
        """(avg / ag, TB [s], TC [s], TD [s]) of the vertical spectrum (Table 3.4)."""
        return EC8_VERTICAL[self.type]

    @property
    def vertical_q(self) -> float | None:
        """The behaviour factor of the vertical design spectrum: q, at most 1.5 (3.2.2.5(5)); None: elastic."""
        q = self.behaviour_factor
        return None if q is None else min(q, EC8_VERTICAL_Q)

    @property
    def period_limit(self) -> float:
        """The longest period [s] for which EN 1998-1 states its expressions (4 s)."""
        return EC8_PERIOD_LIMIT

    def horizontal(self, T, xi=0.05) -> np.ndarray:
        """Se(T) (eqs. 3.2-3.5) at damping ratio ``xi``, or Sd(T) (eqs. 3.13-3.16) with a behaviour factor
        [m/s^2]; ``T`` [s] >= 0, any shape."""
        S, TB, TC, TD = self.parameters
        ag, q = self.design_ag, self.behaviour_factor
        if q is None:
            return _branches(T, ag, S, TB, TC, TD, 2.5 * damping_correction(xi))
        return _branches(T, ag, S, TB, TC, TD, 2.5 / q, lower=EC8_LOWER_BOUND * ag, start=2.0 / 3.0)

    def vertical(self, T, xi=0.05) -> np.ndarray:
        """Sve(T) (eqs. 3.8-3.11) at damping ratio ``xi``, or its design form (3.2.2.5(6), q at most 1.5)
        [m/s^2]."""
        ratio, TB, TC, TD = self.vertical_parameters
        avg, q = ratio * self.design_ag, self.vertical_q
        if q is None:
            return _branches(T, avg, 1.0, TB, TC, TD, 3.0 * damping_correction(xi))
        return _branches(T, avg, 1.0, TB, TC, TD, 2.5 / q, lower=EC8_LOWER_BOUND * avg, start=2.0 / 3.0)

    def pseudo_acceleration(self, T, xi, direction: str) -> np.ndarray:
        """The spectrum's pseudo-acceleration [m/s^2] at periods ``T`` [s] and damping ratios ``xi`` along
        ``direction`` (``"x"``, ``"y"``: horizontal; ``"z"``: vertical)."""
        return (self.vertical if direction == "z" else self.horizontal)(T, xi)

    def corner_periods(self, direction: str) -> tuple[float, float, float]:
        """TB, TC, TD [s] of the spectrum along ``direction``."""
        return (self.vertical_parameters if direction == "z" else self.parameters)[1:]

    def describe(self) -> str:
        """One line: which spectrum, with its numbers."""
        S, TB, TC, TD = self.parameters
        kind = "elastic" if self.behaviour_factor is None else f"design (q = {self.behaviour_factor:g})"
        return (f"EN 1998-1:2004 {kind} spectrum, type {self.type}, ground {self.ground_type} (S = {S:g}, TB = "
                f"{TB:g} s, TC = {TC:g} s, TD = {TD:g} s), ag = {self.importance:g} x {self.ag:g} = "
                f"{self.design_ag:.4g} m/s^2")


def _periods(value, field: str) -> np.ndarray:
    periods = np.asarray(value, dtype=float)
    if periods.ndim != 1 or periods.size < 2 or not np.all(np.isfinite(periods)) or periods[0] < 0 \
            or np.any(np.diff(periods) <= 0):
        raise InputError(field, "at least 2 finite, strictly increasing periods >= 0 in s", Plain(str(value)))
    return readonly(periods)


@dataclass(frozen=True, eq=False)
class TabulatedSpectrum(Frozen):
    """A spectrum given as a table (``[spectrum] file``): pseudo-acceleration against period, interpolated
    linearly, at the damping ratio ``damping``.

    Parameters
    ----------
    periods : array_like, shape (n,)
        Strictly increasing periods >= 0 [s].
    values : array_like, shape (n,)
        Pseudo-accelerations >= 0 [m/s^2].
    damping : float
        The damping ratio the values are for [1]; other ratios get ``eta(xi) / eta(damping)`` of them.
    source : str
        Where the table came from (the file name), named by the errors.
    """

    periods: np.ndarray = checked(_periods)
    values: np.ndarray = checked(lambda value, field: readonly(np.asarray(value, dtype=float)))
    damping: float = checked(_damping_ratio, default=0.05)
    source: str = "the table"

    def __check__(self) -> None:
        if self.values.shape != self.periods.shape or not np.all(np.isfinite(self.values)) \
                or np.any(self.values < 0):
            raise InputError("values", f"{self.periods.size} finite pseudo-accelerations >= 0 in m/s^2, one per "
                             f"period of {self.source}", Plain(str(self.values.tolist())))

    @property
    def period_limit(self) -> float:
        """The longest period of the table [s]."""
        return float(self.periods[-1])

    def pseudo_acceleration(self, T, xi, direction: str = "x") -> np.ndarray:
        """The table's pseudo-acceleration [m/s^2] at periods ``T`` [s] (within the table's), scaled by
        ``eta(xi) / eta(damping)``; the same along every ``direction``.

        Raises
        ------
        InputError
            For a period outside the table's.
        """
        T = np.asarray(T, dtype=float)
        low, high = float(self.periods[0]), float(self.periods[-1])
        outside = (T < low) | (T > high)
        if np.any(outside):
            bad = float(np.ravel(T)[np.flatnonzero(np.ravel(outside))[0]])
            raise InputError("spectrum.file", f"a spectrum whose periods cover every mode's: {self.source} gives "
                             f"{low:g} to {high:g} s", Plain(f"a mode of period {bad:.6g} s"))
        scale = damping_correction(xi) / damping_correction(self.damping)
        return np.interp(T, self.periods, self.values) * scale

    def corner_periods(self, direction: str) -> tuple[float, ...]:
        """None: a table has no corner periods."""
        return ()

    def describe(self) -> str:
        """One line: where the table is from and its range."""
        return (f"spectrum of {self.source} ({self.periods.size} points, {self.periods[0]:g} to "
                f"{self.periods[-1]:g} s, at {100 * self.damping:g} % damping)")


def _directions(value, field: str) -> tuple[str, ...]:
    expected = f"a non-empty list of distinct directions among {', '.join(repr(d) for d in DIRECTIONS)}"
    if not isinstance(value, (list, tuple)) or not value:
        raise InputError(field, expected, value)
    for i, d in enumerate(value):
        choice_check(DIRECTIONS)(d, f"{field}[{i}]")
    if len(set(value)) != len(value):
        raise InputError(field, expected, list(value))
    return tuple(value)


#: Modal combinations: complete quadratic (Der Kiureghian 1981) or square root of the sum of squares.
COMBINATIONS = ("cqc", "srss")
#: Directional combinations: SRSS over the directions, or the 100-30 rule (EN 1998-1 4.3.3.5.1(3), 4.3.3.5.2(4)).
DIRECTIONALS = ("srss", "100-30")


@dataclass(frozen=True, eq=False)
class SpectrumSettings(Frozen):
    """The ``[spectrum]`` table: a response-spectrum analysis (:func:`sixdof.analysis.spectrum.response_spectrum`).

    Parameters
    ----------
    spectrum : EC8Spectrum or TabulatedSpectrum
    damping : float
        Damping ratio of every mode [1] (default 0.05): the spectrum's eta correction and the CQC coefficients.
    directions : tuple of str
        Ground directions analysed, among ``"x"``, ``"y"``, ``"z"`` (body axes; z the vertical, with the
        vertical spectrum). Default ``("x", "y")``.
    combination : str
        ``"cqc"`` (default) or ``"srss"``: how the modes' peaks combine.
    directional : str
        ``"srss"`` (default) or ``"100-30"``: how the directions' peaks combine.
    """

    spectrum: EC8Spectrum | TabulatedSpectrum
    damping: float = checked(_damping_ratio, default=0.05)
    directions: tuple[str, ...] = checked(_directions, default=("x", "y"))
    combination: str = checked(choice_check(COMBINATIONS), default="cqc")
    directional: str = checked(choice_check(DIRECTIONALS), default="srss")

    def __check__(self) -> None:
        if not isinstance(self.spectrum, (EC8Spectrum, TabulatedSpectrum)):
            raise InputError("spectrum", "an EC8Spectrum or a TabulatedSpectrum", self.spectrum)
        if isinstance(self.spectrum, TabulatedSpectrum) and not math.isclose(self.spectrum.damping, self.damping):
            raise InputError("spectrum.damping", f"the analysis's damping ratio ({self.damping:g}) for the table",
                             self.spectrum.damping)
