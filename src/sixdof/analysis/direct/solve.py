"""The traced solve of one window: the one diffrax call, linear and with nonlinear mounts (region by region)."""

from __future__ import annotations

import numpy as np

from sixdof._jax import jax, jnp


def _ground_kinematics(code: int, p, t, g):
    """Ground displacement, velocity and acceleration along its direction at ``t`` (``g``: the state's ``u_g, v_g``)."""
    signal, scale = p["ground_signal"], p["ground_scale"]
    if code == 0:
        zero = jnp.zeros_like(t)
        return zero, zero, zero
    if code == 1:
        return scale * signal(t), scale * signal.derivative(t), scale * signal.derivative(t, 2)
    if code == 2:
        return g[0], scale * signal(t), scale * signal.derivative(t)
    return g[0], g[1], scale * signal(t)


def _input(t, g, p, code: int):
    """The input ``u(t)`` of :func:`first_order_form` (``g``: the state's ``u_g, v_g``)."""
    _, v_g, a_g = _ground_kinematics(code, p, t, g)
    return jnp.stack([*(signal(t) for signal in p["signals"]), a_g if code == 3 else v_g])


def solve_ode(field, x0, t0, t1, saveat, jump_ts, rtol, atol, *, solver: str, max_steps: int, args=None, event=None,
              dtmax=None):
    """The one diffrax call of sixdof, shared by :func:`simulate_windows` and the batch engine (traceable).

    ``solver`` (a key of :data:`SOLVERS`; explicit methods with unrolled stages,
    :mod:`sixdof.analysis.unrolled`) with PID step control at ``rtol`` and ``atol`` on the (scaled)
    state, stepping onto every time of ``jump_ts`` (:func:`jump_times`), ``max_steps`` at most; with
    ``throw=False``, the caller turns a failed result code into a :class:`~sixdof.errors.SolverError`.
    """
    import diffrax  # noqa: PLC0415 (diffrax, which a cached solve never loads)

    # Not at the top: it imports diffrax (~0.65 s), which a solve loaded from the export cache never needs.
    from sixdof.analysis import unrolled  # noqa: PLC0415 (diffrax, which a cached solve never loads)

    controller = diffrax.PIDController(rtol=rtol, atol=atol, dtmax=dtmax)
    # No breakpoints (``jump_ts`` of length 0, a static shape): no clipping traced. Clipping makes every step
    # check the jumps and redo its first stage after one; without it the bridge traffic solve (no breakpoints)
    # traces, lowers and compiles in 0.65 instead of 0.85 s, for the same steps and values.
    if jump_ts.shape[0]:
        controller = diffrax.ClipStepSizeController(controller, jump_ts=jump_ts)
    return diffrax.diffeqsolve(
        diffrax.ODETerm(field), unrolled.solver(solver), t0, t1, None, x0, args=args, saveat=saveat,
        stepsize_controller=controller, max_steps=max_steps, throw=False, event=event,
        # Never differentiated in reverse mode: diffrax's default adjoint traces a checkpointed loop for it, which
        # made the first (cold) solve 0.25-0.3 s longer to trace and compile, for the same steps and results.
        adjoint=diffrax.ForwardMode(),
    )


def _solve_window(p, xs0, ts, t0, t1, jump_ts, rtol, atol, *, solver: str, code: int, max_steps: int):
    """One window from ``t0`` to ``t1``, saved at ``ts`` (traced): scaled end state, states and outputs at ``ts``."""
    import diffrax  # noqa: PLC0415 (diffrax, which a cached solve never loads)

    A, B, sigma = p["A"], p["B"], p["sigma"]
    # On the scaled state xs = x / sigma the field is one product [A_s | B_s] [xs; u(t)] (A and B scaled
    # once): a single dot per stage, which XLA runs fastest on the CPU (measured against A_s xs + B_s u).
    AB = jnp.concatenate([A * sigma[None, :], B], axis=1) / sigma[:, None]

    def field(t, xs, AB):
        return AB @ jnp.concatenate([xs, _input(t, xs[12:14] * sigma[12:14], p, code)])

    sol = solve_ode(field, xs0, t0, t1, diffrax.SaveAt(ts=ts), jump_ts, rtol, atol, args=AB,
                    solver=solver, max_steps=max_steps)
    xs = sol.ys * sigma

    def outputs(t, x):
        u = _input(t, x[12:14], p, code)
        return (A @ x + B @ u)[6:12], p["vectors"].T @ u[:-1], jnp.stack(_ground_kinematics(code, p, t, x[12:14]))

    qdd, Q, ground = jax.vmap(outputs)(ts, xs)
    stats = jnp.stack([sol.stats["num_steps"], sol.stats["num_accepted_steps"], sol.stats["num_rejected_steps"]])
    # The result as its integer code (a pytree leaf), so that the compiled solve returns plain arrays.
    result = jax.tree.leaves(sol.result)[0]
    return sol.ys[-1], xs, qdd, Q, ground, sol.result == diffrax.RESULTS.successful, result, stats


def _solve_segment(p, xs0, ts, t0, t1, jump_ts, rtol, atol, region, *, solver: str, code: int, max_steps: int):
    """A window's solve with nonlinear mounts, from ``t0`` until ``t1`` or the first change of region (traced).

    Inside the regions ``region`` (ne,) of the force laws the motion is linear: the field is ``A x + B u`` with
    each law's slope and intercept there in place of its tangent at rest. Leaving a region is an event,
    root-found on the step's dense output; the caller restarts from it in the next region. Two more states
    integrate the work done on the body and the energy dissipated (:func:`sixdof.analysis.contact.energy_balance`).
    Returns what :func:`_solve_window` does, with the work and dissipation at ``ts``, the time the segment
    ended, whether an event ended it and which boundary (ne, 2: below, above).
    """
    import diffrax  # noqa: PLC0415 (diffrax, which a cached solve never loads)

    A, B, sigma = p["A"], p["B"], p["sigma"]
    laws = p["laws"]
    rows, knots = laws["rows"], laws["knots"]
    size = A.shape[0]
    pick = jax.vmap(lambda table, i: table[i])
    slope, intercept = pick(laws["slope"], region), pick(laws["intercept"], region)
    # In the region: r = a + s (d_s + L z), written as its tangent at rest (already in K) plus a correction.
    dK = rows.T @ ((slope - laws["tangent"])[:, None] * rows)
    f0 = rows.T @ (intercept + slope * laws["static"] - laws["force"])
    Minv = p["Minv"]
    A = A.at[6:12, :6].add(-Minv @ dK)
    c = jnp.zeros(size).at[6:12].set(-Minv @ f0)
    # The dashpots of mounts lifted off are off: C_off z', z' = w - r v_g, no longer resists the motion.
    C_off = rows.T @ (((1.0 - pick(laws["contact"], region)) * laws["damping"])[:, None] * rows)
    # So are the Maxwell branches of a lifted mount: they carry nothing and relax, f' = -f / tau.
    lifts = laws["lifts"]
    lifted = lifts & (region == laws["lifted_region"])
    off = laws["branches"].T @ lifted.astype(A.dtype)
    big = 1e30
    padded = jnp.concatenate([jnp.full((knots.shape[0], 1), -jnp.inf), knots, jnp.full((knots.shape[0], 1), jnp.inf)],
                             axis=1)
    low, high = (jnp.clip(pick(padded, region + shift), -big, big) for shift in (0, 1))
    scale = jnp.concatenate([sigma, p["energy_scale"]])
    C, K, R, k_b, tau = p["C"], p["K"], p["R"], p["k_b"], p["tau"]
    r = p["r"]
    nb = k_b.size
    branch = slice(14, 14 + nb)

    def motion(t, x):
        """``x'`` in the region, the input ``u`` and the hysteretic axes' :func:`_hysteresis`."""
        u = _input(t, x[12:14], p, code)
        dx = A @ x + B @ u + c
        zd, f = dx[:6], x[branch]
        dx = dx.at[6:12].add(Minv @ (C_off @ zd + R.T @ (off * f)))
        dx = dx.at[branch].add(-off * k_b * (R @ zd))
        hyst = _hysteresis(p["hysteresis"], x[:6], zd, x[14 + nb:])
        dx = dx.at[6:12].add(-Minv @ (p["hysteresis"]["rows"].T @ hyst["force"]))
        return dx.at[14 + nb:].set(hyst["rate"]), u, hyst

    def field(t, ys, args):
        x = ys[:size] * sigma
        dx, u, hyst = motion(t, x)
        z, w, f = x[:6], x[6:12], x[branch]
        zd = dx[:6]
        _, v_g, a_g = _ground_kinematics(code, p, t, x[12:14])
        # The generalized force of the mounts on the foundation.
        mounts = (K @ z + dK @ z + f0 + (C - C_off) @ zd + R.T @ ((1.0 - off) * f)
                  + p["hysteresis"]["rows"].T @ hyst["force"])
        power = p["vectors"].T @ u[:-1] @ w - v_g * (r @ mounts)  # the ground moves against the mounts' force
        loss = (zd @ (C - C_off) @ zd + jnp.sum(f * f / (k_b * tau))
                + _hysteretic_loss(p["hysteresis"], hyst, dx[6:12] - r * a_g))
        return jnp.concatenate([dx, jnp.stack([power, loss])]) / scale

    # Distances to the region's knots, below and above (ne, 2), over each axis's deflection scale: the event is the
    # nearest reaching zero (one continuous function, which bisection brackets on the step's dense output). A mount
    # that lifts off leaves contact where its whole load F = r(d) + c d' + f_b would pull (F / k_max, a deflection,
    # reaching zero), and touches again where d < 0 and F < 0 both hold.
    delta, length = laws["hysteresis"], laws["hysteresis"] / REGION_HYSTERESIS

    def distances(t, y):
        x = y[:size] * sigma
        d = laws["static"] + rows @ x[:6]
        rate = rows @ (x[6:12] - r * _ground_kinematics(code, p, t, x[12:14])[1])
        at = jnp.sum(knots < d[:, None], axis=1)  # the region of d alone, lifted or not
        load = pick(laws["intercept"], at) + pick(laws["slope"], at) * d + laws["damping"] * rate
        e = (load + laws["branches"] @ x[branch]) / laws["stiffness_scale"]
        below = jnp.where(lifted, jnp.maximum(d - low, e), d - low)
        above = jnp.where(lifts & ~lifted, jnp.minimum(high - d, -e), high - d)
        return jnp.stack([below + delta, above + delta], axis=1) / length[:, None]

    # Hysteretic laws alone have no region to leave: no event.
    event = None if not knots.shape[0] else diffrax.Event(lambda t, y, args, **kw: jnp.min(distances(t, y)),
                                                          direction=False, root_finder=_event_bisection())
    # An event is a sign change between steps: capped steps see every excursion past a knot that lasts two steps.
    sol = solve_ode(field, xs0, t0, t1, diffrax.SaveAt(ts=ts, t1=True), jump_ts, rtol, atol, args=None,
                    solver=solver, max_steps=max_steps, event=event, dtmax=p["dtmax"])
    # The state where the segment ended is saved after the samples before it (those after it are inf).
    last = jnp.sum(jnp.isfinite(sol.ts)) - 1
    ys = jnp.where(jnp.arange(ts.size)[:, None] < last, sol.ys[:-1], sol.ys[last])
    xs = ys[:, :size] * sigma

    def outputs(t, x):
        dx, u, _ = motion(t, x)
        return dx[6:12], p["vectors"].T @ u[:-1], jnp.stack(_ground_kinematics(code, p, t, x[12:14]))

    qdd, Q, ground = jax.vmap(outputs)(ts, xs)
    energy = ys[:, size:] * p["energy_scale"]
    stats = jnp.stack([sol.stats["num_steps"], sol.stats["num_accepted_steps"], sol.stats["num_rejected_steps"]])
    at_end = distances(sol.ts[last], sol.ys[last]) if knots.shape[0] else jnp.zeros((0, 2))
    crossed = (sol.result == diffrax.RESULTS.event_occurred) & (at_end == jnp.min(at_end, initial=jnp.inf))
    ok = (sol.result == diffrax.RESULTS.successful) | (sol.result == diffrax.RESULTS.event_occurred)
    result = jax.tree.leaves(sol.result)[0]
    return sol.ys[last], xs, qdd, Q, ground, ok, result, stats, energy, sol.ts[last], crossed


def _hysteresis(h, z, zd, state):
    """The hysteretic axes (:class:`~sixdof.model.hysteresis.HystereticAxes`, as the arrays ``h``) at the body's
    motion ``z``, ``z'`` relative to the ground and their variables ``state`` (traced): each axis's force
    ``p d + q z`` [N], the rate of its variable (Wen's law, biaxial where ``coupled``), and what the energy
    balance needs (:func:`_hysteretic_loss`)."""
    d, rate = h["rows"] @ z, h["rows"] @ zd
    pendulum = h["pendulum"]
    # A pendulum's compressive load along w, zero once lifted off; its sliding speed in the dish's plane.
    load_rate = h["load_row"] @ zd
    load = jnp.maximum(h["static_load"] - h["load_stiffness"] * (h["load_row"] @ z)
                       - h["load_damping"] * load_rate, 0.0)
    speed = jnp.sqrt(h["coupled"] @ (rate * rate))
    slowing = jnp.exp(-h["rate"] * speed)
    mu = h["mu_fast"] - (h["mu_fast"] - h["strength"]) * slowing
    p = jnp.where(pendulum > 0, load * h["stiffness"], h["stiffness"])
    q = jnp.where(pendulum > 0, load * mu, h["strength"])
    # d_y z' = d' - |z|^(n - 2) (beta sgn(z . d') + gamma) (z . d') z, with |z|^(n - 2) z (z . d') -> 0 as z -> 0.
    along = h["coupled"] @ (state * rate)
    norm2 = h["coupled"] @ (state * state)
    power = jnp.where(norm2 > 0, jnp.maximum(norm2, 1e-300) ** (0.5 * h["exponent"] - 1.0), 0.0)
    state_rate = (rate - power * (h["beta"] * jnp.sign(along) + h["gamma"]) * along * state) / h["yield_displacement"]
    return {"force": p * d + q * state, "rate": state_rate, "d": d, "d_rate": rate, "state": state, "p": p, "q": q,
            "mu": mu, "load": load, "load_rate": load_rate, "speed": speed, "slowing": slowing}


def _hysteretic_loss(h, hyst, zdd):
    """The energy the hysteretic axes dissipate per unit time [W] at the body's acceleration ``zdd`` relative to the
    ground (traced): their force's power less the rate of ``p d^2 / 2 + q d_y z^2 / 2``
    (:meth:`~sixdof.model.hysteresis.HystereticAxes.stored`), whose ``p`` and ``q`` change with a pendulum's load and
    speed."""
    d, rate, state, q = hyst["d"], hyst["d_rate"], hyst["state"], hyst["q"]
    d_y = h["yield_displacement"]
    pendulum = h["pendulum"] > 0
    acc = h["rows"] @ zdd
    load_dot = jnp.where(hyst["load"] > 0, -h["load_stiffness"] * hyst["load_rate"]
                         - h["load_damping"] * (h["load_row"] @ zdd), 0.0)
    speed_dot = jnp.where(hyst["speed"] > 0, (h["coupled"] @ (rate * acc)) / jnp.maximum(hyst["speed"], 1e-300), 0.0)
    mu_dot = (h["mu_fast"] - h["strength"]) * h["rate"] * hyst["slowing"] * speed_dot
    p_dot = jnp.where(pendulum, load_dot * h["stiffness"], 0.0)
    q_dot = jnp.where(pendulum, load_dot * hyst["mu"] + hyst["load"] * mu_dot, 0.0)
    loss = q * (state * rate - d_y * state * hyst["rate"]) - 0.5 * p_dot * d * d - 0.5 * q_dot * d_y * state * state
    return jnp.sum(loss)


def _event_bisection():
    """The root finder of the events: bisection that stops once the time is bracketed to its tolerance.

    The distances of :func:`_solve_segment` fall through zero at every event (``flip=True``), so it needs no check
    that they change sign within the step, nor that they are near zero where it stops: a ground velocity that jumps
    at a breakpoint (a kinked displacement, a table) makes a lift-off mount's dashpot load jump between one step's
    end (just before the breakpoint) and the next one's start (just after). That next step is then past the event
    at both ends, its value there is not small, and the root is its start.
    """
    import optimistix as optx  # noqa: PLC0415 (diffrax, which a cached solve never loads)

    class EventBisection(optx.Bisection):
        def terminate(self, fn, y, args, options, state, tags):
            return jnp.abs(state.lower - state.upper) < self.atol + self.rtol * jnp.abs(y), optx.RESULTS.successful

    return EventBisection(rtol=1e-12, atol=1e-12, flip=True)


def _failure(result) -> str:
    """diffrax's message for a result code returned by :func:`_solve_window`."""
    import diffrax  # noqa: PLC0415 (diffrax, which a cached solve never loads)

    item = jax.tree.unflatten(jax.tree.structure(diffrax.RESULTS.successful), [np.asarray(result)])
    return diffrax.RESULTS[item]


#: Hysteresis of a change of region, relative to the deflection scale of the axis: after an event the solver
#: restarts exactly on the knot, and must not see that knot again before it has moved away from it.
REGION_HYSTERESIS = 1e-10


def _window_args(params, xs0, ts, t0, t1, jumps, settings, region=None) -> tuple:
    """The arguments of :func:`_solve_window` (with ``region``: of :func:`_solve_segment`), as float64 arrays."""
    scalars = (np.float64(t0), np.float64(t1))
    args = (params, np.asarray(xs0), ts, *scalars, jumps, np.float64(settings.rtol), np.float64(settings.atol))
    return args if region is None else (*args, np.asarray(region, dtype=np.int64))
