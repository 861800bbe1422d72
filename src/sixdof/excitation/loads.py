"""What acts on the body: point loads, rotating unbalance, ground motion and the initial state.

:class:`Load` (a force at a body point plus a moment, times a signal) and :class:`Unbalance`
(a rotating force ``m e Omega^2``) each expand into *components*: pairs of a constant generalized
force vector (6,) and a signal, ``Q(t) = sum_k Q_k s_k(t)``. :class:`GroundMotion` prescribes a rigid
translation of the foundation under every mount; :class:`InitialState` and :class:`ModeRelease` give
``q(0), q'(0)``. :class:`Excitation` holds them all.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import ClassVar

import numpy as np

from sixdof.dofs import DOFS
from sixdof.errors import (
    MAX_FREQUENCY_HZ,
    InputError,
    Plain,
    array_check,
    choice_check,
    direction_check,
    integer_check,
    label_check,
    number_check,
    optional,
    point_check,
    readonly,
    short,
    tuple_check,
    vector3_check,
)
from sixdof.excitation.baseline import (
    BASELINE_DEGREE,
    BASELINE_METHODS,
    MAX_BASELINE_DEGREE,
    integrate_record,
    polynomial_baseline,
)
from sixdof.excitation.signals import Harmonic, Signal, Table, signal_field
from sixdof.frozen import Frozen, checked
from sixdof.model.kinematics import generalized_force, rigid_translation


@dataclass(frozen=True, eq=False)
class Load(Frozen):
    """A force at a body point plus a moment, both scaled by a signal: ``F(t) = force s(t)``.

    Parameters
    ----------
    name : str
        Label for tables and files.
    point : array_like, shape (3,)
        Point of application from the CG in body axes [m].
    force : array_like, shape (3,), optional
        Force amplitude in body axes [N]. Default zero.
    moment : array_like, shape (3,), optional
        Moment amplitude in body axes [N m]. Default zero. ``force`` and ``moment`` are not both zero.
    signal : Signal or mapping
        The time signal (a mapping with a ``kind`` key is built with :func:`make_signal`).
    """

    kind: ClassVar[str] = "force"
    name: str = checked(label_check)
    point: np.ndarray = checked(point_check)
    force: np.ndarray = checked(vector3_check("3 force components in N"), default_factory=lambda: np.zeros(3))
    moment: np.ndarray = checked(vector3_check("3 moment components in N m"), default_factory=lambda: np.zeros(3))
    signal: Signal | None = checked(signal_field, default=None)

    def __check__(self) -> None:
        if not (np.any(self.force) or np.any(self.moment)):
            raise InputError("force", "a non-zero force or moment (N, N m)", self.force)

    def components(self) -> tuple[tuple[np.ndarray, Signal], ...]:
        """``((Q, signal),)``: the generalized force (6,) [N, N m] multiplied by the signal."""
        return self._components

    @cached_property
    def _components(self) -> tuple[tuple[np.ndarray, Signal], ...]:  # asked for several times by every solve
        return ((readonly(generalized_force(self.point, self.force, self.moment)), self.signal),)


@dataclass(frozen=True, eq=False)
class Unbalance(Frozen):
    """A rotating unbalance: the force ``m e Omega^2`` turning at constant speed in a plane.

    ``F(t) = m e Omega^2 (cos(theta) u + sin(theta) v)``, ``theta = Omega (t - start) + phase``,
    zero before ``start``. ``u, v`` span the plane normal to ``axis`` with ``u x v = axis`` (the
    rotation is positive about ``axis``); ``u`` is the body axis least aligned with ``axis``
    (x first on ties) made normal to it: for ``axis = z``, ``u = x`` and ``v = y``; for
    ``axis = x``, ``u = y, v = z``; for ``axis = y``, ``u = x, v = -z``.

    Parameters
    ----------
    name : str
    point : array_like, shape (3,)
        Centre of the rotor's plane of unbalance from the CG in body axes [m].
    unbalance : float
        ``m e`` [kg m], > 0.
    f_hz : float, optional
        Rotation frequency [Hz]; give this or ``speed_rpm``.
    speed_rpm : float, optional
        Rotation speed [rev/min].
    axis : array_like, shape (3,), optional
        Spin axis in body axes (normalized here). Default ``[0, 0, 1]``.
    phase_deg : float, optional
        Angle of the force from ``u`` at ``start`` [deg]. Default 0.
    start : float, optional
        Time the rotor is at speed from [s]. Default 0.
    """

    kind: ClassVar[str] = "unbalance"
    name: str = checked(label_check)
    point: np.ndarray = checked(point_check)
    unbalance: float = checked(number_check("a positive m e in kg m", low=0.0, strict=True))
    f_hz: float | None = checked(optional(number_check(f"a positive rotation frequency in Hz, at most "
                                                       f"{short(MAX_FREQUENCY_HZ)}", low=0.0, strict=True,
                                                       high=MAX_FREQUENCY_HZ)), default=None)
    speed_rpm: float | None = checked(optional(number_check(f"a positive speed in rev/min, at most "
                                                            f"{short(60 * MAX_FREQUENCY_HZ)}", low=0.0, strict=True,
                                                            high=60 * MAX_FREQUENCY_HZ)), default=None)
    axis: np.ndarray = checked(direction_check("a non-zero 3-vector (spin axis, body axes)"),
                               default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    phase_deg: float = checked(number_check("a finite phase in degrees"), default=0.0)
    start: float = checked(number_check("a finite time in s"), default=0.0)

    def __check__(self) -> None:
        if (self.f_hz is None) == (self.speed_rpm is None):
            raise InputError("f_hz", "either f_hz (Hz) or speed_rpm (rev/min), exactly one",
                             Plain("both" if self.f_hz is not None else "neither"))

    @property
    def frequency_hz(self) -> float:
        """Rotation frequency [Hz]."""
        return self.f_hz if self.f_hz is not None else self.speed_rpm / 60.0

    @property
    def force_amplitude(self) -> float:
        """``m e Omega^2`` [N]."""
        return self.unbalance * (2 * np.pi * self.frequency_hz) ** 2

    def components(self) -> tuple[tuple[np.ndarray, Signal], ...]:
        """Two components: ``u`` times ``cos(theta)`` and ``v`` times ``sin(theta)`` (see class doc)."""
        return self._components

    @cached_property
    def _components(self) -> tuple[tuple[np.ndarray, Signal], ...]:  # asked for several times by every solve
        e = np.eye(3)[int(np.argmin(np.abs(self.axis)))]  # the body axis least aligned with the spin axis
        u = e - np.dot(e, self.axis) * self.axis
        u /= np.linalg.norm(u)
        v = np.cross(self.axis, u)
        return tuple(  # cos(theta) = sin(theta + 90 deg) along u, sin(theta) along v
            (readonly(generalized_force(self.point, self.force_amplitude * axis)),
             Harmonic(f_hz=self.frequency_hz, phase_deg=self.phase_deg + shift, start=self.start))
            for axis, shift in ((u, 90.0), (v, 0.0))
        )


#: TOML ``kind`` of a load -> its class (``"force"`` when the key is absent).
LOAD_KINDS: dict[str, type] = {"force": Load, "unbalance": Unbalance}


GROUND_QUANTITIES = ("displacement", "velocity", "acceleration")
# A ground displacement that jumps needs an infinite force: breakpoints of a displacement signal
# may not change its value by more than this fraction of its peak.
_CONTINUITY_RTOL = 1e-6


@dataclass(frozen=True, eq=False)
class GroundMotion(Frozen):
    """Rigid translation of the foundation under every mount: ``scale s(t)`` along ``direction``.

    The foundation moves as one rigid block (no rotation); every mount's lower end follows it. The
    mount springs and dashpots then act on the body's motion *relative to the ground*.
    ``velocity`` and ``acceleration`` grounds start at rest at zero displacement at the start of a
    simulation and are integrated with the body. A ``displacement`` signal must be continuous (a
    jump would need an infinite force); its slope may jump. Where it is not zero at the start, the
    body starts displaced with it, in equilibrium (:meth:`Excitation.equilibrium`).

    Parameters
    ----------
    quantity : {"displacement", "velocity", "acceleration"}
        What ``scale s(t)`` is: m, m/s or m/s^2.
    direction : array_like, shape (3,)
        Direction in body axes [1] (normalized here).
    signal : Signal or mapping
        Shape in time (for an accelerogram: ``{kind = "table", file = "record.csv"}``).
    scale : float, optional
        Multiplies the signal [m, m/s or m/s^2 per signal unit]: ``9.81`` for a record in g.
        Default 1.
    baseline : {"none", "polynomial"}, optional
        Baseline correction of an accelerogram (a ``table`` signal of ``quantity = "acceleration"``):
        ``"polynomial"`` removes the derivative of a polynomial fitted to the record's integrated velocity,
        so that the ground ends at rest where it started (:func:`sixdof.excitation.baseline.polynomial_baseline`:
        Boore 2001; Boore, Stephens & Joyner 2002). ``signal`` is then the corrected record and ``recorded``
        the one given. Default ``"none"``: the record as given.
    baseline_degree : int, optional
        Degree of that polynomial, 2 to 6 (only with a baseline). Default 2
        (:data:`sixdof.excitation.baseline.BASELINE_DEGREE`).
    """

    quantity: str = checked(choice_check(GROUND_QUANTITIES))
    direction: np.ndarray = checked(direction_check("a non-zero 3-vector in body axes"))
    signal: Signal | None = checked(signal_field, default=None)
    scale: float = checked(number_check("a finite non-zero number"), default=1.0)
    baseline: str = checked(choice_check(BASELINE_METHODS), default="none")
    baseline_degree: int | None = checked(optional(integer_check(f"an integer from 2 to {MAX_BASELINE_DEGREE}", 2)),
                                          default=None)

    def __check__(self) -> None:
        if self.scale == 0.0:
            raise InputError("scale", "a finite non-zero number", self.scale)
        if self.baseline_degree is not None:
            if self.baseline == "none":
                raise InputError("baseline_degree", "baseline = 'polynomial' (the degree is its polynomial's)",
                                 self.baseline_degree)
            if self.baseline_degree > MAX_BASELINE_DEGREE:
                raise InputError("baseline_degree", f"an integer from 2 to {MAX_BASELINE_DEGREE}",
                                 self.baseline_degree)
        self._derive(recorded=self.signal)
        if self.baseline != "none":
            self._derive(signal=self._corrected())
        points = np.array(self.signal.breakpoints, dtype=float)
        if self.quantity != "displacement" or points.size == 0:
            return
        # Look just left of each breakpoint (far enough not to be flushed as a denormal) and
        # extrapolate with the slope there, so that a steep but continuous signal passes.
        gap = np.min(np.diff(points)) / 2 if points.size > 1 else np.inf
        eps = np.minimum(1e-9 * np.maximum(1.0, np.abs(points)), gap)
        left = points - eps
        predicted = np.asarray(self.signal(left)) + np.asarray(self.signal.derivative(left)) * eps
        after = np.asarray(self.signal(points))
        jump = np.abs(after - predicted) > _CONTINUITY_RTOL * self.signal.peak
        if np.any(jump):
            i = int(np.flatnonzero(jump)[0])
            raise InputError(
                "signal",
                "a continuous signal for a ground displacement (a jump needs an infinite force; "
                "use quantity = 'velocity' or 'acceleration')",
                Plain(f"a {self.signal.kind} signal jumping by {after[i] - predicted[i]:.6g} at "
                      f"t = {points[i]:.6g} s"),
            )

    def _corrected(self) -> Table:
        """The record with its baseline corrected (``baseline = "polynomial"``)."""
        signal = self.signal
        accelerogram = (self.quantity == "acceleration" and isinstance(signal, Table) and signal.slopes is None
                        and signal.outside == "zero")
        if not accelerogram:
            raise InputError("baseline", "'none' unless the ground is an accelerogram (quantity = 'acceleration', "
                             "a table signal with outside = 'zero' and no slopes)",
                             Plain(f"'{self.baseline}' for a {self.quantity} {signal.kind} signal"))
        degree = BASELINE_DEGREE if self.baseline_degree is None else self.baseline_degree
        if signal.t.size < degree + 2:
            raise InputError("baseline_degree" if self.baseline_degree is not None else "signal",
                             f"a record of at least {degree + 2} samples for a baseline of degree {degree}",
                             Plain(f"{signal.t.size} samples"))
        values = polynomial_baseline(signal.t, signal.values, degree)
        return Table(t=signal.t, values=values, outside="zero")

    @property
    def baseline_effect(self) -> tuple[float, float, tuple[float, float], int]:
        """What the baseline correction changed: the largest change of acceleration [m/s^2], the record's peak as
        given [m/s^2], its end velocity and displacement as given ``(v, d)`` [m/s, m] (the corrected record ends
        at rest), and the polynomial's degree. For a ground with ``baseline`` set."""
        recorded, scale = self.recorded, abs(self.scale)
        change = scale * float(np.max(np.abs(np.asarray(self.signal.values) - recorded.values)))
        v, d = integrate_record(recorded.t, self.scale * np.asarray(recorded.values))
        degree = BASELINE_DEGREE if self.baseline_degree is None else self.baseline_degree
        return change, scale * float(np.max(np.abs(recorded.values))), (float(v[-1]), float(d[-1])), degree

    @property
    def rigid_vector(self) -> np.ndarray:
        """``r`` (6,): the generalized coordinates of a unit ground translation (no rotation)."""
        return rigid_translation(self.direction)


@dataclass(frozen=True, eq=False)
class InitialState(Frozen):
    """Initial displacement and velocity of the body.

    Parameters
    ----------
    q : array_like, shape (6,), optional
        Displacement at the start from the static equilibrium there [m, m, m, rad, rad, rad]:
        absolute, unless a ground displacement is not zero at the start, when the equilibrium
        follows the ground (:meth:`Excitation.equilibrium`). Default zero (in equilibrium).
    qd : array_like, shape (6,), optional
        ``q'(start)``, absolute [m/s, rad/s]. Default zero.
    maxwell_force : array_like, shape (nb,), optional
        Force in each Maxwell branch state at the start [N], in the order of
        :attr:`sixdof.model.system.System.branches`. Default: relaxed (zero).
    """

    q: np.ndarray = checked(array_check("6 values [x, y, z, rx, ry, rz] in m and rad", (6,)),
                            default_factory=lambda: np.zeros(6))
    qd: np.ndarray = checked(array_check("6 values [x, y, z, rx, ry, rz] in m/s and rad/s", (6,)),
                             default_factory=lambda: np.zeros(6))
    maxwell_force: np.ndarray | None = None

    def state(self, system) -> tuple[np.ndarray, np.ndarray]:
        """``(q0, qd0)``, each (6,) [m, rad; m/s, rad/s], ``q0`` from the static equilibrium."""
        return np.array(self.q), np.array(self.qd)


@dataclass(frozen=True, eq=False)
class ModeRelease(Frozen):
    """Free vibration: release from rest in one undamped mode shape.

    ``q(0) = amplitude phi / phi[d]`` with ``phi`` the mode's shape and ``d`` its dominant DOF (the
    DOF holding the largest share of the mode's kinetic energy, :attr:`sixdof.model.modes.Modes.dominant_dof`),
    so ``amplitude`` is the initial displacement of that DOF; ``q'(0) = 0``. ``q(0)`` is measured from
    the static equilibrium (:meth:`Excitation.equilibrium`).

    Parameters
    ----------
    mode : int
        Mode number, 1-based in ascending frequency (1 to 6).
    amplitude : float
        Initial value of the mode's dominant DOF [m for x, y, z; rad for rx, ry, rz], non-zero.
    """

    mode: int = checked(integer_check("a mode number from 1 to 6", 1))
    amplitude: float = checked(number_check("a non-zero amplitude in m or rad"))

    def __check__(self) -> None:
        if self.mode > 6:
            raise InputError("mode", "a mode number from 1 to 6", self.mode)
        if self.amplitude == 0.0:
            raise InputError("amplitude", "a non-zero amplitude in m or rad", self.amplitude)

    def state(self, system) -> tuple[np.ndarray, np.ndarray]:
        """``(q0, qd0)`` for ``system`` (6,) each [m, rad; m/s, rad/s]."""
        modes = system.modes
        j = self.mode - 1
        d = DOFS.index(modes.dominant_dof[j])
        shape = modes.shapes[:, j]
        return self.amplitude * shape / shape[d], np.zeros(6)


@dataclass(frozen=True, eq=False)
class Excitation(Frozen):
    """Everything that drives eq. (1) in one simulation.

    Parameters
    ----------
    loads : sequence of Load or Unbalance, optional
        Acting together; names unique.
    ground : GroundMotion, optional
    initial : InitialState or ModeRelease, optional
        Default: at rest in static equilibrium.
    """

    loads: tuple = checked(tuple_check("a sequence of Load or Unbalance"), default=())
    ground: GroundMotion | None = None
    initial: InitialState | ModeRelease | None = None

    def __check__(self) -> None:
        for i, load in enumerate(self.loads):
            if not isinstance(load, tuple(LOAD_KINDS.values())):
                raise InputError(f"loads[{i}]", "a Load or Unbalance", load)
        names = [load.name for load in self.loads]
        repeated = sorted({n for n in names if names.count(n) > 1})
        if repeated:
            raise InputError("loads", "unique load names", Plain(f"{', '.join(repeated)} repeated"))
        if self.ground is not None and not isinstance(self.ground, GroundMotion):
            raise InputError("ground", "a GroundMotion", self.ground)
        if self.initial is not None and not isinstance(self.initial, (InitialState, ModeRelease)):
            raise InputError("initial", "an InitialState or a ModeRelease", self.initial)

    def components(self) -> tuple[tuple[np.ndarray, Signal], ...]:
        """Every load's ``(Q (6,) [N, N m], signal)`` pairs, in load order."""
        return tuple(c for load in self.loads for c in load.components())

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """Sorted times [s] where any load or ground signal or a derivative jumps."""
        times = {b for _, s in self.components() for b in s.breakpoints}
        if self.ground is not None:
            times.update(self.ground.signal.breakpoints)
        return tuple(sorted(times))

    def events(self, t0: float, t1: float) -> dict[str, tuple[str, float, float]]:
        """The shocks and switch-ons starting in ``[t0, t1)`` [s] (see ``Signal.event``): ``(kind, start,
        duration)`` by load name, ``"ground motion"`` for the ground's."""
        sources = [(load.name, load.components()[0][1]) for load in self.loads]
        if self.ground is not None:
            sources.append(("ground motion", self.ground.signal))
        return {name: signal.event for name, signal in sources
                if signal.event is not None and t0 <= signal.event[1] < t1}

    def idle(self, t0: float, t1: float) -> tuple[str, ...]:
        """What never acts from ``t0`` to ``t1`` [s]: one description per load (and the ground motion)
        whose signals are all zero over ``[t0, t1)`` (see ``Signal.support``). A load starting at ``t1``
        acts only after the run."""
        sources = [(f"loads[{i}] ({load.name})", [s for _, s in load.components()])
                   for i, load in enumerate(self.loads)]
        if self.ground is not None:
            sources.append(("ground motion", [self.ground.signal]))
        found = []
        for label, signals in sources:
            if all(s.support[1] <= t0 or s.support[0] >= t1 for s in signals):
                first, end = signals[0].support
                found.append(f"{label}: its {signals[0].kind} signal is zero throughout" if not first < end else
                             f"{label}: its {signals[0].kind} signal is zero outside [{first:.6g}, {end:.6g}) s")
        return tuple(found)

    def initial_state(self, system, t0: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """``(q0, qd0)`` at the start ``t0`` [s], (6,) each, absolute [m, rad; m/s, rad/s].

        ``q0`` is the static equilibrium at ``t0`` (:meth:`equilibrium`) plus ``initial``'s displacement
        from it; without ``initial`` the body is at rest in equilibrium.
        """
        q0, qd0 = (self.initial or InitialState()).state(system)
        return q0 + self.equilibrium(t0), qd0

    def initial_branch_forces(self, system) -> np.ndarray:
        """The Maxwell branch forces at the start (nb,) [N]: ``initial.maxwell_force``, or relaxed (zeros)."""
        count = system.branches.count
        given = getattr(self.initial, "maxwell_force", None)
        if given is None:
            return np.zeros(count)
        forces = np.asarray(given, dtype=float).reshape(-1)
        if forces.size != count or not np.all(np.isfinite(forces)):
            raise InputError("initial.maxwell_force", f"{count} finite forces in N (one per Maxwell branch state)",
                             given)
        return forces

    def equilibrium(self, t0: float = 0.0) -> np.ndarray:
        """Static equilibrium ``q`` (6,) at ``t0`` [s] about the unloaded one [m, rad].

        A ground displaced at ``t0`` carries the body with it, so that no mount deflects:
        ``r u_g(t0)`` (``r``: :attr:`GroundMotion.rigid_vector`). Zero otherwise, and for grounds given
        as a velocity or an acceleration, which start at zero displacement. (Gravity's static
        deflection is not in ``q``: every response here is the dynamic part about it.)
        """
        ground = self.ground
        if ground is None or ground.quantity != "displacement":
            return np.zeros(6)
        return ground.rigid_vector * float(ground.scale * ground.signal(float(t0)))

    def generalized_force(self, t) -> np.ndarray:
        """The loads' generalized force ``Q(t) = sum_k Q_k s_k(t)`` (ground motion not included).

        Parameters
        ----------
        t : array_like, shape (n,)
            Times [s].

        Returns
        -------
        ndarray, shape (n, 6)
            [N, N, N, N m, N m, N m].
        """
        t = np.atleast_1d(np.asarray(t, dtype=float))
        return sum((np.asarray(signal(t))[:, None] * vector for vector, signal in self.components()),
                   np.zeros((t.size, 6)))
