"""Run every benchmark (each in its own process, one after another) and write results.md.

Run: python benchmarks/run_all.py   (about 20 minutes on 2 cores, 15 of them the 100,000-variant sweeps)
"""

import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent

for script in ("bench_direct.py", "bench_superposition.py", "bench_frf.py", "bench_batch.py", "bench_cli.py",
               "bench_sweep.py", "bench_correlate.py", "make_table.py"):
    print(f"== {script}", flush=True)
    subprocess.run([sys.executable, str(HERE / script), *sys.argv[1:]], check=True)
