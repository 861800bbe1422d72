"""Nonlinear mounts: bump stops, lift-off and force-deflection tables, as piecewise-linear force laws.

Along one of its own axes a mount carries the load ``r(d)`` [N] for its *total* deflection ``d`` [m] from the
unloaded mount (static plus dynamic), in the sign convention of every mount load of sixdof: along the axis,
with the sign of the deflection for a spring (``r = k d``; along ``w`` compression is ``d < 0``, ``r < 0``).
The body receives ``-r``. Three things make ``r`` nonlinear, each continuous in ``d``:

- a **bump stop** (``Mount.bump_clearance``, ``Mount.bump_stiffness``): a contact spring that engages in both
  directions once ``|d|`` exceeds the clearance, adding ``k_s (|d| - c) sign(d)``;
- **lift-off** (``Mount.tension = False``): the mount carries no tension along ``w`` from any of its parts. Its
  whole load there, spring, dashpot and Maxwell branches together, ``F = r(d) + c d' + sum f_b``, is carried while
  compressive and the mount is in contact; it lifts off where ``F`` would turn to tension (not where ``d`` crosses
  zero: a dashpot pulls before) and carries nothing while lifted, its branches relaxing unloaded; it touches again
  where ``d < 0`` and ``F < 0`` both hold (the standard unilateral Kelvin-Voigt contact, ``min(F, 0)``). Lifted,
  the law is ``r = 0``: its region beyond the knot at zero, :attr:`ForceLaws.lifted_region`, whatever ``d``;
- a **force-deflection table** (:class:`ForceDeflection`): ``r`` interpolated piecewise-linearly in a measured
  table, extrapolated with its end slopes, in place of the linear stiffness on that axis.

Combined, each law is continuous and piecewise linear: knots ``X_1 < ... < X_P`` split the deflection into
``P + 1`` regions, in region ``i`` ``r = a_i + s_i d``. Inside a region the motion is linear; the direct solve
(:mod:`sixdof.analysis.direct`) locates every crossing of a knot, and every zero crossing of a lift-off mount's
``F``, as an event and changes the region there, so it never steps over a kink. The linear paths (modes, FRFs,
superposition) use the slope of the region of the static equilibrium
(:attr:`sixdof.model.system.System.equilibrium`): the linearization.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from sixdof.errors import InputError, Plain, choice_check, finite_array, label_check, readonly
from sixdof.frozen import Frozen
from sixdof.results import label, quantity

#: A mount's own axes, in the order of its 3-vectors.
AXES = ("u", "v", "w")

#: Slopes of neighbouring regions that differ by less than this (relative) are one region: a table that is
#: linear over some knots has no kink there.
SAME_SLOPE_RTOL = 1e-12


def _table_array(value, field: str) -> np.ndarray:
    array = finite_array(value, field, "a list of at least 2 numbers", (-1,))
    if array.size < 2:
        raise InputError(field, "a list of at least 2 numbers", value)
    return readonly(array)


@dataclass(frozen=True, eq=False)
class ForceDeflection(Frozen):
    """A measured force-deflection table of one mount axis, replacing its linear stiffness.

    Parameters
    ----------
    mount : str
        Name of the mount.
    axis : str
        ``"u"``, ``"v"`` or ``"w"``: the mount's own axis the table acts along.
    deflection : array_like, shape (m,)
        Deflection from the unloaded mount along the axis [m], strictly increasing, m >= 2.
    force : array_like, shape (m,)
        The mount's load at each deflection [N], in sixdof's sign convention (the sign of the deflection:
        compression along ``w`` is negative), non-decreasing (a mount whose load falls as it deflects
        further would be unstable), through zero at zero deflection. Interpolated linearly, extrapolated
        with the end slopes.
    source : str, optional
        The file it was read from (provenance).
    """

    mount: str = quantity("", (), decode=str, check=label_check, description="the mount of a force-deflection table")
    axis: str = quantity("", (), decode=str, check=choice_check(AXES), description="the mount's own axis of the table")
    deflection: np.ndarray = quantity("m", ("point",), check=_table_array,
                                      description="deflection from the unloaded mount along the axis")
    force: np.ndarray = quantity("N", ("point",), check=_table_array,
                                 description="the mount's load at each deflection (sign of the deflection)")
    source: str = label(default="")

    @property
    def name(self) -> str:
        return f"{self.mount} {self.axis}"

    def __check__(self) -> None:
        d, f = self.deflection, self.force
        where = f" of {self.source}" if self.source else ""
        if f.shape != d.shape:
            raise InputError("force", f"{d.size} forces in N, one per deflection", Plain(f"{f.size} forces"))
        if np.any(np.diff(d) <= 0):
            k = int(np.flatnonzero(np.diff(d) <= 0)[0])
            raise InputError("deflection", "strictly increasing deflections in m",
                             Plain(f"{d[k]:.6g} then {d[k + 1]:.6g} m (rows {k + 1}-{k + 2}{where})"))
        if np.any(np.diff(f) < 0):
            k = int(np.flatnonzero(np.diff(f) < 0)[0])
            raise InputError("force", "forces that never decrease as the deflection grows (a monotonic table)",
                             Plain(f"{f[k]:.6g} N at {d[k]:.6g} m, then {f[k + 1]:.6g} N at {d[k + 1]:.6g} m "
                                   f"(rows {k + 1}-{k + 2}{where})"))
        at_zero = _linear(d, f, 0.0)
        if abs(at_zero) > 1e-9 * np.abs(f).max():
            raise InputError("force", "a table through zero force at zero deflection (the unloaded mount)",
                             Plain(f"{at_zero:.6g} N at 0 m{where}"))


def _linear(x: np.ndarray, y: np.ndarray, at: float) -> float:
    """The piecewise-linear interpolation of (x, y) at ``at``, extrapolated with the end slopes."""
    if at < x[0]:
        return float(y[0] + (at - x[0]) * (y[1] - y[0]) / (x[1] - x[0]))
    if at > x[-1]:
        return float(y[-1] + (at - x[-1]) * (y[-1] - y[-2]) / (x[-1] - x[-2]))
    return float(np.interp(at, x, y))


@dataclass(frozen=True, eq=False)
class ForceLaws:
    """The nonlinear mount axes of a system, each a continuous piecewise-linear force law ``r(d)``.

    Region ``i`` of axis ``e`` lies between ``knots[e, i - 1]`` and ``knots[e, i]`` (``-inf`` and ``+inf`` at
    the ends); there ``r = intercept[e, i] + slope[e, i] d``. Knots are padded with ``+inf`` to a common count.

    Attributes
    ----------
    names : tuple of str
        ``"<mount> <axis>"``.
    kinds : tuple of str
        What makes each axis nonlinear: ``"bump stop"``, ``"lift-off"``, ``"table"``, joined by ``" + "``.
    mount, axis : ndarray of int, shape (ne,)
        The mount (index in ``System.mounts``) and its axis (0, 1, 2 for u, v, w).
    rows : ndarray, shape (ne, 6)
        The axis's deflection per unit ``q`` [m/m, m/rad].
    knots : ndarray, shape (ne, P)
        [m].
    intercept, slope : ndarray, shape (ne, P + 1)
        [N], [N/m].
    static_deflection : ndarray, shape (ne,)
        Deflection at the system's static equilibrium [m].
    clearance : ndarray, shape (ne,)
        Bump stop clearance [m] (inf: none).
    contact : ndarray, shape (ne, P + 1)
        1 in the regions where the mount touches the body along the axis, 0 where it has lifted off (its
        dashpot along the axis acts only in contact).
    damping : ndarray, shape (ne,)
        The mount's dashpot along the axis [N s/m].
    """

    names: tuple[str, ...]
    kinds: tuple[str, ...]
    mount: np.ndarray
    axis: np.ndarray
    rows: np.ndarray
    knots: np.ndarray
    intercept: np.ndarray
    slope: np.ndarray
    static_deflection: np.ndarray
    clearance: np.ndarray
    contact: np.ndarray
    damping: np.ndarray

    @property
    def count(self) -> int:
        return len(self.names)

    def region(self, d) -> np.ndarray:
        """The region of each axis at deflections ``d`` (..., ne) [m]: an int array of the same shape. A deflection
        on a knot belongs to the region nearer zero deflection: a stop engages once the deflection *exceeds* its
        clearance, a mount without preload is still in contact."""
        d = np.asarray(d, dtype=float)
        if not self.count:
            return np.zeros(d.shape, dtype=np.int64)
        return np.stack([np.where(d[..., e] >= 0, np.searchsorted(self.knots[e], d[..., e], side="left"),
                                  np.searchsorted(self.knots[e], d[..., e], side="right"))
                         for e in range(self.count)], axis=-1).astype(np.int64)

    def _pick(self, table: np.ndarray, region: np.ndarray) -> np.ndarray:
        return np.take_along_axis(np.broadcast_to(table, region.shape[:-1] + table.shape), region[..., None],
                                  axis=-1)[..., 0]

    @cached_property
    def lifts(self) -> np.ndarray:
        """Whether each axis lifts off (``Mount.tension = False``) (ne,)."""
        return np.array(["lift-off" in kind for kind in self.kinds], dtype=bool)

    @cached_property
    def lifted_region(self) -> np.ndarray:
        """The region of each axis that lifts off while lifted (ne,): beyond its last knot (zero), where ``r = 0``
        and the dashpot is off; -1 for an axis that does not lift off."""
        return np.where(self.lifts, np.isfinite(self.knots).sum(axis=1), -1).astype(np.int64)

    @cached_property
    def stiffness_scale(self) -> np.ndarray:
        """The largest slope of each law (ne,) [N/m]: turns a load into a deflection for the events of lift-off."""
        return np.maximum(np.abs(self.slope).max(axis=1, initial=0.0), np.finfo(float).tiny)

    def branch_map(self, mount, axis) -> np.ndarray:
        """(ne, nb): 1 where Maxwell branch ``b``, on mount ``mount[b]`` along ``axis[b]``, acts along law ``e``."""
        return ((self.mount[:, None] == np.asarray(mount)[None, :])
                & (self.axis[:, None] == np.asarray(axis)[None, :])).astype(float)

    def trial_force(self, d, rate, branch_force=0.0) -> np.ndarray:
        """The whole load of each axis in contact (..., ne) [N]: ``r(d) + c d' + sum f_b`` at deflections ``d`` [m],
        deflection rates ``rate`` [m/s] and forces of its Maxwell branches summed ``branch_force`` [N]."""
        return self.force(d) + self.damping * np.asarray(rate, dtype=float) + branch_force

    def state(self, d, rate, branch_force=0.0) -> np.ndarray:
        """The region of each axis (..., ne) at deflections ``d`` [m], rates ``rate`` [m/s] and branch forces
        ``branch_force`` [N]: :meth:`region`, but :attr:`lifted_region` for an axis that lifts off where its
        :meth:`trial_force` would pull."""
        region = self.region(d)
        pulls = self.lifts & (self.trial_force(d, rate, branch_force) > 0)
        return np.where(pulls, self.lifted_region, region)

    def in_contact(self, d, rate, branch_force=0.0) -> np.ndarray:
        """1 where the mount touches the body along the axis (..., ne), 0 where it has lifted off; arguments as
        :meth:`state`."""
        return self._pick(self.contact, self.state(d, rate, branch_force))

    def force(self, d) -> np.ndarray:
        """``r(d)`` (..., ne) [N] at deflections ``d`` (..., ne) [m]."""
        d = np.asarray(d, dtype=float)
        region = self.region(d)
        return self._pick(self.intercept, region) + self._pick(self.slope, region) * d

    def slopes(self, d) -> np.ndarray:
        """``r'(d)`` (..., ne) [N/m] at deflections ``d`` (..., ne) [m]: the slope of the region each is in."""
        return self._pick(self.slope, self.region(d))

    def potential(self, d) -> np.ndarray:
        """The energy stored by each law, ``integral_0^d r`` (..., ne) [J], at deflections ``d`` (..., ne) [m]."""
        d = np.asarray(d, dtype=float)
        region = self.region(d)
        start, stored = self._anchors
        x0 = self._pick(start, region)
        a, s = self._pick(self.intercept, region), self._pick(self.slope, region)
        return self._pick(stored, region) + a * (d - x0) + 0.5 * s * (d * d - x0 * x0)

    @cached_property
    def _anchors(self) -> tuple[np.ndarray, np.ndarray]:
        """A point of each region (its lower knot, or its upper for the first; 0 for a law without knots) and the
        law's integral from 0 to it (ne, P + 1)."""
        ne, P = self.knots.shape
        start = np.zeros((ne, P + 1))
        stored = np.zeros((ne, P + 1))
        for e in range(ne):
            knots = self.knots[e][np.isfinite(self.knots[e])]
            if knots.size == 0:
                continue
            points = np.concatenate([[knots[0]], knots, np.full(P - knots.size, knots[-1])])
            start[e] = points
            for i, x in enumerate(points):
                stored[e, i] = _integral(self.knots[e], self.intercept[e], self.slope[e], x)
        return start, stored

    @property
    def static_region(self) -> np.ndarray:
        return self.region(self.static_deflection)

    @property
    def static_force(self) -> np.ndarray:
        """``r`` at the static equilibrium (ne,) [N]."""
        return self.force(self.static_deflection)

    @property
    def tangent(self) -> np.ndarray:
        """The slope of each law at the static equilibrium (ne,) [N/m]: the linearization's stiffness."""
        return self.slopes(self.static_deflection)


def _integral(knots, intercept, slope, x: float) -> float:
    """``integral_0^x r`` of one law, exactly (piecewise quadratic)."""
    edges = np.concatenate([[-np.inf], knots, [np.inf]])
    low, high = min(0.0, x), max(0.0, x)
    total = 0.0
    for i in range(intercept.size):
        a, b = max(low, edges[i]), min(high, edges[i + 1])
        if b > a:
            total += intercept[i] * (b - a) + 0.5 * slope[i] * (b * b - a * a)
    return total if x >= 0 else -total


def _law(stiffness: float, table: ForceDeflection | None, clearance: float, stop: float, lift: bool):
    """Knots, intercepts and slopes of one axis: its table (or linear stiffness), bump stop and lift-off."""
    if table is not None:
        x, y = table.deflection, table.force
        left, right = (y[1] - y[0]) / (x[1] - x[0]), (y[-1] - y[-2]) / (x[-1] - x[-2])
        candidates = list(x)
    else:
        left = right = stiffness
        candidates = []

    def base(d):
        return np.array([_linear(x, y, v) for v in d]) if table is not None else stiffness * np.asarray(d)

    has_stop = np.isfinite(clearance)
    if has_stop:
        candidates += [-clearance, clearance]
        left, right = left + stop, right + stop
    if lift:
        candidates.append(0.0)
        right = 0.0
    knots = np.unique(np.asarray(candidates, dtype=float))

    def law(d):
        d = np.asarray(d, dtype=float)
        r = base(d) + (stop * (np.maximum(d - clearance, 0.0) + np.minimum(d + clearance, 0.0)) if has_stop else 0.0)
        return np.minimum(r, 0.0) if lift else r

    values = law(knots)
    slopes = np.concatenate([[left], np.diff(values) / np.diff(knots), [right]]) if knots.size else np.array([left])
    # Knots where the slope does not change are no kinks (a linear table, a stop's knot beyond a lift-off).
    scale = max(np.abs(slopes).max(), 1e-300)
    kink = np.abs(np.diff(slopes)) > SAME_SLOPE_RTOL * scale
    knots, values = knots[kink], values[kink]
    slopes = np.concatenate([slopes[:1], slopes[1:][kink]])
    points = np.concatenate([knots[:1], knots]) if knots.size else np.zeros(1)
    at = np.concatenate([values[:1], values]) if knots.size else np.zeros(1)
    # A mount that has lifted off touches nothing: its dashpot along the axis is off too.
    contact = np.ones(slopes.size) if not lift else np.concatenate([[1.0], (knots < 0).astype(float)])
    return knots, at - slopes * points, slopes, contact


def force_laws(mounts, local_map: np.ndarray, tables, equilibrium: np.ndarray) -> ForceLaws:
    """The :class:`ForceLaws` of the nonlinear axes of ``mounts`` (their deflection per unit ``q``:
    ``local_map`` (n, 3, 6)), with the force-deflection ``tables`` and the static ``equilibrium`` q (6,)."""
    by_axis = {(t.mount, AXES.index(t.axis)): t for t in tables}
    laws = []
    for j, mount in enumerate(mounts):
        for a in range(3):
            table = by_axis.get((mount.name, a))
            lift = a == 2 and not mount.tension
            clearance = float(mount.bump_clearance[a])
            if table is None and not lift and not np.isfinite(clearance):
                continue
            kinds = [k for k, on in (("table", table is not None), ("bump stop", np.isfinite(clearance)),
                                     ("lift-off", lift)) if on]
            laws.append((f"{mount.name} {AXES[a]}", " + ".join(kinds), j, a, clearance,
                         _law(float(mount.stiffness[a]), table, clearance, float(mount.bump_stiffness[a]), lift)))
    P = max((law[-1][0].size for law in laws), default=0)

    def padded(values, extra: int, fill=None):
        """One row per law, padded to P + extra with ``fill`` (default: the row's last value)."""
        rows = [np.concatenate([v, np.full(P + extra - v.size, v[-1] if fill is None else fill)]) for v in values]
        return readonly(np.array(rows).reshape(len(laws), P + extra))

    mount = np.array([law[2] for law in laws], dtype=np.int64)
    axis = np.array([law[3] for law in laws], dtype=np.int64)
    rows = local_map[mount, axis].reshape(-1, 6)
    return ForceLaws(
        names=tuple(law[0] for law in laws), kinds=tuple(law[1] for law in laws),
        mount=readonly(mount, None), axis=readonly(axis, None), rows=readonly(rows),
        knots=padded([law[-1][0] for law in laws], 0, np.inf),
        intercept=padded([law[-1][1] for law in laws], 1),
        slope=padded([law[-1][2] for law in laws], 1),
        static_deflection=readonly(rows @ np.asarray(equilibrium, dtype=float)),
        clearance=readonly([law[4] for law in laws]),
        contact=padded([law[-1][3] for law in laws], 1),
        damping=readonly([float(mounts[law[2]].damping[law[3]]) for law in laws]),
    )
