"""``sixdof modes``: the modes, damping, decoupling and statics of a scenario's system, computed without files.

:func:`modal_run` computes what the command prints (:func:`sixdof.io.console.modes_text`) and
:func:`modes_json` what ``--json`` prints: the modal and statics groups of the results file, the design
metrics and, with ``sensitivity``, their derivatives.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from sixdof.analysis.design import DesignMetrics, design_metrics, sensitivities
from sixdof.analysis.statespace import damped_modes, damping_ratios
from sixdof.analysis.statics import try_gravity_statics
from sixdof.analysis.validity import RangeWarning, geometric_stiffness_note, implausible_inputs, static_range
from sixdof.io.store import build_results
from sixdof.io.tables import without_round_off
from sixdof.results import RunResults
from sixdof.workflows.prepare import prepare


@dataclass(frozen=True, eq=False)
class ModalRun:
    """What ``sixdof modes`` computes of a scenario.

    Attributes
    ----------
    results : sixdof.results.RunResults
        The system, its modes, damping ratios and statics (``None`` where there is no equilibrium), with the
        scenario and the geometric-stiffness line.
    no_statics : str or None
        Why there are no statics.
    metrics : sixdof.analysis.design.DesignMetrics
        Decoupling, torque-roll axis, elastic centre.
    sensitivities : sixdof.analysis.design.Sensitivities or None
        With ``sensitivity``: the derivatives of frequencies and decoupling per mount-axis stiffness.
    """

    results: RunResults
    no_statics: str | None
    metrics: DesignMetrics
    sensitivities: Any = None


def modal_run(scenario, *, sensitivity: bool = False) -> ModalRun:
    """The modes, damping, statics and design metrics of a scenario's system (a path is loaded); the warnings of
    inputs out of range are raised (:class:`~sixdof.analysis.validity.RangeWarning`)."""
    scenario = prepare(scenario)
    system = scenario.system
    modes = system.modes
    statics, no_statics = try_gravity_statics(system, scenario.statics.gravity, scenario.statics.direction)
    points = {p.name: p.position for p in scenario.points}
    for note in static_range(statics, system) + implausible_inputs(system, scenario.excitation, points):
        warnings.warn(note, RangeWarning, stacklevel=2)
    results = RunResults(name=scenario.name, description=scenario.description, system=system, modes=modes,
                         statics=statics, damping_ratios=damping_ratios(system.C, modes, system.branches),
                         scenario=scenario, stiffness_note=geometric_stiffness_note(system, scenario.statics.vector))
    return ModalRun(results=results, no_statics=no_statics,
                    metrics=design_metrics(system, scenario.design.torque_axis),
                    sensitivities=sensitivities(system) if sensitivity else None)


def modes_json(run: ModalRun) -> dict:
    """The modal and statics groups of the results file (:func:`sixdof.io.store.build_results`), each key the
    name of its dataset or attribute there (mode numbers from 1, like the file's), NaN as null; and, for
    scripts written before those names, the keys of earlier versions (``frequencies_hz``, ``omega_rad_s``,
    ``damping_ratios``, ``zero_modes`` (indices from 0), and in ``statics`` ``mounts``, ``mount_forces_n``,
    ``support_n``). ``mount_forces_n`` keeps the sign of those versions: the force of each mount on the body [N],
    ``-mount_force``."""
    results = run.results
    modes, statics, system = results.modes, results.statics, results.system
    tree = build_results(RunResults(name=results.name, system=system, modes=modes, statics=statics,
                                    damping_ratios=results.damping_ratios))

    def group(name):
        found = {path.split("/", 1)[1]: _plain(d.data) for path, d in tree.datasets.items()
                 if path.startswith(f"{name}/") and "/" not in path[len(name) + 1:]}
        return {**found, **{key: _plain(value) for key, value in tree.attrs.get(name, {}).items()}}

    modal = group("modal")
    modal["subsystems"] = [list(g) for g in modes.subsystems]  # stored comma-joined: HDF5 has no ragged lists
    out = {"name": results.name, "dofs": modal["dof"], **modal,
           "frequencies_hz": modal["frequency_hz"], "omega_rad_s": modal["omega"],
           "damping_ratios": modal["damping_ratio"], "zero_modes": list(modes.zero_modes), "statics": None}
    laws = system.nonlinear
    # Modes of a system with nonlinear mounts are those of its linearization about the static equilibrium.
    # Hysteretic bearings at their stated linearization, after them.
    hysteretic = system.hysteretic
    out["linearized_axes"] = list(laws.names) + list(hysteretic.names)
    out["linearized_stiffness"] = [float(k) for k in laws.tangent] + [float(k) for k in hysteretic.linear_stiffness]
    out["linearization"] = ["tangent"] * laws.count + list(hysteretic.linearization)
    out["geometric_stiffness"] = system.geometric_stiffness  # whether K (so the modes) holds gravity's K_G
    out["full_model_poles"] = _full_model_poles(system, modes)
    out.update(_design_json(run))
    if statics is not None:
        fixed = group("statics")
        # Earlier versions gave the force each mount exerts on the body (Fz > 0 under -z gravity); today's
        # mount_force is the body's force on the mount, its opposite. The legacy key keeps its own sign.
        legacy = _plain(0.0 - np.asarray(statics.mount_forces))  # 0.0 - x: no -0.0
        out["statics"] = {**fixed, "mounts": fixed["mount"], "mount_forces_n": legacy,
                          "support_n": fixed["support"]}
    return out


def _plain(value):
    """``value`` as JSON takes it: lists, with NaN (rigid-body mode) and inf (overdamped: no oscillating pole) as
    null, which JSON has neither of."""
    if isinstance(value, (tuple, list)):
        return [_plain(v) for v in value]
    value = np.asarray(value)
    if value.dtype.kind == "f":
        return np.where(np.isfinite(value), value.astype(object), None).tolist()
    return value.tolist()


def _full_model_poles(system, modes) -> dict | None:
    """With Maxwell branches, the pole of each mode in the full visco-elastic model (the augmented state space,
    :func:`sixdof.analysis.statespace.damped_modes`), as the modes table's "f full model" column shows it:
    ``frequency_hz`` |lambda| / 2 pi, ``damped_frequency_hz`` Im(lambda) / 2 pi and ``damping_ratio``
    -Re(lambda) / |lambda|, per mode (null: a rigid-body or overdamped mode); None without branches."""
    if not system.branches.count:
        return None
    poles, _ = damped_modes(system.C, modes, system.branches)
    size = np.abs(poles)
    return {"frequency_hz": _plain(size / (2 * np.pi)), "damped_frequency_hz": _plain(poles.imag / (2 * np.pi)),
            "damping_ratio": _plain(-poles.real / size)}


def _design_json(run: ModalRun) -> dict:
    """The design metrics (:func:`sixdof.analysis.design.design_metrics`), modes numbered from 1, absent
    values null; with sensitivities, the derivatives (mode, mount, axis) per mount-axis stiffness [N/m]."""
    metrics = run.metrics
    optional = {name: None if getattr(metrics, name) is None else _plain(getattr(metrics, name))
                for name in ("torque_axis", "torque_roll_axis", "roll_mode_tra_angle_deg", "decoupling_tra_percent",
                             "elastic_center")}
    out = {"decoupling_percent": _plain(metrics.decoupling_percent), **optional,
           "roll_mode": None if metrics.roll_mode is None else metrics.roll_mode + 1,
           "elastic_axes": _plain(metrics.elastic_axes), "principal_stiffness": _plain(metrics.principal_stiffness)}
    found = run.sensitivities
    if found is not None:
        def shown(values):  # masked: no derivative -> null; round-off of the mode's largest (1e-36 for 0) -> 0
            return _plain(np.where(values.mask, np.nan, without_round_off(values.data, axis=(1, 2))))

        out.update(frequency_sensitivity=shown(found.frequency), decoupling_sensitivity=shown(found.decoupling),
                   repeated_modes=[[j + 1 for j in group] for group in found.repeated_modes],
                   sensitivity_axes=["mode", "mount", "mount_axis"])
    return out
