"""Property-based tests (hypothesis): assembly invariants on random layouts, and random malformed
scenario files that must end in a ScenarioError, never in an unhandled exception."""

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from sixdof import Mount, RigidBody, ScenarioError, System, modal_analysis, parse_scenario
from test_scenario import BASE
from tolerances import RTOL_ZERO_ENTRY

finite = st.floats(-2.0, 2.0, allow_nan=False)
positive = st.floats(1e3, 1e7, allow_nan=False)
mounts = st.lists(
    st.tuples(st.tuples(finite, finite, finite), st.tuples(positive, positive, positive), st.integers(0, 2**32 - 1)),
    min_size=1,
    max_size=6,
)


def build(mount_data, R=np.eye(3)):
    body = RigidBody(250.0, R @ np.diag([20.0, 30.0, 40.0]) @ R.T)
    return System(
        body,
        [
            Mount(str(i), R @ np.array(p), k, axes=Rotation.random(random_state=seed).as_matrix() @ R.T)
            for i, (p, k, seed) in enumerate(mount_data)
        ],
    )


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mounts, st.integers(0, 2**32 - 1))
def test_random_layouts_keep_the_assembly_invariants(mount_data, seed):
    system = build(mount_data)
    K = system.K
    scale = np.abs(K).max()
    assert np.allclose(K, K.T, rtol=0, atol=RTOL_ZERO_ENTRY * scale)
    assert np.linalg.eigvalsh(K).min() >= -1e-11 * scale
    # Rotating the whole layout leaves the frequencies unchanged.
    rotated = build(mount_data, Rotation.random(random_state=seed).as_matrix())
    f0 = modal_analysis(system.M, system.K).eigenvalues
    f1 = modal_analysis(rotated.M, rotated.K).eigenvalues
    assert np.allclose(f1, f0, rtol=1e-8, atol=1e-9 * f0.max())


toml_values = st.one_of(
    st.integers(-10, 10),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=5),
    st.booleans(),
    st.lists(st.floats(-1e3, 1e3), max_size=4),
    st.lists(st.lists(st.integers(-2, 2), max_size=3), max_size=3),
)


def toml_literal(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return "nan" if value != value else ("inf" if value == float("inf") else "-inf" if value == float("-inf") else repr(value))
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"').encode("unicode_escape").decode() + '"'
    if isinstance(value, list):
        return "[" + ", ".join(toml_literal(v) for v in value) + "]"
    return str(value)


KEYS = [
    "mass", "inertia", "dimensions", "position", "stiffness", "damping", "name", "points", "f_hz",
    "gravity", "zeta", "kind", "start", "duration", "point", "force", "unbalance", "speed_rpm", "axis",
    "quantity", "direction", "q", "sample_rate_hz",
]


@settings(max_examples=300, deadline=None)
@given(st.sampled_from(KEYS), toml_values, st.data())
def test_malformed_scenarios_end_in_a_scenario_error(key, value, data):
    lines = BASE.splitlines()
    candidates = [i for i, line in enumerate(lines) if line.split("=")[0].strip() == key or f"{key} =" in line]
    if not candidates:
        return
    i = data.draw(st.sampled_from(candidates))
    if "{" in lines[i]:  # inline table: replace the inner value
        head, _, rest = lines[i].partition(f"{key} = ")
        tail = rest[rest.index("]") + 1 :] if rest.startswith("[") else rest[rest.find(",") if "," in rest else rest.find("}") :]
        lines[i] = f"{head}{key} = {toml_literal(value)}{tail}"
    else:
        lines[i] = f"{key} = {toml_literal(value)}"
    try:
        parse_scenario("\n".join(lines), "fuzz.toml")
    except ScenarioError as exc:
        assert str(exc).startswith("fuzz.toml: ")
