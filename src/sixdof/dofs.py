"""Degree-of-freedom names, order and units, defined once for arrays, files and plot labels."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

DOFS: tuple[str, ...] = ("x", "y", "z", "rx", "ry", "rz")
"""The six generalized coordinates, in array order: translations of the centre of gravity along the
body axes, then small rotations about the central axes."""

DOF_UNITS: tuple[str, ...] = ("m", "m", "m", "rad", "rad", "rad")
"""Unit of each coordinate of ``q`` (SI)."""

#: Unit of the generalized force conjugate to each coordinate.
FORCE_UNITS: tuple[str, ...] = ("N", "N", "N", "N m", "N m", "N m")

#: Names of the generalized forces, conjugate to the DOFs: the input axis of M, C, K and receptances.
LOADS: tuple[str, ...] = ("Fx", "Fy", "Fz", "Mx", "My", "Mz")

#: Body axes: the component axis of positions, point motions and mount forces.
AXES: tuple[str, ...] = ("x", "y", "z")

#: A mount's own axes (rows of ``Mount.axes``): the axis of its stiffness and damping.
MOUNT_AXES: tuple[str, ...] = ("u", "v", "w")



# ----------------------------------------------------------------------------------------------------
# Units of stored quantities whose DOF or load axis mixes translations and rotations.
# ----------------------------------------------------------------------------------------------------


def mixed_units(translation: str, rotation: str) -> str:
    """Words for the units of an array whose DOF axis mixes translations and rotations."""
    return f"{translation} (x, y, z); {rotation} (rx, ry, rz)"


def dof_units(order: int = 0) -> tuple[str, ...]:
    """Unit of each DOF of ``q`` (order 0), ``q'`` (1) or ``q''`` (2)."""
    suffix = ("", "/s", "/s^2")[order]
    return tuple(u + suffix for u in DOF_UNITS)


#: The peak responses of a batch of variants (``peak_q`` then ``peak_qdd`` of
#: :class:`~sixdof.analysis.batch.BatchResult`), in order, with their SI units: ``|q|`` then ``|q''|`` per DOF.
PEAK_RESPONSES: tuple[tuple[str, str], ...] = (*((f"|{d}|", u) for d, u in zip(DOFS, dof_units(0))),
                                               *((f"|{d}''|", u) for d, u in zip(DOFS, dof_units(2))))


def _split(translation: str, rotation: str) -> tuple[str, ...]:
    """One unit per DOF or load label: ``translation`` for the first three, ``rotation`` for the last."""
    return (translation,) * 3 + (rotation,) * 3


@dataclass(frozen=True)
class MixedUnits:
    """Units of an array whose DOF or load axes mix translations and rotations (m and rad, N and N m),
    which no single unit string can state.

    The unit of an element is the product of one factor per mixed axis: ``factors`` maps each such axis
    (``"dof"``, ``"load"``) to the factor of each of its six labels, every one a unit string that pint
    and UDUNITS parse. In a file (and in :func:`sixdof.to_xarray`) they are the attributes
    ``<axis>_units`` beside ``units_description`` (these words), and the array has no ``units``
    attribute: unit-aware tools (pint-xarray) leave it unquantified instead of misreading it.
    """

    factors: tuple[tuple[str, tuple[str, ...]], ...]
    description: str

    def attrs(self) -> dict[str, object]:
        """The attributes that state these units in a file."""
        return {"units_description": self.description, **{f"{dim}_units": units for dim, units in self.factors}}

    @classmethod
    def from_attrs(cls, attrs, dims: tuple[str, ...]) -> MixedUnits:
        """The units stated by ``attrs`` (see :meth:`attrs`) of an array with axes ``dims``."""
        return cls(tuple((dim, tuple(attrs[f"{dim}_units"])) for dim in dims if f"{dim}_units" in attrs),
                   str(attrs["units_description"]))


def unit_attrs(units: str | MixedUnits) -> dict[str, object]:
    """The attributes that state ``units`` in a file: ``units`` for one unit, else :meth:`MixedUnits.attrs`."""
    return units.attrs() if isinstance(units, MixedUnits) else {"units": units}


def _per_dof(translation: str, rotation: str, note: str = "") -> MixedUnits:
    return MixedUnits((("dof", _split(translation, rotation)),), mixed_units(translation, rotation) + note)


def _per_load(force: str, moment: str) -> MixedUnits:
    return MixedUnits((("load", _split(force, moment)),), f"{force} (Fx, Fy, Fz); {moment} (Mx, My, Mz)")


def motion_units(order: int) -> MixedUnits:
    """Units of ``q`` (order 0), ``q'`` (1) or ``q''`` (2)."""
    units = dof_units(order)
    return _per_dof(units[0], units[3])


def per_load_units(per: str) -> MixedUnits:
    """Units of a generalized force (N, N m) per unit of an applied load in ``per`` (N or N m)."""
    per = f"({per})" if " " in per else per
    return _per_load(f"N/{per}", f"N m/{per}")


#: Units of the mixed-DOF quantities, one place for all.
UNITS: dict[str, MixedUnits] = {
    "q": motion_units(0),
    "qd": motion_units(1),
    "qdd": motion_units(2),
    "Q": _per_load("N", "N m"),
    # Matrices (load, dof): entry = load factor x dof factor, e.g. N x 1/m for the translation block of K.
    "M": MixedUnits((("load", _split("N", "N m")), ("dof", _split("s^2/m", "s^2/rad"))),
                    "kg (translation block); kg m (coupling blocks); kg m^2 (rotation block)"),
    "C": MixedUnits((("load", _split("N", "N m")), ("dof", _split("s/m", "s/rad"))),
                    "N s/m (translation block); N s/rad and N s (coupling blocks); N m s/rad (rotation block)"),
    "K": MixedUnits((("load", _split("N", "N m")), ("dof", _split("1/m", "1/rad"))),
                    "N/m (translation block); N/rad and N (coupling blocks); N m/rad (rotation block)"),
    "receptance": MixedUnits((("dof", _split("m", "rad")), ("load", _split("1/N", "1/(N m)"))),
                             "m/N (x, y, z per Fx, Fy, Fz); rad/N and m/(N m) (coupling); "
                             "rad/(N m) (rx, ry, rz per Mx, My, Mz)"),
    "shapes": _per_dof("kg^-0.5", "kg^-0.5/m", " (mass-normalized)"),
    "effective_mass": _per_dof("kg", "kg m^2"),
    "ground_transmissibility": _per_dof("m/m", "rad/m"),
}


# ----------------------------------------------------------------------------------------------------
# Display units of tables and figures.
# ----------------------------------------------------------------------------------------------------

#: For each SI unit, (factor from SI, label, threshold): the first choice whose scaled peak is at
#: least its threshold is used, so that a value prints between 1 and 1000 where it can (0.03 mm is 30 µm).
DISPLAY_UNITS: dict[str, tuple[tuple[float, str, float], ...]] = {
    "m": ((1e3, "mm", 1.0), (1e6, "µm", 1.0), (1e9, "nm", 0.0)),
    "m/s": ((1e3, "mm/s", 1.0), (1e6, "µm/s", 0.0)),
    "m/s^2": ((1.0, "m/s²", 1.0), (1e3, "mm/s²", 0.0)),
    "rad": ((1e3, "mrad", 1.0), (1e6, "µrad", 1.0), (1e9, "nrad", 0.0)),
    "rad/s": ((1e3, "mrad/s", 1.0), (1e6, "µrad/s", 0.0)),
    "rad/s^2": ((1.0, "rad/s²", 1.0), (1e3, "mrad/s²", 0.0)),
    "N": ((1e-3, "kN", 1.0), (1.0, "N", 0.0)),
    "N m": ((1e-3, "kN m", 1.0), (1.0, "N m", 0.0)),
}


def display_unit(values, unit: str) -> tuple[float, str]:
    """Factor and label that show ``values`` (in SI ``unit``) with a readable peak: the one display-unit
    scaler of the tables and figures. Units without a display choice are shown as they are."""
    choices = DISPLAY_UNITS.get(unit)
    if choices is None:
        return 1.0, unit
    peak = float(np.nanmax(np.abs(values))) if np.size(values) else 0.0
    for factor, label, threshold in choices:
        if peak * factor >= threshold:
            return factor, label
    return choices[0][0], choices[0][1]


def distinct_digits(values, least: int) -> int:
    """The fewest significant digits, at least ``least``, that print every one of ``values`` differently
    (two close modes at 15.229 and 15.234 Hz are not both "15.23 Hz"): for the tables and the figures alike."""
    values = list(values)
    return next((d for d in range(least, 9) if len({f"{v:.{d}g}" for v in values}) == len(set(values))), 9)
