"""Degree-of-freedom names, order and units, defined once for arrays, files and plot labels."""

from __future__ import annotations

#: The six generalized coordinates, in array order: translations of the centre of gravity along the
#: body axes, then small rotations about the central axes.
DOFS: tuple[str, ...] = ("x", "y", "z", "rx", "ry", "rz")

#: Unit of each coordinate of ``q`` (SI).
DOF_UNITS: tuple[str, ...] = ("m", "m", "m", "rad", "rad", "rad")

#: Unit of the generalized force conjugate to each coordinate.
FORCE_UNITS: tuple[str, ...] = ("N", "N", "N", "N m", "N m", "N m")

#: Names of the generalized forces, conjugate to the DOFs: the input axis of M, C, K and receptances.
LOADS: tuple[str, ...] = ("Fx", "Fy", "Fz", "Mx", "My", "Mz")

#: Body axes: the component axis of positions, point motions and mount forces.
AXES: tuple[str, ...] = ("x", "y", "z")

#: A mount's own axes (rows of ``Mount.axes``): the axis of its stiffness and damping.
MOUNT_AXES: tuple[str, ...] = ("u", "v", "w")



# ----------------------------------------------------------------------------------------------------
# Units of stored quantities whose DOF axis mixes translations and rotations.
# ----------------------------------------------------------------------------------------------------


def mixed_units(translation: str, rotation: str) -> str:
    """Units string of an array whose DOF axis mixes translations and rotations."""
    return f"{translation} (x, y, z); {rotation} (rx, ry, rz)"


def dof_units(order: int = 0) -> tuple[str, ...]:
    """Unit of each DOF of ``q`` (order 0), ``q'`` (1) or ``q''`` (2)."""
    suffix = ("", "/s", "/s^2")[order]
    return tuple(u + suffix for u in DOF_UNITS)


#: ``units`` strings of the mixed-DOF quantities, one place for all.
UNITS: dict[str, str] = {
    "q": mixed_units("m", "rad"),
    "qd": mixed_units("m/s", "rad/s"),
    "qdd": mixed_units("m/s^2", "rad/s^2"),
    "Q": mixed_units("N", "N m"),
    "M": "kg (translation block); kg m (coupling blocks); kg m^2 (rotation block)",
    "C": "N s/m (translation block); N s/rad and N s (coupling blocks); N m s/rad (rotation block)",
    "K": "N/m (translation block); N/rad and N (coupling blocks); N m/rad (rotation block)",
    "receptance": "m/N (x, y, z per Fx, Fy, Fz); rad/N and m/(N m) (coupling); rad/(N m) (rx, ry, rz per Mx, My, Mz)",
    "shapes": mixed_units("kg^-1/2", "kg^-1/2 m^-1") + " (mass-normalized)",
    "effective_mass": mixed_units("kg", "kg m^2"),
}


# ----------------------------------------------------------------------------------------------------
# Display units of tables and figures.
# ----------------------------------------------------------------------------------------------------

#: For each SI unit, (factor from SI, label, threshold): the first choice whose scaled peak is at
#: least its threshold is used, so that a value prints with a readable number of digits.
DISPLAY_UNITS: dict[str, tuple[tuple[float, str, float], ...]] = {
    "m": ((1e3, "mm", 0.01), (1e6, "µm", 0.0)),
    "m/s": ((1e3, "mm/s", 0.01), (1e6, "µm/s", 0.0)),
    "m/s^2": ((1.0, "m/s²", 0.01), (1e3, "mm/s²", 0.0)),
    "rad": ((1e3, "mrad", 0.01), (1e6, "µrad", 0.0)),
    "rad/s": ((1e3, "mrad/s", 0.01), (1e6, "µrad/s", 0.0)),
    "rad/s^2": ((1.0, "rad/s²", 0.01), (1e3, "mrad/s²", 0.0)),
    "N": ((1e-3, "kN", 0.01), (1.0, "N", 0.0)),
    "N m": ((1e-3, "kN m", 0.01), (1.0, "N m", 0.0)),
}


def display_unit(values, unit: str) -> tuple[float, str]:
    """Factor and label that show ``values`` (in SI ``unit``) with a readable peak: the one display-unit
    scaler of the tables and figures. Units without a display choice are shown as they are."""
    import numpy as np

    choices = DISPLAY_UNITS.get(unit)
    if choices is None:
        return 1.0, unit
    peak = float(np.nanmax(np.abs(values))) if np.size(values) else 0.0
    for factor, label, threshold in choices:
        if peak * factor >= threshold:
            return factor, label
    return choices[0][0], choices[0][1]
