"""Full 6x6 receptance of the bridge beam at 10,000 frequencies (sixdof.analysis.frf.receptance).

Run: python benchmarks/bench_frf.py
"""

from __future__ import annotations

import sys

import numpy as np

import common

TARGET_MS = 3.0


def main(argv):
    from sixdof.analysis.frf import receptance

    system = common.bridge_system()
    f = np.geomspace(0.1, 100.0, 10_000)
    receptance(system, f)  # warm caches (System's cached matrices)
    rows = {}
    for method in ("direct", "modal"):
        best_s, median_s, frf = common.best(lambda method=method: receptance(system, f, method=method), 30)
        rows[method] = {"best_ms": best_s * 1e3, "median_ms": median_s * 1e3, "basis": frf.basis}
        print(f"receptance {method}: best {best_s * 1e3:.2f} ms, median {median_s * 1e3:.2f} ms")
    # Reference point: numpy's batched inverse alone on the same (10000, 6, 6) complex stack.
    Z = (np.asarray(system.K)[None] - (2 * np.pi * f[:, None, None]) ** 2 * np.asarray(system.M)[None]
         + 1j * 2 * np.pi * f[:, None, None] * np.asarray(system.C)[None])
    inv_s, _, _ = common.best(lambda: np.linalg.inv(Z), 30)
    rows["numpy_inv_only"] = {"best_ms": inv_s * 1e3}
    path = common.save("frf", {"frequencies": f.size, "rows": rows, "target_ms": TARGET_MS})
    print(f"-> {path}")


if __name__ == "__main__":
    main(sys.argv[1:])
