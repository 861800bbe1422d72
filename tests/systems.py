"""The test systems shared by several test modules, each built in one place.

- :func:`bridge`: the seed paper's 83 t bridge beam on four elastomeric bearings (section 5), with the
  damping models the tests need as parameters.
- :func:`four_mount`: a body on four identical mounts at the corners of a rectangle (doubly symmetric).
- :func:`small_box`, :func:`skewed_box`: small bodies on three unequal mounts, every DOF coupled;
  :func:`heavily_damped_box`: the same mounts with dashpots that leave two modes overdamped.
- :func:`skewed_machine`: a full inertia tensor on four inclined, differently damped mounts.
- :func:`sdof`: one vertical spring at the CG, a single-DOF oscillator in z.

The seed paper's values are kept exactly as printed in its Tables 1-2 (tests/test_seed_case_study.py
compares against the paper's tables).
"""

from __future__ import annotations

import numpy as np

from sixdof import Mount, Rayleigh, RigidBody, System

BRIDGE_MASS = 83e3  # kg
BRIDGE_INERTIA = [11.105e6, 0.0491e6, 11.064e6]  # kg m^2, principal (Jxx, Jyy, Jzz)
BRIDGE_DIMENSIONS = (1.2, 40.0, 2.0)  # m, the beam's box
# Bearings 1, 2 at one end, 3, 4 at the other: the two ends differ, so every mode couples several DOFs.
BRIDGE_POSITIONS = [(-0.195, -19.55, -1.031), (0.195, -19.55, -1.031), (0.195, 19.55, -1.031),
                    (-0.195, 19.55, -1.031)]
BRIDGE_STIFFNESS = [[0.26e6, 0.26e6, 312e6]] * 2 + [[0.51e6, 0.51e6, 496e6]] * 2  # N/m per bearing
# Mount dashpots [N s/m] per bearing and axis, by name (none of them is proportional damping):
BRIDGE_DASHPOTS = {
    # The same dashpot on every bearing.
    "equal": [[520.0, 520.0, 0.62e6]] * 4,
    # One dashpot per pair of bearings.
    "two_pairs": [[520.0, 520.0, 0.62e6]] * 2 + [[1040.0, 1040.0, 0.4e6]] * 2,
    # Elastomer dashpots with a different ratio per mount pair and per axis: modal ratios from 1.4 %
    # to 6.3 %, and coupled modes.
    "elastomer": [[3800.0, 3800.0, 1.4e5]] * 2 + [[9000.0, 9000.0, 1.2e5]] * 2,
}


def bridge_body(dimensions=BRIDGE_DIMENSIONS) -> RigidBody:
    """The bridge beam as a rigid body: 83 t, principal inertias, its box (None: without one)."""
    return RigidBody(BRIDGE_MASS, BRIDGE_INERTIA, dimensions)


def bridge(dashpots=((0.0, 0.0, 0.0),) * 4, *, rayleigh=None, modal_damping=None, loss_factor=(0.0, 0.0, 0.0),
           stiffness_factor=1.0, dimensions=BRIDGE_DIMENSIONS) -> System:
    """The seed paper's bridge beam: 83 t on four bearings, natural frequencies 0.63 to 38 Hz.

    ``dashpots``: a name in :data:`BRIDGE_DASHPOTS` or values per bearing and axis [N s/m] (default
    none); ``loss_factor``: the same per axis on every bearing; ``stiffness_factor`` scales every
    bearing's stiffness, and its dashpots by its square root (the damping ratios stay the same);
    ``dimensions``: the body's box [m], None for none; ``rayleigh`` and ``modal_damping`` go to the System.
    """
    damping = np.asarray(BRIDGE_DASHPOTS[dashpots] if isinstance(dashpots, str) else dashpots, float)
    mounts = [Mount(str(i + 1), p, np.asarray(k) * stiffness_factor, d * np.sqrt(stiffness_factor),
                    loss_factor=loss_factor)
              for i, (p, k, d) in enumerate(zip(BRIDGE_POSITIONS, BRIDGE_STIFFNESS, damping))]
    return System(bridge_body(dimensions), mounts, rayleigh=rayleigh, modal_damping=modal_damping)


def bridge_toml(dashpots="elastomer") -> str:
    """The ``[body]`` and ``[[mounts]]`` tables of a scenario file for :func:`bridge` (without a box)."""
    lines = ["[body]", f"mass = {BRIDGE_MASS!r}", f"inertia = {list(BRIDGE_INERTIA)!r}"]
    for i, (p, k, d) in enumerate(zip(BRIDGE_POSITIONS, BRIDGE_STIFFNESS, BRIDGE_DASHPOTS[dashpots])):
        lines += ["[[mounts]]", f'name = "{i + 1}"', f"position = {list(p)!r}", f"stiffness = {list(k)!r}",
                  f"damping = {list(d)!r}"]
    return "\n".join(lines) + "\n"


#: ``[[loads]]`` of a bridge scenario file that move all six DOFs: an off-centre harmonic force and a pulse near
#: one end.
BRIDGE_LOADS_TOML = """[[loads]]
name = "traffic"
point = [0.3, 10.0, 1.0]
force = [5e3, 2e4, -1e5]
signal = { kind = "harmonic", f_hz = 5.0 }
[[loads]]
name = "impact"
point = [0.4, 19.55, 0.5]
force = [2e4, -5e4, 3e4]
signal = { kind = "half_sine", start = 0.5, duration = 0.05 }
"""


FOUR_MOUNT_CORNERS = [(-1, -1), (1, -1), (1, 1), (-1, 1)]


def four_mount(m=500.0, J=(40.0, 60.0, 80.0), a=0.4, b=0.6, h=0.3, k=(2e5, 3e5, 8e5), *,
               damping=(0.0, 0.0, 0.0), dimensions=None) -> System:
    """A body (mass ``m`` [kg], principal inertias ``J`` [kg m^2], box ``dimensions`` [m]) on four
    identical mounts at ``(+-a, +-b, -h)`` [m] (stiffness ``k`` [N/m] and dashpots ``damping`` [N s/m]
    along x, y, z): doubly symmetric."""
    mounts = [Mount(f"m{i}", [sx * a, sy * b, -h], k, damping) for i, (sx, sy) in enumerate(FOUR_MOUNT_CORNERS)]
    return System(RigidBody(m, J, dimensions), mounts)


# Three unequal mounts around the CG of a small box (name, position [m], stiffness [N/m]).
THREE_MOUNTS = [
    ("a", [0.4, 0.3, -0.2], [2e5, 3e5, 8e5]),
    ("b", [-0.5, 0.35, -0.25], [1e5, 1e5, 6e5]),
    ("c", [0.1, -0.45, -0.3], [3e5, 2e5, 9e5]),
]


def small_box(zeta=0.04) -> System:
    """A 120 kg box on the three mounts of :data:`THREE_MOUNTS`, all six DOFs coupled, modes 10-49 Hz,
    Rayleigh damping of ratio ``zeta`` at 5 and 20 Hz."""
    mounts = [Mount(name, p, k) for name, p, k in THREE_MOUNTS]
    return System(RigidBody(120.0, [4.0, 5.0, 6.0]), mounts, rayleigh=Rayleigh.from_ratio(zeta, (5.0, 20.0)))


#: Dashpots [N s/m] on the mounts of :data:`THREE_MOUNTS` that leave two of the six modes of :func:`small_box`'s body
#: without an oscillating pole (four complex pairs, four real eigenvalues), although the diagonal approximation
#: phi' C phi / (2 omega) gives them 83 % and 90 %.
HEAVY_DASHPOTS = [[12700.0, 630.0, 6200.0], [720.0, 27.0, 13.0], [210.0, 15100.0, 610.0]]


def heavily_damped_box() -> System:
    """:func:`small_box`'s body on :data:`THREE_MOUNTS` with :data:`HEAVY_DASHPOTS`: two modes overdamped by
    non-proportional damping."""
    mounts = [Mount(name, p, k, d) for (name, p, k), d in zip(THREE_MOUNTS, HEAVY_DASHPOTS)]
    return System(RigidBody(120.0, [4.0, 5.0, 6.0]), mounts)


def heavily_damped_box_toml() -> str:
    """The ``[body]`` and ``[[mounts]]`` tables of a scenario file for :func:`heavily_damped_box`."""
    lines = ["[body]", "mass = 120.0", "inertia = [4.0, 5.0, 6.0]"]
    for (name, p, k), d in zip(THREE_MOUNTS, HEAVY_DASHPOTS):
        lines += ["[[mounts]]", f'name = "{name}"', f"position = {p!r}", f"stiffness = {k!r}", f"damping = {d!r}"]
    return "\n".join(lines) + "\n"


def skewed_box() -> System:
    """A 250 kg body with a full inertia tensor on the three mounts of :data:`THREE_MOUNTS`, with mount
    axes rotated 0.3 rad about z (a, c), dashpots (a, b) and loss factors (a, c): everything coupled,
    the damping non-proportional."""
    rot = np.array([[np.cos(0.3), np.sin(0.3), 0.0], [-np.sin(0.3), np.cos(0.3), 0.0], [0, 0, 1.0]])
    body = RigidBody(250.0, [[12.0, 1.5, -0.7], [1.5, 9.0, 0.4], [-0.7, 0.4, 15.0]])
    extra = [
        dict(damping=[40.0, 60.0, 300.0], axes=rot, loss_factor=[0.02, 0.0, 0.08]),
        dict(damping=[10.0, 90.0, 150.0]),
        dict(axes=rot.T, loss_factor=[0.05, 0.05, 0.0]),
    ]
    return System(body, [Mount(name, p, k, **kw) for (name, p, k), kw in zip(THREE_MOUNTS, extra)])


def skewed_machine() -> System:
    """A 500 kg body with a full inertia tensor on four inclined mounts, each damped differently."""
    body = RigidBody(500.0, [[60.0, 4.0, -3.0], [4.0, 45.0, 2.0], [-3.0, 2.0, 70.0]])
    mounts = []
    for i, (x, y) in enumerate([(-0.4, -0.3), (0.4, -0.3), (0.4, 0.3), (-0.4, 0.3)]):
        angle = np.deg2rad(20.0 + 10.0 * i)  # inclined about the body's y axis, all different
        c, s = np.cos(angle), np.sin(angle)
        axes = [[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]]
        k = np.array([3e5, 2.5e5, 8e5]) * (1.0 + 0.1 * i)
        d = np.array([300.0, 500.0, 900.0]) * (1.0 + 0.5 * i)
        mounts.append(Mount(f"m{i + 1}", [x, y, -0.25], k, d, axes))
    return System(body, mounts)


def sdof(mass=120.0, k=4.0e5, c=0.0, eta=0.0) -> System:
    """One mount at the CG, stiff only along z: z decouples as m z'' + c z' + k (1 + i eta) z = F;
    the five other DOFs are unrestrained (zero-frequency modes). Inertias (3, 4, 5) kg m^2."""
    mount = Mount("m", [0.0, 0.0, 0.0], [0.0, 0.0, k], damping=[0.0, 0.0, c], loss_factor=[0.0, 0.0, eta])
    return System(RigidBody(mass, [3.0, 4.0, 5.0]), [mount])
