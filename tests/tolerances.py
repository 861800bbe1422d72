"""Tolerances used by the tests, named once. Each says what it bounds and why it is that size."""

# Linear algebra on 6x6 float64 matrices whose entries span ~12 decades (N/m vs N m/rad):
# results are compared relative to each quantity's own scale.
RTOL_LINALG = 1e-10
# Closed-form natural frequencies against the eigen-solver.
RTOL_FREQUENCY = 1e-10
# Round-off floor of an assembled matrix entry that must be zero, relative to the matrix scale.
RTOL_ZERO_ENTRY = 1e-14
# A printed value of the seed paper agrees with ours when it equals ours rounded or truncated to the
# digits printed (the paper does both: f1 = 0.6255 Hz is printed 0.62): within one unit of its last
# printed digit (see tests/test_seed_case_study.py).
def printed_ulp(printed: str) -> float:
    """One unit in the last digit of a number as printed (``"-19.140"`` -> 0.001)."""
    mantissa = printed.lower().split("e")[0]
    decimals = len(mantissa.split(".")[1]) if "." in mantissa else 0
    exponent = int(printed.lower().split("e")[1]) if "e" in printed.lower() else 0
    return 10.0 ** (exponent - decimals)
