"""Measured test data as one typed object (:class:`TestData`), and the scenario's ``[test]`` setup
(:class:`TestSetup`): where the test's nodes are and the limits a correlation is judged by.

:func:`sixdof.io.testfile.load_test` reads a test file (UFF58, or sixdof's own CSV) into a :class:`TestData`:
FRFs or time histories in SI units, each channel with its node, position and direction in the scenario's body
axes from the centre of gravity, so that the model's response on the same channels is
``test.response_rows() @ H6(w) @ test.load_columns()``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from sixdof.dofs import AXES, MixedUnits
from sixdof.errors import InputError, Plain, finite_array, number_check, readonly
from sixdof.frozen import Frozen, checked
from sixdof.model.kinematics import response_row, unit_load
from sixdof.results import Result, label, result_type
from sixdof.results import quantity as array_field  # the class has a field named quantity

#: What an FRF relates, by its response quantity: receptance (displacement), mobility (velocity),
#: accelerance (acceleration) per force.
FRF_QUANTITIES = {"receptance": "displacement", "mobility": "velocity", "accelerance": "acceleration"}
#: Response quantities of time data.
TIME_QUANTITIES = ("displacement", "velocity", "acceleration")
#: SI unit of each response quantity: (translation, rotation).
RESPONSE_UNITS = {"displacement": ("m", "rad"), "velocity": ("m/s", "rad/s"), "acceleration": ("m/s^2", "rad/s^2")}


def _response_quantity(test: TestData) -> str:
    return FRF_QUANTITIES.get(test.quantity, test.quantity)


def _output_units(test: TestData) -> tuple[str, ...]:
    translation, rotation = RESPONSE_UNITS[_response_quantity(test)]
    return tuple(rotation if r else translation for r in test.out_rotation)


def _reference_units(test: TestData, per: bool) -> tuple[str, ...]:
    if per:
        return tuple("1/(N m)" if r else "1/N" for r in test.ref_rotation)
    return tuple("N m" if r else "N" for r in test.ref_rotation)


def frf_units(test: TestData) -> MixedUnits:
    """The units of ``test``'s FRFs, per output and reference channel."""
    return MixedUnits((("output", _output_units(test)), ("reference", _reference_units(test, True))),
                      f"{test.quantity}: response unit per output times 1/N or 1/(N m) per reference")


def _response_units(test: TestData) -> MixedUnits:
    return MixedUnits((("output", _output_units(test)),), "response unit per output (translation or rotation)")


def _input_units(test: TestData) -> MixedUnits:
    return MixedUnits((("reference", _reference_units(test, False)),), "N (forces) or N m (moments) per reference")


def _labels(values) -> tuple[str, ...]:
    return tuple(str(v) for v in values)


def _flags(values) -> np.ndarray:
    return readonly(np.asarray(values, dtype=bool), bool)


@result_type
@dataclass(frozen=True, eq=False)
class TestData(Frozen, Result):
    """Measured FRFs or time histories of a test, channels located on the body.

    Attributes
    ----------
    name : str
        What the test is called (the file's stem by default).
    source : str
        The file it was read from.
    kind : {"frf", "time"}
    quantity : str
        ``"receptance"``, ``"mobility"`` or ``"accelerance"`` for FRFs; the measured response quantity
        (``"displacement"``, ``"velocity"``, ``"acceleration"``) for time data.
    f_hz : ndarray, shape (nf,), or None
        FRF frequencies [Hz].
    H : ndarray, shape (nf, n_out, n_ref), complex, or None
        The FRFs, SI: [m/N], [(m/s)/N], [(m/s^2)/N] for translations per force; [rad/(N m)] etc. for
        rotations and moments.
    t : ndarray, shape (n,), or None
        Times [s], evenly spaced.
    inputs : ndarray, shape (n, n_ref), or None
        The reference channels: force [N] or moment [N m].
    responses : ndarray, shape (n, n_out), or None
        The response channels, SI units of ``quantity`` (m/s^2 or rad/s^2 for accelerations).
    sample_rate_hz : float or None
        Of the time data [Hz].
    out_nodes, ref_nodes : ndarray of int, shape (n_out,), (n_ref,)
        The test's node number of each channel.
    out_positions, ref_positions : ndarray, shape (n_out, 3), (n_ref, 3)
        The nodes from the CG in body axes [m].
    out_directions, ref_directions : ndarray, shape (n_out, 3), (n_ref, 3)
        Unit vectors in body axes: the measured direction, or the axis of a rotation (of a moment).
    out_rotation, ref_rotation : ndarray of bool
        Whether a channel is a rotation (a reference: a moment).
    out_labels, ref_labels : tuple of str
        Channel names (``"101+Z"``).
    """

    __test__ = False  # not a pytest test class, for all its name

    name: str = label()
    source: str = label()
    kind: str = label()
    quantity: str = label()
    out_nodes: np.ndarray = array_field("1", ("output",), decode=lambda a: readonly(a, np.int64),
                                        description="test node of each response channel")
    out_positions: np.ndarray = array_field("m", ("output", "axis"),
                                            description="response nodes from the CG, body axes")
    out_directions: np.ndarray = array_field("1", ("output", "axis"),
                                             description="measured direction, body axes (the axis of a rotation)")
    out_rotation: np.ndarray = array_field("1", ("output",), encode=lambda a: np.asarray(a, np.int8),
                                           decode=_flags, description="1: a rotation channel")
    out_labels: tuple[str, ...] = array_field("", ("output",), decode=_labels, description="response channel names")
    ref_nodes: np.ndarray = array_field("1", ("reference",), decode=lambda a: readonly(a, np.int64),
                                        description="test node of each reference channel")
    ref_positions: np.ndarray = array_field("m", ("reference", "axis"),
                                            description="reference nodes from the CG, body axes")
    ref_directions: np.ndarray = array_field("1", ("reference", "axis"),
                                             description="force direction, body axes (the axis of a moment)")
    ref_rotation: np.ndarray = array_field("1", ("reference",), encode=lambda a: np.asarray(a, np.int8),
                                           decode=_flags, description="1: a moment reference")
    ref_labels: tuple[str, ...] = array_field("", ("reference",), decode=_labels,
                                              description="reference channel names")
    f_hz: np.ndarray | None = array_field("Hz", ("f_hz",), default=None)
    H: np.ndarray | None = array_field(frf_units, ("f_hz", "output", "reference"), default=None,
                                       description="measured FRF, response per reference")
    t: np.ndarray | None = array_field("s", ("t",), default=None)
    inputs: np.ndarray | None = array_field(_input_units, ("t", "reference"), default=None,
                                            description="measured reference forces and moments")
    responses: np.ndarray | None = array_field(_response_units, ("t", "output"), default=None,
                                               description="measured responses")
    sample_rate_hz: float | None = label(default=None, decode=float)

    def __check__(self) -> None:
        if self.kind not in ("frf", "time"):
            raise InputError("kind", "'frf' or 'time'", self.kind)
        allowed = tuple(FRF_QUANTITIES) if self.kind == "frf" else TIME_QUANTITIES
        if self.quantity not in allowed:
            raise InputError("quantity", f"one of {', '.join(allowed)} for {self.kind} data", self.quantity)
        n_out, n_ref = self._channels("out"), self._channels("ref")
        if self.kind == "frf":
            if self.f_hz is None or self.H is None:
                raise InputError("H", "FRFs (f_hz and H) in FRF data", Plain("none"))
            f = readonly(self.f_hz)
            if f.ndim != 1 or f.size < 1 or not np.all(np.isfinite(f)):
                raise InputError("f_hz", "finite frequencies in Hz, shape (nf,)", self.f_hz)
            H = readonly(self.H, complex)
            if H.shape != (f.size, n_out, n_ref):
                raise InputError("H", f"shape ({f.size}, {n_out}, {n_ref})", Plain(f"shape {H.shape}"))
            self._derive(f_hz=f, H=H)
            if any(v is not None for v in (self.t, self.inputs, self.responses)):
                raise InputError("t", "no time data in FRF data", Plain("time data"))
        else:
            if self.t is None or self.inputs is None or self.responses is None:
                raise InputError("t", "t, inputs and responses in time data", Plain("none"))
            t = readonly(self.t)
            if t.ndim != 1 or t.size < 2:
                raise InputError("t", "at least 2 times in s, shape (n,)", self.t)
            inputs, responses = readonly(self.inputs), readonly(self.responses)
            for name, value, n in (("inputs", inputs, n_ref), ("responses", responses, n_out)):
                if value.shape != (t.size, n):
                    raise InputError(name, f"shape ({t.size}, {n})", Plain(f"shape {value.shape}"))
            rate = number_check("a positive sample rate in Hz", low=0.0, strict=True)(self.sample_rate_hz,
                                                                                    "sample_rate_hz")
            self._derive(t=t, inputs=inputs, responses=responses, sample_rate_hz=float(rate))
            if self.f_hz is not None or self.H is not None:
                raise InputError("f_hz", "no FRFs in time data", Plain("FRFs"))

    def _channels(self, side: str) -> int:
        """Check the four arrays and the labels of the ``side`` ("out" or "ref") channels; their number."""
        nodes = readonly(getattr(self, f"{side}_nodes"), np.int64)
        n = nodes.shape[0] if nodes.ndim == 1 else -1
        if n < 1:
            raise InputError(f"{side}_nodes", "at least one node number, shape (n,)", getattr(self, f"{side}_nodes"))
        positions = finite_array(getattr(self, f"{side}_positions"), f"{side}_positions",
                                 f"{n} positions [x, y, z] in m", (n, 3))
        directions = finite_array(getattr(self, f"{side}_directions"), f"{side}_directions",
                                  f"{n} unit vectors", (n, 3))
        if not np.allclose(np.linalg.norm(directions, axis=1), 1.0, rtol=0, atol=1e-9):
            raise InputError(f"{side}_directions", "unit vectors", directions)
        rotation = _flags(getattr(self, f"{side}_rotation"))
        labels = _labels(getattr(self, f"{side}_labels"))
        if rotation.shape != (n,) or len(labels) != n:
            raise InputError(f"{side}_labels", f"{n} labels and rotation flags",
                             Plain(f"{len(labels)} labels, {rotation.size} flags"))
        self._derive(**{f"{side}_nodes": nodes, f"{side}_positions": positions, f"{side}_directions": directions,
                        f"{side}_rotation": rotation, f"{side}_labels": labels})
        return n

    @property
    def n_outputs(self) -> int:
        return len(self.out_labels)

    @property
    def n_references(self) -> int:
        return len(self.ref_labels)

    def response_rows(self) -> np.ndarray:
        """Rows (n_out, 6) taking the body's ``q`` to each response channel
        (:func:`~sixdof.model.kinematics.response_row`): dimensionless, m in a translation's rotation part."""
        return np.stack([response_row(p, d, bool(r)) for p, d, r in
                         zip(self.out_positions, self.out_directions, self.out_rotation)])

    def load_columns(self) -> np.ndarray:
        """Columns (6, n_ref): the generalized force [N, N m] of a unit force (moment) at each reference
        (:func:`~sixdof.model.kinematics.unit_load`)."""
        return np.stack([unit_load(p, d, bool(r)) for p, d, r in
                         zip(self.ref_positions, self.ref_directions, self.ref_rotation)], axis=1)

    def to_xarray(self):
        """This data as an :class:`xarray.Dataset`: ``H`` (f_hz, output, reference), or ``inputs`` (t, reference)
        and ``responses`` (t, output); coordinates ``output`` and ``reference`` (the labels) with each channel's
        ``*_node``, ``*_position``, ``*_direction`` (axis ``axis``) and ``*_rotation``; units as attributes
        (``units``, or ``output_units``/``reference_units`` per channel). Needs xarray."""
        import xarray as xr

        coords: dict[str, Any] = {"output": ("output", list(self.out_labels)),
                                  "reference": ("reference", list(self.ref_labels)), "axis": ("axis", list(AXES))}
        for side, dim in (("out", "output"), ("ref", "reference")):
            coords[f"{side}_node"] = (dim, np.asarray(getattr(self, f"{side}_nodes")))
            coords[f"{side}_position"] = ((dim, "axis"), np.asarray(getattr(self, f"{side}_positions")), {"units": "m"})
            coords[f"{side}_direction"] = ((dim, "axis"), np.asarray(getattr(self, f"{side}_directions")),
                                           {"units": "1"})
            coords[f"{side}_rotation"] = (dim, np.asarray(getattr(self, f"{side}_rotation")))
        variables = {}
        if self.kind == "frf":
            coords["f_hz"] = ("f_hz", np.asarray(self.f_hz), {"units": "Hz"})
            variables["H"] = (("f_hz", "output", "reference"), np.asarray(self.H), frf_units(self).attrs())
        else:
            coords["t"] = ("t", np.asarray(self.t), {"units": "s"})
            variables["inputs"] = (("t", "reference"), np.asarray(self.inputs), _input_units(self).attrs())
            variables["responses"] = (("t", "output"), np.asarray(self.responses), _response_units(self).attrs())
        attrs = {"name": self.name, "source": self.source, "kind": self.kind, "quantity": self.quantity}
        if self.sample_rate_hz is not None:
            attrs["sample_rate_hz"] = self.sample_rate_hz
        return xr.Dataset(variables, coords=coords, attrs=attrs)


# ----------------------------------------------------------------------------------------------------
# The scenario's [test] table.
# ----------------------------------------------------------------------------------------------------

#: Rows of ``[test] axes`` are orthonormal when ``|A A' - I|`` is within this (typed to 6 or more digits).
AXES_ATOL = 1e-6


def _nodes(value: Any, field: str) -> dict[int, tuple[float, float, float]]:
    if not isinstance(value, dict):
        raise InputError(field, "a table of node number = [x, y, z] in m", value)
    nodes = {}
    for key, position in value.items():
        text = str(key)
        if not text.isdigit() or int(text) < 1:
            raise InputError(f"{field}.{key}", "a positive integer node number as the key", Plain(repr(text)))
        nodes[int(text)] = tuple(finite_array(position, f"{field}.{key}", "3 coordinates [x, y, z] in m",
                                              (3,)).tolist())
    return nodes


def _origin(value: Any, field: str) -> tuple[float, float, float]:
    return tuple(finite_array(value, field, "3 coordinates [x, y, z] in m from the CG in body axes", (3,)).tolist())


def _axes(value: Any, field: str) -> tuple[tuple[float, ...], ...]:
    expected = "3 orthonormal rows (the test frame's x, y, z axes in body axes)"
    axes = finite_array(value, field, expected, (3, 3))
    error = float(np.max(np.abs(axes @ axes.T - np.eye(3))))
    if error > AXES_ATOL:
        raise InputError(field, expected, Plain(f"{axes.tolist()}, |A A' - I| up to {error:.3g}"))
    return tuple(tuple(row) for row in axes.tolist())


@dataclass(frozen=True, eq=False)
class TestSetup(Frozen):
    """The scenario's ``[test]`` table.

    Attributes
    ----------
    nodes : mapping of int to (x, y, z)
        Test node coordinates [m] in the test frame (``[test.nodes]``, node number = [x, y, z]).
    origin : (3,) float
        The test frame's origin from the CG in body axes [m].
    axes : (3, 3)
        Rows: the test frame's x, y, z axes in body axes (orthonormal).
    max_frequency_error_percent : float
        A paired mode is correlated when its frequency error is within this [%].
    min_mac : float
        ... and its MAC at least this.
    """

    __test__ = False  # not a pytest test class, for all its name

    nodes: dict = checked(_nodes, default_factory=dict)
    origin: tuple = checked(_origin, default=(0.0, 0.0, 0.0))
    axes: tuple = checked(_axes, default=((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)))
    max_frequency_error_percent: float = checked(number_check("a positive percentage", low=0.0, strict=True),
                                                 default=5.0)
    min_mac: float = checked(number_check("a MAC from 0 to 1", low=0.0, high=1.0), default=0.9)

    def to_body(self, positions) -> np.ndarray:
        """Points (..., 3) of the test frame [m] from the CG in body axes: ``origin + p @ axes``."""
        return np.asarray(self.origin) + np.asarray(positions, dtype=float) @ np.asarray(self.axes)

    def direction_to_body(self, directions) -> np.ndarray:
        """Vectors (..., 3) of the test frame in body axes: ``d @ axes``."""
        return np.asarray(directions, dtype=float) @ np.asarray(self.axes)
