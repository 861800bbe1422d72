"""Batches of design variants (sixdof.analysis.batch) against the one-at-a-time library calls.

The batch is an independent code path (vmapped assembly, batched eigh, a vmapped 12-state solve):
its frequencies are compared with scipy's eigh through modal_analysis, its peaks with
sixdof.analysis.direct.simulate run on each variant's own System, per DOF relative to that DOF's own peak.
"""

import numpy as np
import pytest

from sixdof import (
    Excitation,
    GroundMotion,
    Harmonic,
    InputError,
    ModeRelease,
    Rayleigh,
    SimulationSettings,
    SolverError,
    System,
    modal_analysis,
    parse_scenario,
    simulate,
)
from sixdof.analysis.batch import batch_frequencies, make_variants, run_batch, variant_matrices, variant_system
from sixdof.io.sweep import parse_sweep_spec
from sixdof.workflows import sweep
from systems import bridge, bridge_toml
from tolerances import RTOL_BATCH_DIRECT, RTOL_BATCH_FREQUENCY, RTOL_BATCH_MATRIX

# Loads that move all six DOFs: an off-centre harmonic force and a pulse near one end.
SCENARIO_TOML = 'name = "beam"\n' + bridge_toml("elastomer") + """[[loads]]
name = "traffic"
point = [0.3, 10.0, 1.0]
force = [5e3, 2e4, -1e5]
signal = { kind = "harmonic", f_hz = 5.0 }
[[loads]]
name = "impact"
point = [0.4, 19.55, 0.5]
force = [2e4, -5e4, 3e4]
signal = { kind = "half_sine", start = 0.5, duration = 0.05 }
[simulation]
duration = 1.5
sample_rate_hz = 400.0
"""
SCENARIO = parse_scenario(SCENARIO_TOML)
EXCITATION, SETTINGS = SCENARIO.excitation, SCENARIO.simulation
CHUNK = 2  # 3 variants in chunks of 2: the padded last chunk is exercised


@pytest.fixture(scope="module")
def beam():
    return bridge("elastomer")


@pytest.fixture(scope="module")
def variants(beam):
    rng = np.random.default_rng(7)
    return make_variants(
        beam,
        stiffness_factor=rng.uniform(0.6, 1.5, (3, 4, 3)),
        damping_factor=rng.uniform(0.5, 2.0, (3, 4)),
        position_offset=rng.normal(0.0, 0.05, (3, 4, 3)),
    )


@pytest.fixture(scope="module")
def batch(beam, variants):
    return run_batch(beam, variants, EXCITATION, SETTINGS, histories=(2,), chunk_size=CHUNK)


def test_batch_peaks_equal_direct_simulation_one_by_one(beam, variants, batch):
    for i in range(variants.count):
        direct = simulate(variant_system(beam, variants, i), EXCITATION, SETTINGS)
        for name, peak in (("q", batch.peak_q[i]), ("qdd", batch.peak_qdd[i])):
            expected = np.max(np.abs(getattr(direct, name)), axis=0)
            assert np.all(expected > 0)
            error = np.abs(peak - expected) / expected
            assert np.all(error < RTOL_BATCH_DIRECT), (i, name, error)
    # The comparison would be weak if every variant gave the same answer.
    spread = np.ptp(batch.peak_q, axis=0) / np.max(batch.peak_q, axis=0)
    assert np.all(spread > 1e-3), spread
    assert np.all(np.ptp(batch.frequency_hz, axis=0) > 1e-3)


def test_kept_history_is_the_direct_response(beam, variants, batch):
    assert set(batch.histories) == {2}
    history = batch.histories[2]
    assert history.q.shape == (SETTINGS.times.size, 6)
    error = np.abs(np.max(np.abs(history.q), axis=0) - batch.peak_q[2]) / batch.peak_q[2]
    assert np.all(error < RTOL_BATCH_DIRECT)
    assert batch.num_steps.shape == (3,) and np.all(batch.num_steps > 0)


def test_batch_frequencies_equal_modal_analysis_per_variant(beam):
    rng = np.random.default_rng(3)
    variants = make_variants(beam, stiffness_factor=rng.uniform(0.2, 5.0, (20, 4, 3)),
                             position_offset=rng.normal(0.0, 0.3, (20, 3)))
    f = batch_frequencies(beam, variants)
    for i in range(20):
        system = variant_system(beam, variants, i)
        expected = modal_analysis(system.M, system.K).frequency_hz
        np.testing.assert_allclose(f[i], expected, rtol=RTOL_BATCH_FREQUENCY, atol=0)


def test_batched_matrices_include_rayleigh_and_modal_damping(beam):
    rng = np.random.default_rng(5)
    system = System(beam.body, beam.mounts, rayleigh=Rayleigh.from_ratio(0.02, (0.6, 38.0)),
                    modal_damping=(0.01, 0.02, 0.03, 0.01, 0.02, 0.05))
    variants = make_variants(system, stiffness_factor=rng.uniform(0.5, 2.0, (4, 4)),
                             damping_factor=rng.uniform(0.0, 3.0, (4, 4, 3)))
    K, C, _ = variant_matrices(system, variants)
    for i in range(4):
        one = variant_system(system, variants, i)
        assert np.max(np.abs(K[i] - one.K)) <= RTOL_BATCH_MATRIX * np.max(np.abs(one.K))
        assert np.max(np.abs(C[i] - one.C)) <= RTOL_BATCH_MATRIX * np.max(np.abs(one.C))


SPEC = """
count = 3
seed = 11
[[vary]]
parameter = "stiffness"
distribution = "uniform"
low = 0.8
high = 1.2
mounts = ["1", "2"]
axes = ["w"]
independent = true
[[vary]]
parameter = "damping"
distribution = "normal"
mean = 1.0
std = 0.1
"""

def test_spec_draws_only_what_it_names(beam):
    spec = parse_sweep_spec(SPEC)
    v = spec.variants(beam)
    k = v.stiffness_factor
    assert np.all(k[:, 2:] == 1.0) and np.all(k[:, :2, :2] == 1.0)  # mounts 3, 4 and axes u, v
    assert np.all((k[:, :2, 2] >= 0.8) & (k[:, :2, 2] <= 1.2)) and k[0, 0, 2] != k[0, 1, 2]
    d = v.damping_factor
    assert np.all(d == d[:, :1, :1])  # one shared draw per variant
    np.testing.assert_array_equal(spec.variants(beam).stiffness_factor, k)  # seeded


def test_grids_combine_as_a_full_factorial(beam):
    spec = parse_sweep_spec("""
[[vary]]
parameter = "stiffness"
distribution = "grid"
values = [0.5, 1.0, 2.0]
[[vary]]
parameter = "position"
distribution = "grid"
values = [0.0, 0.1]
axes = ["x"]
""")
    v = spec.variants(beam)
    assert v.count == 6
    pairs = {(float(k), float(x)) for k, x in zip(v.stiffness_factor[:, 0, 0], v.position_offset[:, 0, 0])}
    assert pairs == {(a, b) for a in (0.5, 1.0, 2.0) for b in (0.0, 0.1)}


def test_sweep_of_a_scenario_and_its_file(tmp_path, beam):
    from sixdof.io.store import load_results, load_tree, write_results
    from sixdof.results import RunResults

    spec = parse_sweep_spec(SPEC)
    result = sweep(SCENARIO, spec, chunk_size=CHUNK)
    direct = simulate(variant_system(SCENARIO.system, spec.variants(SCENARIO.system), 1), EXCITATION, SETTINGS)
    expected = np.max(np.abs(direct.q), axis=0)
    assert np.all(np.abs(result.peak_q[1] - expected) / expected < RTOL_BATCH_DIRECT)
    written = write_results(tmp_path / "sweep.h5", RunResults(name="beam", system=SCENARIO.system, sweep=result))
    back = load_tree(written.path)
    np.testing.assert_array_equal(back.array("sweep/frequency_hz"), result.frequency_hz)
    np.testing.assert_array_equal(back.array("sweep/peak_q"), result.peak_q)
    assert back["sweep/peak_q"].units == "m (x, y, z); rad (rx, ry, rz)"
    assert back["sweep/frequency_hz"].units == "Hz"
    assert back["sweep/position_offset"].units == "m"
    assert back.attrs["sweep"]["count"] == result.variants.count and back.attrs["sweep"]["solver"] == "Tsit5"
    typed = load_results(written.path).sweep
    np.testing.assert_array_equal(typed.peak_qdd, result.peak_qdd)
    np.testing.assert_array_equal(typed.variants.stiffness_factor, result.variants.stiffness_factor)
    assert typed.settings == result.settings and typed.chunk_size == result.chunk_size


@pytest.mark.parametrize("text, match", [
    ("count = 3", r"vary: expected at least one \[\[vary\]\] table, got nothing"),
    ("count = 0\n[[vary]]\nparameter='stiffness'\ndistribution='uniform'\nlow=0.5\nhigh=1.5",
     r"count: expected a positive integer, got 0"),
    ("[[vary]]\nparameter='stiffness'\ndistribution='uniform'\nlow=0.5\nhigh=1.5",
     r"count: expected a positive integer \(number of random variants\), got nothing"),
    ("count = 2\n[[vary]]\nparameter='mass'\ndistribution='uniform'\nlow=0.5\nhigh=1.5",
     r"vary\[0\]\.parameter: expected one of stiffness, damping, position, got 'mass'"),
    ("count = 2\n[[vary]]\nparameter='stiffness'\ndistribution='beta'",
     r"vary\[0\]\.distribution: expected one of uniform, normal, grid, got 'beta'"),
    ("count = 2\n[[vary]]\nparameter='stiffness'\ndistribution='uniform'\nlow=1.5\nhigh=0.5",
     r"vary\[0\]\.high: expected a number > low = 1\.5, got 0\.5"),
    ("count = 2\n[[vary]]\nparameter='stiffness'\ndistribution='normal'\nmean=1.0",
     r"vary\[0\]\.std: expected a value \(required key\), got nothing"),
    ("count = 2\n[[vary]]\nparameter='stiffness'\ndistribution='normal'\nmean=1.0\nstd=0.1\nlow=0",
     r"vary\[0\]\.low: expected only mean, std with a normal distribution, got 0"),
    ("count = 5\n[[vary]]\nparameter='stiffness'\ndistribution='grid'\nvalues=[1.0, 2.0]",
     r"count: expected the product of the grid sizes, 2 \(or no count\), got 5"),
    ("count = 2\nseeds = 1\n[[vary]]\nparameter='stiffness'\ndistribution='grid'\nvalues=[1.0, 2.0]",
     r"seeds: expected one of the keys chunk_size, count, seed, vary, got an unknown key; did you mean 'seed'\?"),
    ("count = 2\n[[vary]\n", r"spec\.toml: expected valid TOML"),
])
def test_bad_specs_are_named(text, match):
    with pytest.raises(InputError, match=match):
        parse_sweep_spec(text, "spec.toml")


def test_bad_draws_and_names_are_named(beam):
    spec = parse_sweep_spec("count = 50\n[[vary]]\nparameter='stiffness'\ndistribution='normal'\n"
                            "mean=1.0\nstd=2.0")
    with pytest.raises(InputError, match=r"vary\[0\]: expected stiffness factors > 0 \(narrow the "
                                         r"distribution\), got a draw of -"):
        spec.variants(beam)
    spec = parse_sweep_spec("count = 2\n[[vary]]\nparameter='stiffness'\ndistribution='uniform'\n"
                            "low=0.5\nhigh=1.5\nmounts=['9']")
    with pytest.raises(InputError, match=r"vary\[0\]\.mounts: expected mount names among 1, 2, 3, 4, got '9'"):
        spec.variants(beam)


def test_bad_variants_and_unsupported_excitations_are_named(beam, variants):
    with pytest.raises(InputError, match=r"stiffness_factor: expected factors > 0, got min -1"):
        make_variants(beam, stiffness_factor=[1.0, -1.0])
    with pytest.raises(InputError, match=r"variants: expected one number of variants for every "
                                         r"parameter, got counts 2, 3"):
        make_variants(beam, stiffness_factor=[1.0, 2.0], damping_factor=[1.0, 1.0, 1.0])
    with pytest.raises(InputError, match=r"position_offset: expected shape \(nv, 3\) or \(nv, 4, 3\) in m"):
        make_variants(beam, position_offset=np.zeros((2, 2)))
    ground = Excitation(ground=GroundMotion("acceleration", [0, 0, 1], Harmonic(f_hz=2.0)))
    with pytest.raises(InputError, match=r"excitation\.ground: expected no ground motion in a batch"):
        run_batch(beam, variants, ground, SETTINGS)
    release = Excitation(initial=ModeRelease(1, 1e-3))
    with pytest.raises(InputError, match=r"excitation\.initial: expected an InitialState in a batch"):
        run_batch(beam, variants, release, SETTINGS)
    with pytest.raises(InputError, match=r"histories: expected variant indices in \[0, 3\)"):
        run_batch(beam, variants, EXCITATION, SETTINGS, histories=(3,))


def test_step_limit_raises_a_solver_error_naming_the_variant(beam, variants):
    tight = SimulationSettings(duration=1.5, sample_rate_hz=400.0, max_steps=50)
    with pytest.raises(SolverError, match=r"failed for 3 of 3 variants \(first: index 0\)"):
        run_batch(beam, variants, EXCITATION, tight, chunk_size=CHUNK)
