"""Degree-of-freedom names, order and units, defined once for arrays, files and plot labels."""

from __future__ import annotations

#: The six generalized coordinates, in array order: translations of the centre of gravity along the
#: body axes, then small rotations about the central axes.
DOFS: tuple[str, ...] = ("x", "y", "z", "rx", "ry", "rz")

#: Unit of each coordinate of ``q`` (SI).
DOF_UNITS: tuple[str, ...] = ("m", "m", "m", "rad", "rad", "rad")

#: Unit of the generalized force conjugate to each coordinate.
FORCE_UNITS: tuple[str, ...] = ("N", "N", "N", "N m", "N m", "N m")

#: Descriptive names used in tables and figure legends.
DOF_DESCRIPTIONS: tuple[str, ...] = (
    "translation x",
    "translation y",
    "translation z",
    "rotation about x",
    "rotation about y",
    "rotation about z",
)

#: Names of the generalized forces, conjugate to the DOFs: the input axis of M, C, K and receptances.
LOADS: tuple[str, ...] = ("Fx", "Fy", "Fz", "Mx", "My", "Mz")

#: Body axes: the component axis of positions, point motions and mount forces.
AXES: tuple[str, ...] = ("x", "y", "z")

#: A mount's own axes (rows of ``Mount.axes``): the axis of its stiffness and damping.
MOUNT_AXES: tuple[str, ...] = ("u", "v", "w")

TRANSLATIONS = slice(0, 3)
ROTATIONS = slice(3, 6)


def dof_index(name: str) -> int:
    """Index of a DOF given by name (``"x"`` .. ``"rz"``).

    Raises
    ------
    ValueError
        If ``name`` is not one of :data:`DOFS`.
    """
    try:
        return DOFS.index(name)
    except ValueError:
        raise ValueError(f"expected a DOF name, one of {', '.join(DOFS)}; got {name!r}") from None
