"""The traced direct solve kept across processes (jax.export, beside the persistent compilation cache).

A repeated run in a fresh process neither traces nor imports diffrax, and gives the same numbers bit for
bit; a damaged or stale entry is ignored (traced anew, rewritten), never trusted.
"""

import hashlib
import json
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from sixdof._jax import jax
from sixdof.analysis.direct import cache

pytest.importorskip("flatbuffers", reason="jax.export writes with flatbuffers (a sixdof dependency)")

RUN = textwrap.dedent("""
    import sys
    import numpy as np
    from sixdof._jax import enable_compilation_cache
    enable_compilation_cache()
    from sixdof import Excitation, HalfSine, Harmonic, Load, SimulationSettings, simulate
    from systems import bridge
    loads = (Load("a", [0.3, 10.0, 1.0], force=[5e3, 2e4, -1e5], signal=Harmonic(f_hz=5.0)),
             Load("b", [0.4, -9.0, 0.5], force=[0.0, 0.0, 3e4], signal=HalfSine(start=0.2, duration=0.05)))
    run = simulate(bridge("elastomer"), Excitation(loads=loads), SimulationSettings(duration=1.0, sample_rate_hz=500.0))
    np.save(sys.argv[1], np.concatenate([run.q, run.qdd], axis=1))
    print("diffrax imported:", "diffrax" in sys.modules)
""")


def run_fresh(tmp_path, name):
    """One run in a fresh process with the caches in ``tmp_path``: its (q, qdd) and whether it imported diffrax."""
    env = {**os.environ, "SIXDOF_JAX_CACHE": str(tmp_path / "jax")}
    env.pop("EQX_ON_ERROR", None)  # the command line's setting comes from enable_compilation_cache
    here = os.path.dirname(__file__)
    env["PYTHONPATH"] = os.pathsep.join([here, *sys.path])
    out = tmp_path / f"{name}.npy"
    done = subprocess.run([sys.executable, "-c", RUN, str(out)], env=env, capture_output=True, text=True,
                          timeout=600, check=True)
    return np.load(out), "diffrax imported: True" in done.stdout


def entries(tmp_path):
    return sorted((tmp_path / "jax" / "sixdof_solves").glob("*.jaxexport"))


@pytest.mark.long  # ~21 CPU s
def test_a_repeated_run_neither_traces_nor_imports_diffrax(tmp_path):
    first, traced = run_fresh(tmp_path, "first")
    assert traced and len(entries(tmp_path)) == 1
    again, traced = run_fresh(tmp_path, "again")
    assert not traced
    np.testing.assert_array_equal(again, first)
    # A damaged entry is traced anew and rewritten; the numbers stay the same.
    entry = entries(tmp_path)[0]
    data = entry.read_bytes()
    entry.write_bytes(data[: len(data) // 2] + bytes(len(data) - len(data) // 2))
    repaired, traced = run_fresh(tmp_path, "repaired")
    assert traced and entry.read_bytes() == data
    np.testing.assert_array_equal(repaired, first)


def test_damaged_or_foreign_entries_are_refused(tmp_path):
    specs = [jax.ShapeDtypeStruct((3,), np.float64)]
    path = tmp_path / "entry.jaxexport"
    exported = jax.export.export(jax.jit(lambda x: 2 * x))(*specs)
    payload = bytes(exported.serialize())

    def write(key, body, digest=None):
        header = json.dumps({"key": key, "sha256": digest or hashlib.sha256(body).hexdigest()}).encode()
        path.write_bytes(header + b"\n" + body)

    write("k", payload)
    np.testing.assert_array_equal(cache._load_exported(path, "k", specs)(np.ones(3)), [2.0, 2.0, 2.0])
    assert cache._load_exported(path, "another structure", specs) is None
    assert cache._load_exported(path, "k", [jax.ShapeDtypeStruct((4,), np.float64)]) is None
    write("k", payload[:-7] + bytes(7), hashlib.sha256(payload).hexdigest())  # damaged after writing
    assert cache._load_exported(path, "k", specs) is None
    write("k", b"not an export")
    assert cache._load_exported(path, "k", specs) is None
    path.write_bytes(b"\x00garbage")
    assert cache._load_exported(path, "k", specs) is None
    assert cache._load_exported(tmp_path / "absent.jaxexport", "k", specs) is None


def test_solves_are_exported_only_beside_the_compilation_cache(monkeypatch, tmp_path):
    monkeypatch.setenv("EQX_ON_ERROR", "nan")
    assert jax.config.jax_compilation_cache_dir is None and cache._export_dir() is None  # tests leave it off
    jax.config.update("jax_compilation_cache_dir", str(tmp_path))  # nothing is compiled before it is reset
    try:
        assert cache._export_dir() == tmp_path / "sixdof_solves"
        monkeypatch.delenv("EQX_ON_ERROR")  # equinox's checks are then host callbacks, which cannot be exported
        assert cache._export_dir() is None
    finally:
        jax.config.update("jax_compilation_cache_dir", None)
