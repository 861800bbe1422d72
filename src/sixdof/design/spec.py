"""What a mount-system design must achieve and what it may change: the ``[design]`` table of a scenario.

``[[design.target]]`` entries (``kind``):

- ``"frequency"``: ``dof`` and ``f_hz = [lo, hi]`` [Hz]: the mode dominated by that DOF lies in the window;
- ``"decoupling"``: ``min_percent`` [%], ``coordinates = "body"`` or ``"tra"``, optional ``dof``: the
  kinetic-energy share of its dominant coordinate, of every elastic mode or of the mode dominated by ``dof``;
- ``"static_deflection"``: ``max`` [m]: the largest static deflection of a mount under gravity;
- ``"tra_angle"``: ``max_deg`` [deg]: the roll mode's rotation axis within that angle of the torque-roll axis.

``[[design.vary]]`` entries (``parameter``), each over ``mounts`` (names; default all) within ``bounds =
[lo, hi]``, one variable per mount or, with ``tied = true``, one shared by the listed mounts:

- ``"stiffness"``: factors on the stiffness along the mount's own ``axes`` (``"u"``, ``"v"``, ``"w"``;
  default all three), one variable per axis;
- ``"position"``: offsets [m] along the body ``axes`` (``"x"``, ``"y"``, ``"z"``), one variable per axis: each
  mount moves along +axis, except in a tied group mirrored across that axis' plane (judged from the
  positions: :func:`sixdof.design.problem.mirrored`), whose mounts on the negative side move the other way;
- ``"angle"``: a rotation [deg] of the mount's axes about the body axis ``about`` (``"x"``, ``"y"``, ``"z"``),
  right-handed, mirrored likewise (across x = 0 for a turn about y or z, y = 0 about x).

Each mount parameter is varied by one entry at most (a mount axis' stiffness, a position along a body axis,
a turn about a body axis).

``[[design.stiffness_ratio]]`` entries, each over ``mounts`` (names; default all), keep each shear stiffness
over the compression stiffness (``k_u / k_w`` and ``k_v / k_w``) within ``min`` and/or ``max``: a
constraint of the optimizer (what a buildable elastomer mount allows).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np

from sixdof.chunks import check_count
from sixdof.dofs import AXES, DOFS, MOUNT_AXES
from sixdof.errors import (
    InputError,
    Plain,
    boolean,
    choice_check,
    finite_array,
    frequency_band,
    integer_check,
    number_check,
    optional,
)
from sixdof.frozen import Frozen, checked

TARGET_KINDS = ("frequency", "decoupling", "static_deflection", "tra_angle")
PARAMETERS = ("stiffness", "position", "angle")
#: What the optimizer minimizes (:class:`DesignSpec`).
OBJECTIVES = ("nominal", "robust")
#: Each parameter's axes: the names it accepts and its default.
_PARAMETER_AXES = {"stiffness": MOUNT_AXES, "position": AXES, "angle": ()}


def _window(value: Any, field: str) -> tuple[float, float]:
    return frequency_band(value, field, "a window [lo, hi] in Hz with 0 < lo < hi")


def _bounds(value: Any, field: str) -> tuple[float, float]:
    expected = "bounds [lo, hi] with lo < hi"
    low, high = finite_array(value, field, expected, (2,)).tolist()
    if not low < high:
        raise InputError(field, expected, value)
    return low, high


def _names(choices: tuple[str, ...], what: str):
    def check(value, field):
        if value is None:
            return None
        if not isinstance(value, (list, tuple)) or not value or not all(isinstance(v, str) for v in value):
            raise InputError(field, f"a non-empty list of {what}", value)
        for i, name in enumerate(value):
            if name not in choices:
                raise InputError(f"{field}[{i}]", f"one of {', '.join(choices)}", name)
        if len(set(value)) != len(value):
            raise InputError(field, f"{what} listed once each", value)
        return tuple(value)

    return check


_POSITIVE_RATIO = optional(number_check("a positive stiffness ratio", low=0.0, strict=True))
_PERCENT = number_check("a percentage from 0 to 100", low=0.0)
_POSITIVE = number_check("a positive number", low=0.0, strict=True)


@dataclass(frozen=True)
class Target(Frozen):
    """One ``[[design.target]]`` (see the module's list): ``kind`` and the fields that kind uses."""

    kind: str = checked(choice_check(TARGET_KINDS))
    dof: str | None = checked(optional(choice_check(DOFS)), default=None)
    f_hz: tuple[float, float] | None = checked(optional(_window), default=None)
    min_percent: float | None = checked(optional(_PERCENT), default=None)
    coordinates: str = checked(choice_check(("body", "tra")), default="body")
    max: float | None = checked(optional(_POSITIVE), default=None)
    max_deg: float | None = checked(optional(_POSITIVE), default=None)

    #: The fields each kind needs, and those it accepts besides.
    NEEDS = {"frequency": ("dof", "f_hz"), "decoupling": ("min_percent",), "static_deflection": ("max",),
             "tra_angle": ("max_deg",)}
    ACCEPTS = {"decoupling": ("dof", "coordinates")}

    def __check__(self) -> None:
        for name in self.NEEDS[self.kind]:
            if getattr(self, name) is None:
                raise InputError(name, f"a value for a {self.kind} target", Plain("nothing"))
        allowed = {"kind", *self.NEEDS[self.kind], *self.ACCEPTS.get(self.kind, ())}
        for name in ("dof", "f_hz", "min_percent", "max", "max_deg"):
            if name not in allowed and getattr(self, name) is not None:
                raise InputError(name, f"no {name} for a {self.kind} target "
                                 f"(it takes {', '.join(sorted(allowed - {'kind'}))})", getattr(self, name))
        if self.kind == "decoupling" and self.min_percent > 100:
            raise InputError("min_percent", "a percentage from 0 to 100", self.min_percent)

    @property
    def label(self) -> str:
        """A short description: ``"frequency of the rx mode in [5, 8] Hz"``."""
        if self.kind == "frequency":
            return f"frequency of the {self.dof} mode in [{self.f_hz[0]:g}, {self.f_hz[1]:g}] Hz"
        if self.kind == "decoupling":
            which = f"the {self.dof} mode" if self.dof else "every elastic mode"
            return f"decoupling ({self.coordinates}) of {which} >= {self.min_percent:g} %"
        if self.kind == "static_deflection":
            return f"static mount deflection <= {self.max * 1e3:g} mm"
        return f"roll mode within {self.max_deg:g} deg of the TRA"


@dataclass(frozen=True)
class Vary(Frozen):
    """One ``[[design.vary]]`` (see the module's list)."""

    parameter: str = checked(choice_check(PARAMETERS))
    bounds: tuple[float, float] = checked(_bounds)
    mounts: tuple[str, ...] | None = None  # checked against the system's mounts by DesignSpec
    axes: tuple[str, ...] | None = None
    about: str | None = checked(optional(choice_check(AXES)), default=None)
    tied: bool = checked(boolean, default=False)

    def __check__(self) -> None:
        if self.parameter == "angle":
            if self.about is None:
                raise InputError("about", "the body axis 'x', 'y' or 'z' an angle turns the mounts about",
                                 Plain("nothing"))
            if self.axes is not None:
                raise InputError("axes", "no axes for an angle (it turns all three; 'about' names the axis)",
                                 self.axes)
        else:
            if self.about is not None:
                raise InputError("about", f"no 'about' for a {self.parameter} (only for an angle)", self.about)
            choices = _PARAMETER_AXES[self.parameter]
            axes = _names(choices, f"axes from {', '.join(choices)}")(self.axes, "axes")
            self._derive(axes=axes or choices)
        if self.parameter == "stiffness" and self.bounds[0] <= 0:
            raise InputError("bounds", "positive stiffness factors [lo, hi] with 0 < lo < hi", list(self.bounds))


@dataclass(frozen=True)
class StiffnessRatio(Frozen):
    """One ``[[design.stiffness_ratio]]``: each shear stiffness over the compression stiffness of ``mounts``
    (``k_u / k_w`` and ``k_v / k_w``, names; default all, checked by :func:`check_mounts`) within ``min``
    and/or ``max`` [1]."""

    min: float | None = checked(_POSITIVE_RATIO, default=None)
    max: float | None = checked(_POSITIVE_RATIO, default=None)
    mounts: tuple[str, ...] | None = None

    def __check__(self) -> None:
        if self.min is None and self.max is None:
            raise InputError("max", "a min or a max (or both) of the shear over compression stiffness",
                             Plain("neither"))
        if self.min is not None and self.max is not None and not self.min < self.max:
            raise InputError("max", f"a ratio above min = {self.min:g}", self.max)


#: The most optimizer starts a design may ask for: each runs up to 500 iterations (1.2 ms each measured for the
#: bundled engine design's objective and gradient), so 1000 starts take up to 10 min.
MAX_STARTS = 1000
#: The least an optimizer start costs [s]: one evaluation of the objective and its gradient (1.2 ms measured
#: for the bundled engine design; a start takes up to 500).
SECONDS_PER_START = 1e-3
#: The most samples the robust objective may average: each iteration solves and differentiates all of them,
#: 0.2 s for 10,000 (21-24 us each measured on the bundled engine design).
MAX_ROBUST_SAMPLES = 10_000
#: The least one sample of the robust objective costs a start [s]: one iteration's solve and gradient.
SECONDS_PER_ROBUST_SAMPLE = 20e-6


@dataclass(frozen=True)
class DesignSpec(Frozen):
    """The ``[design]`` table: ``torque_axis`` (body axes; for the TRA metrics and targets), the targets,
    the variables, and the robustness study of the optimized design: every mount-axis stiffness scaled by
    an independent factor uniform in ``1 +- tolerance``, ``samples`` times (``seed``); ``starts``: how many
    starting points the optimizer tries (the given design first, then random points within the bounds);
    ``objective``: ``"nominal"``, the targets met by the design itself, or ``"robust"``, the shortfalls'
    squares averaged over ``robust_samples`` designs scattered like the robustness study's (a fixed
    sample, so the objective stays smooth: see :class:`~sixdof.design.problem.DesignProblem`);
    ``stiffness_ratio``: the :class:`StiffnessRatio` constraints. Sizes beyond :data:`MAX_STARTS`,
    :data:`~sixdof.chunks.MAX_VARIANTS` samples and :data:`MAX_ROBUST_SAMPLES` are refused with the least time
    they would take, and so are frequency targets of one DOF whose windows do not overlap."""

    torque_axis: tuple[float, float, float] | None = None
    target: tuple[Target, ...] = ()
    vary: tuple[Vary, ...] = ()
    tolerance: float = checked(number_check("a relative tolerance from 0 to 0.9", low=0.0), default=0.15)
    samples: int = checked(integer_check("an integer >= 1", 1), default=1000)
    seed: int = checked(integer_check("an integer >= 0", 0), default=0)
    starts: int = checked(integer_check("an integer >= 1", 1), default=8)
    objective: str = checked(choice_check(OBJECTIVES), default="nominal")
    robust_samples: int = checked(integer_check("an integer >= 1", 1), default=128)
    stiffness_ratio: tuple[StiffnessRatio, ...] = ()

    def __check__(self) -> None:
        check_count(self.starts, "starts", "starts", MAX_STARTS, SECONDS_PER_START)
        check_count(self.samples, "samples", "samples")  # the robustness study is a sweep of the design
        check_count(self.robust_samples, "robust_samples", "samples", MAX_ROBUST_SAMPLES,
                    self.starts * SECONDS_PER_ROBUST_SAMPLE)
        _check_compatible(self.target)
        if self.tolerance > 0.9:
            raise InputError("tolerance", "a relative tolerance from 0 to 0.9", self.tolerance)
        if self.objective == "robust" and self.tolerance == 0:
            raise InputError("objective", "\"nominal\" with tolerance = 0 (nothing to be robust against)",
                             self.objective)
        needs_tra = [i for i, t in enumerate(self.target) if t.kind == "tra_angle" or t.coordinates == "tra"]
        if needs_tra and self.torque_axis is None:
            raise InputError(f"target[{needs_tra[0]}]", "a torque_axis in [design] for a TRA target",
                             Plain("no torque_axis"))


def _check_compatible(targets: tuple[Target, ...]) -> None:
    """Refuse two targets on one quantity that cannot both hold: frequency windows of one DOF's mode that do
    not overlap (the other kinds bound a quantity on one side only, so any two of a kind hold together)."""
    for j, later in enumerate(targets):
        for i, earlier in enumerate(targets[:j]):
            if later.kind == earlier.kind == "frequency" and later.dof == earlier.dof and (
                    later.f_hz[0] > earlier.f_hz[1] or later.f_hz[1] < earlier.f_hz[0]):
                raise InputError(f"target[{j}].f_hz", f"a window overlapping target[{i}]'s [{earlier.f_hz[0]:g}, "
                                 f"{earlier.f_hz[1]:g}] Hz (the same {later.dof} mode cannot be in both)",
                                 list(later.f_hz))


def _varied(entry: Vary) -> list[tuple[str, str]]:
    """What ``entry`` varies of each of its mounts: (parameter, axis) pairs, the axis ``about`` for an angle."""
    axes = (entry.about,) if entry.parameter == "angle" else entry.axes
    return [(entry.parameter, axis) for axis in axes]


def check_mounts(spec: DesignSpec, mount_names: tuple[str, ...], table: str = "design") -> DesignSpec:
    """``spec`` with each variable's and stiffness ratio's ``mounts`` checked against the system's (default:
    all), and each mount parameter varied by one entry at most (``table``: the table the entries are in, for
    the messages).

    Raises
    ------
    InputError
        An unknown mount, or a mount parameter varied twice (naming the later entry and the earlier).
    """
    def resolved(entries, name):
        found = []
        for i, entry in enumerate(entries):
            try:
                mounts = _names(mount_names, "mount names")(entry.mounts, "mounts") or mount_names
            except InputError as exc:
                raise exc.within(f"{name}[{i}]") from None
            found.append(dataclasses.replace(entry, mounts=mounts))
        return tuple(found)

    vary, ratios = resolved(spec.vary, "vary"), resolved(spec.stiffness_ratio, "stiffness_ratio")
    seen: dict[tuple[str, str, str], int] = {}
    for i, entry in enumerate(vary):
        for mount in entry.mounts:
            for parameter, axis in _varied(entry):
                earlier = seen.setdefault((mount, parameter, axis), i)
                if earlier != i:
                    what = f"the angle about {axis}" if parameter == "angle" else f"{parameter} {axis}"
                    raise InputError(f"vary[{i}]", f"each mount parameter varied by one [[{table}.vary]] only",
                                     Plain(f"{what} of mount {mount} varied by vary[{earlier}] too"))
    seen_ratio: dict[str, int] = {}
    for i, entry in enumerate(ratios):
        for mount in entry.mounts:
            earlier = seen_ratio.setdefault(mount, i)
            if earlier != i:
                raise InputError(f"stiffness_ratio[{i}].mounts", "each mount in one [[design.stiffness_ratio]] only",
                                 Plain(f"{mount}, in stiffness_ratio[{earlier}] too"))
    return dataclasses.replace(spec, vary=vary, stiffness_ratio=ratios)


# ----------------------------------------------------------------------------------------------------
# The [update] table: what model updating may change (sixdof.design.update).
# ----------------------------------------------------------------------------------------------------

#: What updating minimizes (:class:`UpdateSpec`): ``"modal"``, the test modes' eigen-equation residual.
UPDATE_OBJECTIVES = ("modal",)


def _bounds_table(value: Any, field: str, expected: str) -> tuple[Any, str]:
    """The ``bounds`` of a ``{bounds = ...}`` table, and its field; a tuple is bounds checked already (a copy of
    the spec, :func:`dataclasses.replace`)."""
    if isinstance(value, tuple):
        return value, field
    if not isinstance(value, dict) or set(value) != {"bounds"}:
        raise InputError(field, expected, value)
    return value["bounds"], f"{field}.bounds"


def _factor_bounds(value: Any, field: str) -> tuple[float, float]:
    bounds, field = _bounds_table(value, field, "a table {bounds = [lo, hi]} of factors with 0 < lo < hi")
    low, high = _bounds(bounds, field)
    if low <= 0:
        raise InputError(field, "factors [lo, hi] with 0 < lo < hi", [low, high])
    return low, high


def _offset_bounds(value: Any, field: str) -> tuple[tuple[float, float], ...]:
    expected = "a table {bounds = [[lo, hi], [lo, hi], [lo, hi]]} in m along x, y, z, each lo <= 0 <= hi, lo < hi"
    bounds, field = _bounds_table(value, field, expected)
    rows = finite_array(bounds, field, expected, (3, 2))
    if not np.all((rows[:, 0] <= 0) & (rows[:, 1] >= 0) & (rows[:, 0] < rows[:, 1])):
        raise InputError(field, expected, bounds)
    return tuple((float(lo), float(hi)) for lo, hi in rows)


@dataclass(frozen=True)
class UpdateSpec(Frozen):
    """The ``[update]`` table: what updating a model to a test may change, each variable within its bounds.

    ``vary``: ``[[update.vary]]`` entries, the grammar of ``[[design.vary]]`` (:class:`Vary`: stiffness factors
    per mount axis, ``tied``, positions, angles); ``mass``: a factor on the body's mass; ``inertia``: factors on
    the body's three second moments of mass along its principal axes (so the tensor stays positive definite and
    its principal moments keep the triangle inequality, :mod:`sixdof.design.update`); ``cg_offset``: where the
    centre of gravity lies from the given one [m] along x, y, z (every mount and test point moves the other way
    relative to it); ``starts``: how many starting points (the given model first, then random points within the
    bounds, ``seed``); ``objective``: ``"modal"``, the test modes' eigen-equation residual."""

    vary: tuple[Vary, ...] = ()
    mass: tuple[float, float] | None = checked(optional(_factor_bounds), default=None)
    inertia: tuple[float, float] | None = checked(optional(_factor_bounds), default=None)
    cg_offset: tuple[tuple[float, float], ...] | None = checked(optional(_offset_bounds), default=None)
    starts: int = checked(integer_check("an integer >= 1", 1), default=4)
    seed: int = checked(integer_check("an integer >= 0", 0), default=0)
    objective: str = checked(choice_check(UPDATE_OBJECTIVES), default="modal")

    def __check__(self) -> None:
        check_count(self.starts, "starts", "starts", MAX_STARTS, SECONDS_PER_START)
        if not self.vary and self.mass is None and self.inertia is None and self.cg_offset is None:
            raise InputError("vary", "at least one [[update.vary]], mass, inertia or cg_offset to update",
                             Plain("nothing to vary"))


def check_update_mounts(spec: UpdateSpec, mount_names: tuple[str, ...]) -> UpdateSpec:
    """``spec`` with each ``[[update.vary]]``'s mounts checked and resolved as :func:`check_mounts` does a
    design's (one grammar, one check)."""
    return dataclasses.replace(spec, vary=check_mounts(DesignSpec(vary=spec.vary), mount_names, "update").vary)
