"""7 spectrum-compatible records of 20 s at 0.01 s for the bundled bridge ([spectrum] records, issue 48 point 5):
matching and checking them (SIMQKE, analysis.matching.ec8_suite) and the 7 direct solves (record_peaks), with what
they give: mean/target over 0.2-2 T1, mean PGA against ag S, the x peak against the spectrum's.

Run: python benchmarks/bench_records.py
"""

from __future__ import annotations

import math
import sys

import common

SCENARIO = common.ROOT / "scenarios" / "bridge_beam.toml"
SPECTRUM = """
[damping]
modal = 0.05

[spectrum]
code = "ec8"
type = 1
ground_type = "C"
ag = 2.45
directions = ["x", "y"]
records = { count = 7, seed = 1, duration = 20.0, dt = 0.01, direction = "x" }
"""


def main(argv):
    from sixdof import parse_scenario, run
    from sixdof.analysis.matching import ec8_suite, elastic_target
    from sixdof.analysis.record_peaks import record_peaks

    scenario = parse_scenario(SCENARIO.read_text(encoding="utf-8") + SPECTRUM)
    results = run(scenario)  # compiles the solve; the figures below are measured after it
    settings, spectrum = scenario.spectrum_records, results.spectrum
    t1 = float(spectrum.period[spectrum.dominant_mode("x")])
    target = elastic_target(scenario.response_spectrum.spectrum, "x", t1, settings.dt)
    match_s, _, (suite, check) = common.best(lambda: ec8_suite(target.periods, target.sa, settings, ag_s=target.ag_s,
                                                               fundamental_period=t1), 3)
    f_max = float(results.system.modes.frequency_hz.max())  # the run seeks peaks at 10 samples per its period
    rate = math.ceil(10 * f_max * settings.dt) / settings.dt
    solve_s, _, peaks = common.best(lambda: record_peaks(results.system, suite.records, "x", sample_rate_hz=rate), 3)
    ratio = float(peaks.design_q[0] / spectrum.peak_q[0, 0])
    print(f"T1 {t1:.4g} s; mean/target over 0.2-2 T1 {check.min_ratio:.4f}-{check.max_ratio:.4f}; mean PGA "
          f"{check.pga_mean:.4g} m/s^2 vs ag S {check.ag_s:.4g}; x peak {ratio:.4f} of the spectrum's")
    print(f"match and check 7 x 20 s: best {match_s:.2f} s; 7 solves of 20 s: best {solve_s:.2f} s")
    path = common.save("records", {"t1_s": t1, "min_ratio": check.min_ratio, "max_ratio": check.max_ratio,
                                   "pga_mean": check.pga_mean, "ag_s": check.ag_s, "x_peak_ratio": ratio,
                                   "match_s": match_s, "solves_s": solve_s})
    print(f"-> {path}")


if __name__ == "__main__":
    main(sys.argv[1:])
