"""Time histories: the centre of gravity's motion per DOF, the mount forces on the foundation, and the
direct solution against the modal superposition."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from sixdof.analysis.compare import Agreement
from sixdof.analysis.response import MountForces
from sixdof.dofs import DOFS, FORCE_UNITS, display_unit, dof_units
from sixdof.errors import InputError
from sixdof.plots.common import ROTATION, TRANSLATION, margins, plot_long, require, time_axes, title
from sixdof.results import TimeHistory

_HISTORY = "a sixdof.results.TimeHistory"
#: SI unit of each DOF's column of each quantity of a TimeHistory.
_UNITS = {"q": dof_units(0), "qd": dof_units(1), "qdd": dof_units(2), "Q": FORCE_UNITS}
_QUANTITIES = {"q": "displacement", "qd": "velocity", "qdd": "acceleration", "Q": "generalized force"}
_GROUND = {"q": "ground_displacement", "qd": "ground_velocity", "qdd": "ground_acceleration"}


def plot_time_histories(history: TimeHistory, key: str = "q", *, name: str = "") -> Figure:
    """Time history of each DOF on its own axis: translations in mm, rotations in mrad.

    (µm or µrad when the peak is below 0.01 mm or 0.01 mrad; velocities and accelerations
    likewise.) With ground motion the motion relative to the ground is drawn dashed beside the
    absolute one.

    Parameters
    ----------
    history : sixdof.results.TimeHistory
        Times [s] and the motion of the centre of gravity.
    key : {"q", "qd", "qdd", "Q"}
        Displacement [m, rad] (default), velocity [m/s, rad/s], acceleration [m/s^2, rad/s^2] or
        the applied generalized force [N, N m].
    name : str
        Name of the run, put before the title.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    sixdof.errors.InputError
        For another ``key``, or a history without that quantity.
    """
    require(history, "history", TimeHistory, _HISTORY)
    if key not in _UNITS:
        raise InputError("key", f"one of {', '.join(_UNITS)}", key)
    values = getattr(history, key)
    if values is None:
        raise InputError(f"history.{key}", "an (n, 6) array", values)
    t = history.t
    fig = Figure(figsize=(12, 8))
    fig.suptitle(title(name, f"{_QUANTITIES[key]} of the centre of gravity ({key})"), fontsize=13)
    margins(fig, left=0.8, right=0.15, top=0.7, bottom=0.55, wspace=1.0, hspace=0.55, columns=2, rows=3)
    # The motion relative to the ground only when the ground moves (not merely present as zeros).
    ground = getattr(history, _GROUND[key]) if key in _GROUND else None
    relative = getattr(history, f"{key}_relative") if ground is not None and np.any(ground != 0) else None
    axes = fig.subplots(3, 2, sharex=True)
    time_axes(axes, t)
    for i, ax in enumerate(axes.T.flat):  # translations left, rotations right
        shown = values[:, i] if relative is None else np.concatenate([values[:, i], relative[:, i]])
        factor, label = display_unit(shown, _UNITS[key][i])
        plot_long(ax, t, factor * values[:, i], color=TRANSLATION if i < 3 else ROTATION, linewidth=1.0,
                  label="absolute")
        if relative is not None:
            plot_long(ax, t, factor * relative[:, i], color="black", linestyle="--", linewidth=0.9,
                      label="relative to the ground")
            if i == 0:
                ax.legend(fontsize=8, loc="best")
        ax.set_ylabel(f"{DOFS[i]} [{label}]")
        peak = float(np.max(np.abs(values[:, i])))
        ax.set_title(f"{DOFS[i]}: peak {factor * peak:.4g} {label}", fontsize=10)
    return fig


def plot_superposition(direct: TimeHistory, modal: TimeHistory, agreement: Agreement | None = None, *,
                       name: str = "") -> Figure:
    """Direct solution and modal superposition overlaid (left), and their difference divided by the
    DOF's peak (right, with the agreement tolerance dashed), per DOF.

    Parameters
    ----------
    direct : sixdof.results.TimeHistory
        The direct solve; its absolute displacement ``q`` [m, rad] is compared.
    modal : sixdof.results.TimeHistory
        The modal superposition at the same times.
    agreement : sixdof.analysis.compare.Agreement, optional
        ``compare(direct, modal)``: its worst difference goes in the title, its per-DOF values in
        the panels' titles, its tolerance [1] dashed, and its quiet DOFs are divided by the largest
        peak (rotations times its ``length`` [m]).
    name : str
        Name of the run, put before the title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    require(direct, "direct", TimeHistory, _HISTORY)
    require(modal, "modal", TimeHistory, _HISTORY)
    require(agreement, "agreement", (Agreement, type(None)), "a sixdof.analysis.compare.Agreement (or None)")
    if modal.q.shape != direct.q.shape:
        raise InputError("modal.q", f"shape {direct.q.shape} (that of direct.q)", f"shape {modal.q.shape}")
    t = direct.t
    q_direct, q_modal = direct.q, modal.q
    peaks = np.max(np.abs(q_direct), axis=0)
    fig = Figure(figsize=(13, 13))
    heading = "direct solution vs modal superposition"
    if agreement is not None:
        verdict = "within" if agreement.ok else "EXCEEDS"
        heading += (f"\nworst relative difference {agreement.worst:.2e} in "
                    f"{agreement.worst_dof} ({verdict} tolerance {agreement.tolerance:.0e})")
    fig.suptitle(title(name, heading), fontsize=13)
    margins(fig, left=0.8, right=0.15, top=1.0, bottom=0.55, wspace=1.1, hspace=0.45, columns=2, rows=6)
    axes = fig.subplots(6, 2, sharex=True)
    for i in range(6):
        factor, label = display_unit(q_direct[:, i], _UNITS["q"][i])
        left, right = axes[i]
        plot_long(left, t, factor * q_direct[:, i], color="black", linewidth=1.6, label="direct (diffrax)")
        plot_long(left, t, factor * q_modal[:, i], color="tab:orange", linewidth=1.0, linestyle="--",
                  label="modal superposition")
        left.set_ylabel(f"{DOFS[i]} [{label}]")
        # Divided as the agreement divides it: by the DOF's own peak, or for a quiet DOF (round-off
        # only) by the largest peak of all DOFs, rotations times the agreement's length (see compare).
        denominator, against = float(peaks[i]), "peak"
        if agreement is not None and DOFS[i] in tuple(agreement.quiet):
            length = float(agreement.length)
            largest = float(np.max(peaks * np.array([1.0, 1.0, 1.0, length, length, length])))
            denominator, against = (largest / length if i >= 3 else largest), "largest peak"
        difference = q_modal[:, i] - q_direct[:, i]
        relative = difference / denominator if denominator > 0 else difference
        plot_long(right, t, relative, color="tab:purple", linewidth=0.9)
        right.set_ylabel(f"Δ{DOFS[i]} / {against} [1]")
        right.ticklabel_format(axis="y", style="sci", scilimits=(-2, 2))
        # Tolerance lines only where they do not flatten the curve into a line.
        if agreement is not None and np.max(np.abs(relative)) > 0.1 * agreement.tolerance:
            for sign in (-1, 1):
                right.axhline(sign * agreement.tolerance, color="tab:red", linestyle="--", linewidth=0.8)
        if agreement is not None:
            quiet = " (quiet DOF: round-off only)" if against != "peak" else ""
            right.set_title(f"{DOFS[i]}: max|Δ| / {against} = {agreement.per_dof[i]:.2e}{quiet}", fontsize=9)
    axes[0, 0].legend(fontsize=9, loc="lower left", bbox_to_anchor=(0.0, 1.0), ncols=2, frameon=False)
    if agreement is not None:
        axes[0, 1].plot([], [], color="tab:red", linestyle="--", linewidth=0.8, label="± tolerance")
        axes[0, 1].legend(fontsize=8, loc="upper right")
    time_axes(axes, t)
    return fig


def plot_mount_forces(forces: MountForces, t, *, name: str = "") -> Figure:
    """Force of each mount on the foundation, one axis per component (x, y, z in body axes), one
    line per mount, in kN; the total foundation force dashed.

    Components get their own axes because their sizes differ by decades (vertical bearing loads vs
    horizontal ones).

    Parameters
    ----------
    forces : sixdof.analysis.response.MountForces
        ``total`` (n_mounts, n, 3) [N] of the mounts ``names``; ``foundation_force`` (n, 3) [N]
        drawn when not ``None``.
    t : array_like, shape (n,)
        Times [s] of the forces (the response's ``t``).
    name : str
        Name of the run, put before the title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    require(forces, "forces", MountForces, "a sixdof.analysis.response.MountForces")
    t = np.asarray(t, dtype=float)
    values = np.asarray(forces.total)
    if values.ndim != 3 or values.shape[1:] != (len(t), 3) or values.shape[0] != len(forces.names):
        raise InputError("forces.total", f"shape ({len(forces.names)}, {len(t)}, 3) (mounts, len(t), axes)",
                         f"shape {values.shape}")
    names = forces.names
    total = forces.foundation_force
    fig = Figure(figsize=(12, 8.5))
    fig.suptitle(title(name, "mount forces on the foundation (body axes)"), fontsize=13)
    margins(fig, left=0.8, right=0.15, top=0.75, bottom=0.55, hspace=0.2, rows=3)
    axes = fig.subplots(3, 1, sharex=True)
    for c, ax in enumerate(axes):
        component = values[:, :, c]
        shown = component if total is None else np.concatenate([component, total[None, :, c]])
        factor, label = display_unit(shown, "N")
        for k, mount in enumerate(names):
            # Thinner lines for later mounts: symmetric mounts often carry equal forces and would hide.
            width = max(2.4 - 0.4 * k, 0.8)
            plot_long(ax, t, factor * values[k, :, c], color=f"C{k % 10}", linewidth=width, label=f"mount {mount}")
        if total is not None:
            plot_long(ax, t, factor * total[:, c], color="black", linewidth=1.2, linestyle="--", label="total")
        ax.set_ylabel(f"F{'xyz'[c]} [{label}]")
    axes[0].legend(fontsize=9, loc="lower left", bbox_to_anchor=(0.0, 1.0), ncols=min(len(names) + 1, 8),
                   frameon=False)
    time_axes(axes, t)
    return fig
