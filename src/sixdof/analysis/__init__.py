"""Numerics: pure functions of the model and excitation returning immutable results (modes, statics,
frequency responses, the direct and the modal-superposition time responses, batches of variants)."""
