"""The documentation's gallery, drawn by the build: an mkdocs hook (``hooks:`` in mkdocs.yml).

At each ``mkdocs build`` it computes a few cheap bundled scenarios with the library (``sixdof.run`` and
``sixdof.plots.save_all``; the optimizer and the correlation as their commands do), adds their figures to the
site as ``gallery/<scenario>/<figure>.png`` and writes the page ``gallery.md`` that shows them, so no gallery
figure is committed by hand and every figure a guide shows is the library's output of today. The figures are
kept in ``build/docs-gallery/<key>/``, the key a hash of the package's source and the scenarios' files, so that
a rebuild with neither changed (``mkdocs serve``) draws nothing again.
"""

import hashlib
import logging
import shutil
import tempfile
import time
import warnings
from pathlib import Path

from mkdocs.structure.files import File

import sixdof
from sixdof.plots import save_all
from sixdof.workflows.correlate import correlation_run, save_correlation
from sixdof.workflows.optimize import design_run, save_design

log = logging.getLogger("mkdocs.hooks.gallery")

ROOT = Path(__file__).resolve().parents[1]

#: What the gallery draws: (scenario, kind, what it shows). ``run``: the figures of ``sixdof run``; ``design``: of
#: ``sixdof optimize``; ``correlate``: of ``sixdof correlate --update`` against the bundled tap test.
ENTRIES = (
    ("bridge_beam_traffic", "run", "The main example: the seed's bridge beam on damped bearings under an off-centre "
     "harmonic traffic load (getting started, modal analysis, time response, FRFs)."),
    ("bridge_beam_braking", "run", "The bridge beam under a braking force and a wheel impact (time response and "
     "its cross-check)."),
    ("machine_unbalance", "run", "A compressor on four isolators with a rotating unbalance, isolated above "
     "resonance (FRFs and transmissibility)."),
    ("electronics_box", "run", "A box on four isolators under a random base PSD and a half-sine shock (random "
     "vibration and shock)."),
    ("equipment_elastomer", "run", "A cabinet on elastomer mounts fitted from a measured dynamic stiffness table "
     "(visco-elastic mounts)."),
    ("equipment_snubbed_shock", "run", "A cabinet on snubbed wire-rope isolators bumped by a trolley (nonlinear "
     "mounts)."),
    ("bridge_beam_lrb", "run", "The bridge beam on lead-rubber bearings: a 0.25 g record and the EN 1998-1 design "
     "spectrum (seismic isolation)."),
    ("engine_inclined_mounts", "design", "A powertrain's V mounts optimized for its frequency, decoupling and "
     "deflection targets (isolation design)."),
    ("machine_tap_test", "correlate", "A compressor skid's model against its tap test, then updated to it (test "
     "correlation and updating)."),
)

#: One sentence per figure, for the gallery page (a figure without one is shown under its file name).
WORDS = {
    "mode_shapes.png": "the body on its mounts at rest and deformed, one panel per mode",
    "ke_distribution.png": "each mode's kinetic energy per DOF",
    "time_dofs.png": "the six DOFs over the run, with a zoom on the shock or the switch-on",
    "time_points.png": "the named body points' accelerations over the run",
    "mount_forces.png": "each mount's total normal force, static preload included",
    "mount_shear.png": "each mount's shear load",
    "superposition.png": "the direct solve and the modal superposition overlaid, and their difference per DOF",
    "bode.png": "receptances with the natural and operating frequencies marked",
    "transmissibility.png": "force on the foundation over the applied force, with the isolation efficiency",
    "point_frfs.png": "the `[frf]` point FRFs",
    "dynamic_stiffness.png": "measured dynamic stiffness (markers) and the Maxwell fits (lines)",
    "random.png": "input and response PSDs with their RMS values",
    "random_check.png": "the random response's time check: Welch PSDs against the FRFs'",
    "srs.png": "shock response spectra of the base and the body points",
    "hysteresis.png": "each hysteretic bearing's loop, force against deflection",
    "spectrum.png": "the design spectrum and the modes' periods",
    "records.png": "spectrum-compatible records and their spectra",
    "frequencies.png": "the natural frequency of the mode each DOF dominates, given and optimized, against the "
                       "target windows",
    "decoupling.png": "decoupling of the given and optimized designs against the targets",
    "stability.png": "the stability diagram of the test's identification",
    "mac.png": "MAC of the test modes against the model's",
    "frf_overlay.png": "every measured FRF against the model and the updated model",
    "update_history.png": "the update's objective and variables over its iterations",
}


def _key() -> str:
    """A hash of everything the figures depend on: the package's source, the bundled scenarios and this hook."""
    digest = hashlib.sha256(Path(__file__).read_bytes())
    for path in sorted([*(ROOT / "src" / "sixdof").rglob("*.py"), *(ROOT / "scenarios").rglob("*")]):
        if path.is_file():
            digest.update(str(path.relative_to(ROOT)).encode() + b"\0" + path.read_bytes())
    return digest.hexdigest()[:16]


def _draw(name: str, kind: str, folder: Path) -> None:
    """Draw one entry's figures into ``folder`` as the library draws them."""
    scenario = ROOT / "scenarios" / f"{name}.toml"
    if kind == "run":
        save_all(sixdof.run(scenario), folder)
        return
    with tempfile.TemporaryDirectory() as out:   # the command's folder; its figures are kept
        if kind == "design":
            written = save_design(design_run(scenario), out)
        else:
            written = save_correlation(correlation_run(scenario, ROOT / "scenarios" / f"{name}.uff", update=True),
                                       out)
        folder.mkdir(parents=True)
        for png in Path(written).glob("*.png"):
            shutil.copy2(png, folder / png.name)


def _figures(cache: Path) -> None:
    """Every entry's figures in ``cache``, drawn when missing; the library's warnings logged, not raised."""
    cache.mkdir(parents=True, exist_ok=True)
    for name, kind, _ in ENTRIES:
        folder = cache / name
        if folder.is_dir():
            continue
        start = time.perf_counter()
        stage = cache / f".{name}.partial"
        shutil.rmtree(stage, ignore_errors=True)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            _draw(name, kind, stage)
        for w in caught:   # a scenario's own range warnings (the elastomer's causal fit): part of the example
            log.info("%s: %s", name, w.message)
        stage.rename(folder)
        log.info("gallery: %s (%s) drawn in %.1f s", name, kind, time.perf_counter() - start)


def _page(cache: Path) -> str:
    """The gallery page: each entry's command, what it shows and its figures."""
    text = ["# Gallery", "",
            "Figures of the bundled scenarios, drawn by the documentation build itself from today's code "
            "(`scripts/docs_gallery.py`). The commands beside each draw the same into `outputs/`.", ""]
    for name, kind, words in ENTRIES:
        command = {"run": f"sixdof run scenarios/{name}.toml",
                   "design": f"sixdof optimize scenarios/{name}.toml",
                   "correlate": f"sixdof correlate scenarios/{name}.toml --test scenarios/{name}.uff --update"}[kind]
        text += [f"## {sixdof.load_scenario(ROOT / 'scenarios' / f'{name}.toml').description}", "", words, "",
                 f"    {command}", ""]
        order = list(WORDS)
        for png in sorted((cache / name).glob("*.png"), key=lambda p: (order.index(p.name) if p.name in order
                                                                       else len(order), p.name)):
            sentence = WORDS.get(png.name, png.stem.replace("_", " "))
            text += [f"`{png.name}`: {sentence}.", "", f"![{sentence}](gallery/{name}/{png.name})", ""]
    return "\n".join(text)


def on_files(files, config):
    """mkdocs' files event: draw the figures (or take them from the cache), add them and the gallery page."""
    caches = ROOT / "build" / "docs-gallery"
    cache = caches / _key()
    for old in caches.glob("*"):   # figures of other sources: never shown again
        if old != cache:
            shutil.rmtree(old, ignore_errors=True)
    start = time.perf_counter()
    _figures(cache)
    for name, _, _ in ENTRIES:
        for png in sorted((cache / name).glob("*.png")):
            files.append(File.generated(config, f"gallery/{name}/{png.name}", abs_src_path=str(png)))
    files.append(File.generated(config, "gallery.md", content=_page(cache)))
    log.info("gallery: %d entries in %.1f s", len(ENTRIES), time.perf_counter() - start)
    return files
