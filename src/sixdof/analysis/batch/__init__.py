"""Many design variants in one vectorized computation, and the ``sixdof sweep`` command.

A batch varies the mounts of one system: stiffness factors, damping factors and position offsets,
per variant, per mount and per mount axis (:class:`Variants`). :func:`run_batch` assembles every
variant's M, K, C, natural frequencies and mode shapes in one ``jax.vmap`` of the pure assembly
functions of :mod:`sixdof.model.system` (``jnp.linalg.eigh`` of the mass-scaled stiffness), follows each
nominal mode into every variant by its shape (:func:`track_modes`: ascending order mixes modes whose
frequencies cross), then computes every variant's response, keeping only what is asked for: the peak of
``|q|`` and ``|q''|`` per DOF at the output samples, and the full :class:`~sixdof.results.TimeHistory` of a
few chosen variants.

Two engines compute the responses:

- ``"exact"`` (default): the exact linear engine of :mod:`sixdof.analysis.superposition`. The excitation
  is evaluated once on the quadrature nodes (a :class:`~sixdof.analysis.superposition.Drive` per
  window of output steps, shared by every variant); each variant contributes only its modal coordinates
  (method chosen per variant as in :func:`~sixdof.analysis.superposition.superpose`). The coordinates of
  a chunk of variants advance side by side, window by window, and only the peaks are kept. Loads,
  initial states and ground motion. With Maxwell branches each variant's coordinates are the complex modes
  of its augmented first-order system ``[eta, eta', f]``, as :func:`~sixdof.analysis.superposition.superpose`'s.
- ``"diffrax"``: ``jax.vmap`` of one diffrax solve (:func:`sixdof.analysis.direct.solve_ode` with the
  settings of :func:`~sixdof.analysis.direct.simulate`, tolerances on the state scaled by the *nominal*
  system's :func:`~sixdof.analysis.direct.state_scale`), each variant's first-order matrix ``A``
  (``12 + nb`` square with ``nb`` Maxwell branch states, :func:`~sixdof.analysis.direct.mechanical_form`)
  built once, in chunks of equal size. Loads and initial states; what nonlinear mounts will need.

Maxwell branches (measured ``dynamic_stiffness`` tables, ``loss_factor_model = "maxwell"``, and the causal
models of the loss factors that a scenario's ``time_system`` carries) follow each variant's mounts
(:func:`variant_system`): a branch scales with its mount axis's stiffness factor (a fit to that axis's loss
factor or table is linear in its stiffness; relaxation times unchanged) and moves with its mount's position
offset. :func:`run_batch` takes the frequency model (``system``: natural frequencies, tracked modes) and the time
model (``time_system``: the responses and the cross-check) apart, as ``sixdof run`` does.

A sample of the variants (``cross_check``, drawn with a seed) is also solved by
:func:`sixdof.analysis.direct.simulate` (diffrax); the worst agreement of its peaks with the engine's,
DOF by DOF, is kept in :attr:`BatchResult.cross_check`. Mode-release initial states (which depend on
each variant's modes) are not batched: they raise :class:`~sixdof.errors.InputError`.

The package's modules: :mod:`~sixdof.analysis.batch.variants` (the variants and their assembly),
:mod:`~sixdof.analysis.batch.engines` (the two engines) and :mod:`~sixdof.analysis.batch.solve`
(:func:`run_batch`, its result and the cross-check).
"""

from sixdof.analysis.batch.engines import CHUNK_BYTES, EXACT_CHUNK, MAX_CHUNK, WINDOW, default_chunk_size
from sixdof.analysis.batch.solve import (
    CROSS_CHECK,
    ENGINES,
    BatchResult,
    cross_check_fields,
    cross_check_sample,
    direct_peaks,
    run_batch,
)
from sixdof.analysis.batch.variants import (
    Variants,
    batch_frequencies,
    check_batchable,
    make_variants,
    track_modes,
    variant_branches,
    variant_matrices,
    variant_system,
)

__all__ = ["BatchResult", "CHUNK_BYTES", "CROSS_CHECK", "ENGINES", "EXACT_CHUNK", "MAX_CHUNK", "Variants", "WINDOW",
           "batch_frequencies", "check_batchable", "cross_check_fields", "cross_check_sample", "default_chunk_size",
           "direct_peaks", "make_variants", "run_batch", "track_modes", "variant_branches", "variant_matrices",
           "variant_system"]
