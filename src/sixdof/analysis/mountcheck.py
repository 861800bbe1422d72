"""Mount checks of a run: total load and deflection of every mount, tension, and its limits.

The load on a mount is the force the body exerts on it, which the mount passes to the foundation
(what a mount catalogue rates), the one sign convention of every mount force of sixdof. Along the
mount's own axes u, v, w it is ``k delta + c delta'``, where ``delta`` is the deflection of the mount
from its unloaded state: the static deflection under gravity (:mod:`sixdof.analysis.statics`) plus the
dynamic deflection about it (:mod:`sixdof.analysis.response`). The mount's ``w`` axis is its normal
axis, pointing from the foundation towards the body; the normal force is reported as
``compression = -(load along w)``: **positive in compression, negative in tension** (uplift: the mount
pulls the body towards the foundation).

Rayleigh and modal damping act on the body as a whole and are attributed to no mount: a mount's
load here is its spring and dashpot only.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from sixdof.dofs import MOUNT_AXES, display_unit
from sixdof.errors import readonly
from sixdof.model.kinematics import mount_local_map
from sixdof.results import Result, label, quantity, result_type

if TYPE_CHECKING:
    from sixdof.analysis.response import MountForces
    from sixdof.analysis.statics import Statics
    from sixdof.model.system import System

#: A normal force below ``-TENSION_TOL`` times the largest normal force of the run is tension: smaller
#: ones are round-off of a mount that carries nothing.
TENSION_TOL = 1e-9

_COMPRESSION = "normal force along the mount's w axis: > 0 compression, < 0 tension (uplift)"


class MountLimitWarning(UserWarning):
    """A mount went beyond its ``max_deflection``, or into tension with ``allow_tension = false``."""


@result_type
@dataclass(frozen=True, eq=False)
class MountCheck(Result):
    """Total (static + dynamic) loads and deflections of the mounts over a run, and their limits.

    Forces are the load on each mount (the force of the body on it, passed to the foundation), along
    the mount's own axes u, v, w; ``compression`` is ``-force[..., 2]``: positive in compression,
    negative in tension. Deflections are from the unloaded mount. Times of peaks are ``nan`` where
    there is no such peak (a mount never in tension).

    Attributes
    ----------
    names : tuple of str
        Mount names (m mounts).
    preload : bool
        Whether the static load under gravity is included (False when the mounts cannot carry the
        weight: then only the dynamic part is checked).
    static_deflection, static_force : ndarray, shape (m, 3)
        Static deflection [m] and load [N] under gravity, mount axes.
    deflection, force : ndarray, shape (m, n, 3)
        Total deflection [m] and load [N] over time, mount axes.
    compression : ndarray, shape (m, n)
        Total normal force [N], > 0 compression, < 0 tension.
    peak_deflection, peak_deflection_t : ndarray, shape (m, 3)
        Largest deflection in magnitude per axis, with its sign [m], and when [s].
    peak_force, peak_force_t : ndarray, shape (m, 3)
        Largest load in magnitude per axis, with its sign [N], and when [s].
    max_compression, max_compression_t, min_compression, min_compression_t : ndarray, shape (m,)
        Extremes of the normal force [N] and their times [s]; ``min_compression < 0`` is tension.
    tension_start_t : ndarray, shape (m,)
        First time the mount is in tension [s] (``nan``: never).
    over_limit_t : ndarray, shape (m, 3)
        First time the deflection along each axis exceeds the mount's ``max_deflection`` [s] (``nan``: never).
    violations : tuple of str
        One message per mount beyond its limits (``max_deflection``, ``allow_tension``).
    """

    names: tuple[str, ...] = quantity("", ("mount",), name="mount", decode=lambda a: tuple(str(n) for n in a))
    preload: bool = label(decode=bool)
    static_deflection: np.ndarray = quantity("m", ("mount", "mount_axis"),
                                             description="static deflection under gravity from the unloaded mount")
    static_force: np.ndarray = quantity("N", ("mount", "mount_axis"),
                                        description="static load on each mount under gravity (force of the body on it)")
    deflection: np.ndarray = quantity("m", ("mount", "t", "mount_axis"),
                                      description="total deflection (static + dynamic) from the unloaded mount")
    force: np.ndarray = quantity("N", ("mount", "t", "mount_axis"),
                                 description="total load on each mount (static + dynamic; force of the body on it, "
                                 "passed to the foundation)")
    compression: np.ndarray = quantity("N", ("mount", "t"), description=f"total {_COMPRESSION}")
    peak_deflection: np.ndarray = quantity("m", ("mount", "mount_axis"),
                                           description="largest total deflection in magnitude, with its sign")
    peak_deflection_t: np.ndarray = quantity("s", ("mount", "mount_axis"), description="time of peak_deflection")
    peak_force: np.ndarray = quantity("N", ("mount", "mount_axis"),
                                      description="largest total load in magnitude, with its sign")
    peak_force_t: np.ndarray = quantity("s", ("mount", "mount_axis"), description="time of peak_force")
    max_compression: np.ndarray = quantity("N", ("mount",), description=f"largest {_COMPRESSION}")
    max_compression_t: np.ndarray = quantity("s", ("mount",), description="time of max_compression")
    min_compression: np.ndarray = quantity("N", ("mount",), description=f"smallest {_COMPRESSION}")
    min_compression_t: np.ndarray = quantity("s", ("mount",), description="time of min_compression")
    tension_start_t: np.ndarray = quantity("s", ("mount",), description="first time in tension (nan: never)")
    over_limit_t: np.ndarray = quantity("s", ("mount", "mount_axis"),
                                        description="first time the deflection exceeds max_deflection (nan: never)")
    violations: tuple[str, ...] = label(decode=lambda v: tuple(str(m) for m in v))

    @property
    def in_tension(self) -> tuple[str, ...]:
        """Names of the mounts in tension at some time of the run."""
        return tuple(n for n, t in zip(self.names, self.tension_start_t) if np.isfinite(t))


def _signed_peak(values: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Value of largest magnitude along the time axis (axis 1) with its sign, and its time."""
    k = np.argmax(np.abs(values), axis=1)
    return np.take_along_axis(values, k[:, None], axis=1)[:, 0], t[k]


def mount_check(system: System, forces: MountForces, t, statics: Statics | None = None) -> MountCheck:
    """Total loads and deflections of the mounts over a run, checked against their limits.

    Parameters
    ----------
    system : sixdof.model.system.System
        The system simulated; its mounts' ``max_deflection`` [m] and ``allow_tension`` are the limits.
    forces : sixdof.analysis.response.MountForces
        The dynamic mount forces of the run (about static equilibrium).
    t : array_like, shape (n,)
        The run's times [s].
    statics : sixdof.analysis.statics.Statics, optional
        The static equilibrium under gravity the run is about; ``None``: no preload.

    Returns
    -------
    MountCheck
        With one message per mount beyond its limits in ``violations`` (the caller warns:
        :class:`MountLimitWarning`).
    """
    t = np.asarray(t, dtype=float)
    A = np.asarray(system.axes)
    if statics is None:
        static_deflection = static_force = np.zeros((len(system.mounts), 3))
    else:
        static_deflection = mount_local_map(system.positions, A) @ statics.q
        static_force = np.asarray(statics.mount_forces_local)
    dynamic = np.einsum("mij,mnj->mni", A, np.asarray(forces.deformation))
    deflection = static_deflection[:, None, :] + dynamic
    force = static_force[:, None, :] + np.asarray(forces.local)
    compression = -force[:, :, 2]
    peak_deflection, peak_deflection_t = _signed_peak(deflection, t)
    peak_force, peak_force_t = _signed_peak(force, t)
    k_max, k_min = np.argmax(compression, axis=1), np.argmin(compression, axis=1)
    pulling = compression < -TENSION_TOL * max(float(np.abs(compression).max()), np.finfo(float).tiny)
    tension_start = np.where(pulling.any(axis=1), t[np.argmax(pulling, axis=1)], np.nan)
    rows = np.arange(len(compression))
    limits = np.array([mount.max_deflection for mount in system.mounts], dtype=float).reshape(-1, 3)
    over = np.abs(deflection) > limits[:, None, :]
    check = dict(
        names=tuple(system.mount_names), preload=statics is not None,
        static_deflection=readonly(static_deflection), static_force=readonly(static_force),
        deflection=readonly(deflection), force=readonly(force), compression=readonly(compression),
        peak_deflection=readonly(peak_deflection), peak_deflection_t=readonly(peak_deflection_t),
        peak_force=readonly(peak_force), peak_force_t=readonly(peak_force_t),
        max_compression=readonly(compression[rows, k_max]), max_compression_t=readonly(t[k_max]),
        min_compression=readonly(compression[rows, k_min]), min_compression_t=readonly(t[k_min]),
        tension_start_t=readonly(tension_start),
        over_limit_t=readonly(np.where(over.any(axis=1), t[np.argmax(over, axis=1)], np.nan)),
    )
    return MountCheck(**check, violations=_violations(system, check))


def merge_mount_checks(system: System, checks) -> MountCheck:
    """One :class:`MountCheck` over consecutive time windows of a run from each window's.

    Peaks and extremes are the windows' largest (the earliest of equal ones), first times the earliest; the
    time series are the last window's (a windowed run has written the others already).
    """
    def first_of(values):  # the earliest window's finite time, else nan
        stacked = np.stack(values)
        found = np.isfinite(stacked)
        return np.where(found.any(axis=0), np.take_along_axis(stacked, np.argmax(found, axis=0)[None], 0)[0], np.nan)

    def pick(name, rank):  # value and time of the window whose value ranks highest (ties: earliest)
        k = np.argmax(np.stack([rank(getattr(c, name)) for c in checks]), axis=0)[None]
        value, when = (np.take_along_axis(np.stack([getattr(c, n) for c in checks]), k, 0)[0]
                       for n in (name, f"{name}_t"))
        return {name: readonly(value), f"{name}_t": readonly(when)}

    last = checks[-1]
    check = dict(
        names=last.names, preload=last.preload, static_deflection=last.static_deflection,
        static_force=last.static_force, deflection=last.deflection, force=last.force, compression=last.compression,
        **pick("peak_deflection", np.abs), **pick("peak_force", np.abs), **pick("max_compression", np.asarray),
        **pick("min_compression", np.negative),
        tension_start_t=readonly(first_of([c.tension_start_t for c in checks])),
        over_limit_t=readonly(first_of([c.over_limit_t for c in checks])),
    )
    return MountCheck(**check, violations=_violations(system, check))


def _violations(system: System, check: dict) -> tuple[str, ...]:
    return tuple(filter(None, (_violation(mount, j, check) for j, mount in enumerate(system.mounts))))


def _violation(mount, j: int, check: dict) -> str:
    """The message for mount ``j`` beyond its limits, or ``""``."""
    found = []
    for i, axis in enumerate(MOUNT_AXES):
        limit = mount.max_deflection[i]
        if np.isfinite(check["over_limit_t"][j, i]):
            scale, unit = display_unit(limit, "m")
            found.append(f"deflection along {axis} {check['peak_deflection'][j, i] * scale:.4g} {unit} at "
                         f"t = {check['peak_deflection_t'][j, i]:.4g} s, beyond its max_deflection "
                         f"{limit * scale:.4g} {unit} (first at t = {check['over_limit_t'][j, i]:.4g} s)")
    if not mount.allow_tension and np.isfinite(check["tension_start_t"][j]):
        scale, unit = display_unit(check["min_compression"][j], "N")
        found.append(f"in tension (allow_tension = false): {-check['min_compression'][j] * scale:.4g} {unit} "
                     f"at t = {check['min_compression_t'][j]:.4g} s (first at t = {check['tension_start_t'][j]:.4g} s)")
    return f"mount {mount.name!r}: " + "; ".join(found) if found else ""


#: A mount set carries shear worth its own figure (mount_shear.png) when some mount's dynamic shear load (the
#: resultant of u and v) reaches this fraction of the largest dynamic excursion of the normal forces: braking or a
#: longitudinal quake load a bearing in shear, and its shear deflection, not its normal force, is what the
#: design checks.
SHEAR_SHARE = 0.25


def carries_shear(check: MountCheck) -> bool:
    """Whether ``check``'s mounts carry a shear load worth its own figure (:data:`SHEAR_SHARE`)."""
    force = np.asarray(check.force, dtype=float)
    if not force.size:
        return False
    # Dynamic parts against dynamic parts: an inclined mount's static shear is no reason for the figure.
    static = np.asarray(check.static_force, dtype=float) if check.preload else np.zeros((len(check.names), 3))
    dynamic = force - static[:, None, :]
    shear = float(np.max(np.hypot(dynamic[..., 0], dynamic[..., 1])))
    normal = float(np.max(np.abs(dynamic[..., 2])))
    return shear > 0.0 and shear >= SHEAR_SHARE * normal


__all__ = ["MountCheck", "MountLimitWarning", "SHEAR_SHARE", "TENSION_TOL", "carries_shear", "merge_mount_checks",
           "mount_check"]
