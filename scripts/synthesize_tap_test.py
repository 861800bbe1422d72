"""Synthesize the bundled tap test of ``scenarios/machine_tap_test.toml``: ``machine_tap_test.uff`` and
``machine_tap_test.truth.json`` (issue 47, item 9). Deterministic: the same files, byte for byte, every run.

The skid as built (the "truth") differs from the scenario as drawn by:

- the front left mount's vertical (w) stiffness x 0.85 (a soft mount);
- the rear pair's (rear_right, rear_left) lateral (v) stiffness x 1.20 (mounts of a stiffer batch);
- the centre of gravity 10 mm off the drawn one: 6 mm forward (+x) and 8 mm up (+z) in body axes. The inertia
  tensor about it is the drawn one; every mount and test node keeps its place on the machine, so that its
  position from the CG is the drawn position minus ``CG_OFFSET``.

Mass, inertia and the modal damping ratios (one per mode, ascending frequency) are the drawn ones.

Its accelerance [(m/s^2)/N] is measured at five triaxial accelerometers (nodes 101-104 on the base frame's
corners, 105 on top of the machine: 15 channels) for three hammer taps: node 101 along -Z (down on the base
frame), node 103 along +X and node 105 along +Y (lab directions; body +y and -x), the 45 FRFs over 1-100 Hz
every 0.1 Hz (991 lines). Each is the sum of

- the rigid body's accelerance, from sixdof's own receptance of the truth
  (:func:`sixdof.analysis.frf.receptance`; ``-w^2 H`` between the nodes' directions through the point map);
- the base frame's first torsion mode, at ``FLEX_RATIO`` = 3 times the truth's highest rigid-body frequency,
  damping ratio ``FLEX_DAMPING``: vertical displacement ``x y / (a b)`` at a node at ``(x, y)`` of the drawn
  body axes (``a, b`` = 0.70, 0.40 m, the corner nodes' half-spans: the corners move +-1, in-plane nothing), of
  modal mass ``FLEX_MODAL_MASS`` for that shape, so that its term is
  ``-w^2 phi_o phi_r / (m_f (w_f^2 - w^2 + 2 i zeta_f w_f w))``;
- noise: complex Gaussian (real and imaginary parts independent, each of variance sigma^2 / 2), with
  ``sigma = NOISE_RELATIVE * rms + NOISE_FLOOR`` per FRF, ``rms`` the FRF's noise-free rms over the band, from
  ``numpy.random.default_rng(SEED)``.

The UFF file holds a UFF15 dataset of the nodes, in the test lab's frame (its X, Y, Z along the body's +y, -x,
+z: a 90 deg turn about z; origin at ``LAB_ORIGIN`` in body axes from the drawn CG), then one UFF58 dataset per
response channel and tap, the taps in turn (function type 4, ASCII single precision, 6 significant digits;
ordinate acceleration, type 12, "m/s^2"; denominator force, type 13, "N"; abscissa Hz). Channel directions are
lab directions +1..+3; the taps' as stated (the first is -3).

Usage: ``python scripts/synthesize_tap_test.py [FOLDER]`` (default: the repository's ``scenarios/``).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
from pathlib import Path

import numpy as np

from sixdof.analysis.frf import receptance
from sixdof.io.exchange import _abscissa, _axis
from sixdof.io.scenario import load_scenario
from sixdof.model.kinematics import response_row, unit_load
from sixdof.model.system import System

SCENARIO = Path(__file__).resolve().parents[1] / "scenarios" / "machine_tap_test.toml"
NAME = "machine_tap_test"
SEED = 47

#: The as-built deviations (see the module): factors on the drawn stiffness per mount and axis (u, v, w).
STIFFNESS_FACTORS = {"front_left": (1.0, 1.0, 0.85), "front_right": (1.0, 1.0, 1.0),
                     "rear_right": (1.0, 1.20, 1.0), "rear_left": (1.0, 1.20, 1.0)}
#: Where the built body's CG lies in the drawn body axes [m].
CG_OFFSET = np.array([0.006, 0.0, 0.008])

#: The test nodes [m] in the drawn body axes from the drawn CG, and the names their UFF58 entity fields carry.
NODES = {101: (0.70, 0.40, -0.30), 102: (0.70, -0.40, -0.30), 103: (-0.70, -0.40, -0.30),
         104: (-0.70, 0.40, -0.30), 105: (0.25, -0.15, 0.50)}
NODE_NAMES = {101: "BASE_FL", 102: "BASE_FR", 103: "BASE_RR", 104: "BASE_RL", 105: "TOP"}
#: The test lab's frame: its origin [m] in the drawn body axes from the drawn CG, and its axes X, Y, Z (rows) in
#: body axes; a lab point p_lab is the body point ``LAB_ORIGIN + LAB_AXES.T @ p_lab``.
LAB_ORIGIN = np.array([0.80, -0.45, -0.50])
LAB_AXES = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
#: Response channels (node, lab direction) and the taps (node, lab direction), in the file's order.
RESPONSES = tuple((node, direction) for node in NODES for direction in (1, 2, 3))
REFERENCES = ((101, -3), (103, 1), (105, 2))

#: The band [Hz]: 991 lines, 1 to 100 Hz every 0.1 Hz.
F_HZ = 1.0 + 0.1 * np.arange(991)

#: The base frame's torsion mode (see the module).
FLEX_RATIO = 3.0
FLEX_DAMPING = 0.015
FLEX_MODAL_MASS = 250.0                       # kg, for the shape with the corners at +-1
FLEX_HALF_SPANS = (0.70, 0.40)                # m: a, b

#: Noise: sigma per FRF = NOISE_RELATIVE * its rms + NOISE_FLOOR [(m/s^2)/N].
NOISE_RELATIVE = 0.01
NOISE_FLOOR = 2e-5


def body_direction(direction: int) -> np.ndarray:
    """The unit vector in body axes of a UFF lab direction code (+-1..+-3)."""
    return np.sign(direction) * LAB_AXES[abs(direction) - 1]


def lab_position(position) -> np.ndarray:
    """A point [m] given in the drawn body axes from the drawn CG, in the lab frame."""
    return LAB_AXES @ (np.asarray(position, float) - LAB_ORIGIN)


def truth_system(nominal: System) -> System:
    """The skid as built: the drawn system with the stated stiffness factors, and every mount placed from the
    built CG (``position - CG_OFFSET``)."""
    mounts = tuple(dataclasses.replace(m, stiffness=m.stiffness * np.asarray(STIFFNESS_FACTORS[m.name]),
                                       position=m.position - CG_OFFSET) for m in nominal.mounts)
    return dataclasses.replace(nominal, mounts=mounts)


def rigid_accelerance(system: System, f_hz, cg_offset=(0.0, 0.0, 0.0)) -> np.ndarray:
    """The rigid body's accelerance [(m/s^2)/N] between the test's channels and taps.

    Parameters
    ----------
    system : System
    f_hz : array_like, shape (nf,)
        Frequencies [Hz].
    cg_offset : array_like, shape (3,)
        Where the system's CG lies in the drawn body axes [m]: the nodes are placed from it.

    Returns
    -------
    ndarray, shape (nf, n_responses, n_references), complex
    """
    A, cg_offset = receptance(system, f_hz).quantity("accelerance"), np.asarray(cg_offset, float)
    rows = np.array([response_row(np.asarray(NODES[n]) - cg_offset, body_direction(d), False) for n, d in RESPONSES])
    loads = np.array([unit_load(np.asarray(NODES[n]) - cg_offset, body_direction(d), False) for n, d in REFERENCES])
    return np.einsum("oi,fij,rj->for", rows, A, loads)


def flexible_shape(node: int, direction: int) -> float:
    """The torsion mode's displacement at ``node`` along a lab ``direction`` (per unit modal coordinate, corners
    +-1): only vertical motion, ``x y / (a b)`` in the drawn body axes."""
    x, y, _ = NODES[node]
    a, b = FLEX_HALF_SPANS
    return float(body_direction(direction) @ np.array([0.0, 0.0, x * y / (a * b)]))


def flexible_accelerance(f_hz, f_flex_hz: float) -> np.ndarray:
    """The torsion mode's accelerance term [(m/s^2)/N], shape (nf, n_responses, n_references)."""
    w, wf = 2 * np.pi * np.asarray(f_hz, float), 2 * np.pi * f_flex_hz
    out = np.array([flexible_shape(n, d) for n, d in RESPONSES])
    ref = np.array([flexible_shape(n, d) for n, d in REFERENCES])
    modal = -w**2 / (FLEX_MODAL_MASS * (wf**2 - w**2 + 2j * FLEX_DAMPING * wf * w))
    return modal[:, None, None] * out[None, :, None] * ref[None, None, :]


def noise(clean: np.ndarray) -> np.ndarray:
    """The stated noise (see the module) on FRFs ``clean`` of shape (nf, n_responses, n_references)."""
    sigma = NOISE_RELATIVE * np.sqrt(np.mean(np.abs(clean) ** 2, axis=0)) + NOISE_FLOOR
    draws = np.random.default_rng(SEED).standard_normal(clean.shape + (2,))
    return sigma * (draws[..., 0] + 1j * draws[..., 1]) / np.sqrt(2.0)


def synthesize(scenario_path=SCENARIO) -> dict:
    """Everything the files hold: the truth, its FRFs with and without noise, and the frequencies.

    Returns
    -------
    dict
        ``nominal``, ``truth`` (System), ``nominal_hz`` and ``truth_hz`` (6 rigid-body frequencies [Hz]),
        ``flex_hz`` [Hz], ``clean`` and ``noise`` (nf, n_responses, n_references) [(m/s^2)/N].
    """
    nominal = load_scenario(scenario_path).system
    truth = truth_system(nominal)
    flex_hz = FLEX_RATIO * float(truth.modes.frequency_hz[-1])
    clean = rigid_accelerance(truth, F_HZ, CG_OFFSET) + flexible_accelerance(F_HZ, flex_hz)
    return {"nominal": nominal, "truth": truth, "nominal_hz": nominal.modes.frequency_hz,
            "truth_hz": truth.modes.frequency_hz, "flex_hz": flex_hz, "clean": clean, "noise": noise(clean)}


def _direction_name(direction: int) -> str:
    return ("+" if direction > 0 else "-") + "XYZ"[abs(direction) - 1]


def uff_sets(frf: np.ndarray) -> list[dict]:
    """The UFF15 node dataset (lab frame) and one UFF58 accelerance dataset per channel and tap."""
    import pyuff

    lab = np.array([lab_position(NODES[n]) for n in NODES])
    sets = [pyuff.prepare_15(node_nums=list(NODES), x=lab[:, 0], y=lab[:, 1], z=lab[:, 2])]
    for r, (ref_node, ref_dir) in enumerate(REFERENCES):
        for o, (node, direction) in enumerate(RESPONSES):
            sets.append(pyuff.prepare_58(
                binary=0, func_type=4, ord_data_type=5, rsp_node=node, rsp_dir=direction, ref_node=ref_node,
                ref_dir=ref_dir, rsp_ent_name=NODE_NAMES[node], ref_ent_name=NODE_NAMES[ref_node],
                id1=f"{NAME}: accelerance {node}{_direction_name(direction)} / {ref_node}"
                    f"{_direction_name(ref_dir)}",
                id2=f"synthesized by scripts/synthesize_tap_test.py (seed {SEED})",
                **_axis("abscissa", 18, "Hz"), **_axis("ordinate", 12, "m/s^2"), **_axis("orddenom", 13, "N"),
                data=frf[:, o, r], x=F_HZ, num_pts=F_HZ.size, **_abscissa(F_HZ)))
    return sets


def truth_record(data: dict) -> dict:
    """The truth and the test's layout, for ``machine_tap_test.truth.json`` (frequencies to 0.1 mHz)."""
    return {
        "scenario": f"{NAME}.toml", "test_file": f"{NAME}.uff", "seed": SEED,
        "deviations": {
            "stiffness_factors": {name: {"u": u, "v": v, "w": w} for name, (u, v, w) in STIFFNESS_FACTORS.items()},
            "cg_offset_m": CG_OFFSET.tolist()},
        "nominal_frequency_hz": [round(float(f), 4) for f in data["nominal_hz"]],
        "truth_frequency_hz": [round(float(f), 4) for f in data["truth_hz"]],
        "modal_damping": list(data["truth"].modal_damping),
        "flexible_mode": {"frequency_hz": round(data["flex_hz"], 4), "ratio_to_highest_rigid": FLEX_RATIO,
                          "damping_ratio": FLEX_DAMPING, "modal_mass_kg": FLEX_MODAL_MASS,
                          "shape": "vertical x y / (a b), drawn body axes", "half_spans_m": list(FLEX_HALF_SPANS)},
        "noise": {"relative_to_rms": NOISE_RELATIVE, "floor": NOISE_FLOOR, "unit": "(m/s^2)/N"},
        "band_hz": {"min": float(F_HZ[0]), "step": 0.1, "lines": int(F_HZ.size)},
        "lab_frame": {"origin_m": LAB_ORIGIN.tolist(), "axes": LAB_AXES.tolist()},
        "nodes_body_m": {str(n): list(p) for n, p in NODES.items()},
        "responses": [[n, d] for n, d in RESPONSES], "references": [[n, d] for n, d in REFERENCES],
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", nargs="?", default=str(SCENARIO.parent), help="where to write the two files")
    folder = Path(parser.parse_args(argv).folder)
    import pyuff

    data = synthesize()
    uff = folder / f"{NAME}.uff"
    uff.unlink(missing_ok=True)
    pyuff.UFF(str(uff)).write_sets(uff_sets(data["clean"] + data["noise"]), mode="add", force_double=False)
    (folder / f"{NAME}.truth.json").write_text(json.dumps(truth_record(data), indent=2) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
