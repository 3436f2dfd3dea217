"""A moving rod stopper: linear motion through fmi2SetRealInputDerivatives, and a sudden jump of
x_s between communication points that must conserve the air in each chamber (adiabatic
compression P V^gamma = const over the jump, no pressure spike from differencing the input)."""

import math

import numpy as np

from jetpipe_fmu import initialize

V_DA = 2.5
X0, X1 = 0.054, 0.060
T_RAMP0, T_RAMP1, T_STOP = 0.1, 0.4, 0.8


def x_ramp(t):
    if t <= T_RAMP0:
        return X0
    if t >= T_RAMP1:
        return X1
    return X0 + (X1 - X0) * (t - T_RAMP0) / (T_RAMP1 - T_RAMP0)


def slope(t0, t1):
    return (x_ramp(t1) - x_ramp(t0)) / (t1 - t0)


def run_ramp(fmu, vrs, step, mode):
    """mode: 'derivative' (value at step start + first derivative over the step),
    'midpoint' (held value at the middle of the step), 'held' (held value at the step start).
    Returns F_act every 10 ms."""
    n = int(round(T_STOP / step))
    per_sample = int(round(0.01 / step))
    forces = [fmu.getReal([vrs["F_act"]])[0]]
    for j in range(n):
        t, t1 = j * step, (j + 1) * step
        if mode == "derivative":
            fmu.setReal([vrs["x_s"]], [x_ramp(t)])
            fmu.setRealInputDerivatives([vrs["x_s"]], [1], [slope(t, t1)])
        elif mode == "midpoint":
            fmu.setReal([vrs["x_s"]], [x_ramp(0.5 * (t + t1))])
        else:
            fmu.setReal([vrs["x_s"]], [x_ramp(t)])
        fmu.doStep(currentCommunicationPoint=t, communicationStepSize=t1 - t)
        if (j + 1) % per_sample == 0:
            forces.append(fmu.getReal([vrs["F_act"]])[0])
    return np.array(forces)


def test_input_derivative_matches_fine_held_steps(init_fmu, vrs):
    runs = {}
    for mode, step in (("derivative", 1e-2), ("midpoint", 1e-4), ("held", 1e-2)):
        fmu = init_fmu(inputs=(V_DA, X0))
        runs[mode] = run_ramp(fmu, vrs, step, mode)
    err_derivative = np.max(np.abs(runs["derivative"] - runs["midpoint"]))
    err_held = np.max(np.abs(runs["held"] - runs["midpoint"]))
    swing = np.ptp(runs["midpoint"])
    print(f"F_act swing during the ramp {swing:.3f} N; against 1e-4 s held steps: "
          f"with derivatives at 1e-2 s {err_derivative:.2e} N, held at 1e-2 s without derivatives {err_held:.2e} N")
    assert err_derivative <= 0.05, f"derivative run differs by {err_derivative} N from fine held steps"
    assert err_derivative < err_held, "the input derivative makes no difference: is it ignored?"


def volumes(x_s, p):
    A_p = math.pi * p["D_cyl"] ** 2 / 4
    x_p = x_s - (p["L_p"] + p["L_s"] + p["L_sup"])
    return A_p * x_p, A_p * (p["L_cyl"] - x_p - p["L_p"]), A_p


def jump_setup(init_fmu, vrs, t_jump=0.5):
    fmu = init_fmu(inputs=(V_DA, X0))
    t = 0.0
    for k in range(int(round(t_jump / 0.01))):
        fmu.doStep(currentCommunicationPoint=t, communicationStepSize=0.01)
        t = 0.01 * (k + 1)
    return fmu, t


def test_stopper_jump_conserves_air(init_fmu, vrs, defaults):
    p = defaults
    gamma = p["gamma"]
    x_new = 0.056
    # the volume formulas of MODEL.md with the default geometry
    V1a, V2a, A_p = volumes(X0, p)
    assert math.isclose(V1a, A_p * (X0 - 0.026)) and math.isclose(V2a, A_p * (0.070 - (X0 - 0.026)))
    V1b, V2b, _ = volumes(x_new, p)

    fmu, t = jump_setup(init_fmu, vrs)
    out = [vrs[n] for n in ("F_act", "P1", "P2")]
    F_a, P1a, P2a = fmu.getReal(out)
    fmu.setReal([vrs["x_s"]], [x_new])
    h = 1e-9  # a step so short that the orifice flows move the pressures by ~1e-9 relative
    fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
    F_b, P1b, P2b = fmu.getReal(out)

    P1_pred = P1a * (V1a / V1b) ** gamma
    P2_pred = P2a * (V2a / V2b) ** gamma
    spring = p["k_spring"] * (p["L_spring0"] - (x_new - p["L_s"] - p["L_p"]))
    F_pred = max(A_p * (P1_pred - P2_pred), spring)
    print(f"before: P1 {P1a:.3f} P2 {P2a:.3f} F {F_a:.6f}; after: P1 {P1b:.3f} (adiabatic {P1_pred:.3f}), "
          f"P2 {P2b:.3f} (adiabatic {P2_pred:.3f}), F {F_b:.6f} (adiabatic {F_pred:.6f})")
    for name, got, pv_before, V in (("P1", P1b, P1a * V1a ** gamma, V1b), ("P2", P2b, P2a * V2a ** gamma, V2b)):
        rel = abs(got * V ** gamma - pv_before) / pv_before
        assert rel <= 1e-6, f"{name} V^gamma changed by {rel:.3e} (relative) across the stopper jump"
    assert math.isclose(F_b, F_pred, rel_tol=1e-6), f"F_act {F_b} right after the jump, adiabatic value {F_pred}"


def test_stopper_jump_no_spike_and_step_independent(init_fmu, vrs):
    x_new = 0.056
    traces = {}
    for step in (1e-4, 1e-2):
        fmu, t0 = jump_setup(init_fmu, vrs)
        F_before = fmu.getReal([vrs["F_act"]])[0]
        fmu.setReal([vrs["x_s"]], [x_new])
        per_sample = int(round(0.01 / step))
        forces, fine = [], []
        for k in range(20):  # 0.2 s after the jump
            tk = t0 + 0.01 * k
            for j in range(per_sample):
                t = tk + j * step
                t1 = t0 + 0.01 * (k + 1) if j == per_sample - 1 else tk + (j + 1) * step
                fmu.doStep(currentCommunicationPoint=t, communicationStepSize=t1 - t)
                fine.append(fmu.getReal([vrs["F_act"]])[0])
            forces.append(fine[-1])
        traces[step] = (F_before, np.array(forces), np.array(fine))
    F_before, coarse, _ = traces[1e-2]
    _, fine_at_samples, fine_all = traces[1e-4]
    diff = np.max(np.abs(coarse - fine_at_samples))
    print(f"after the jump: F_act before {F_before:.4f} N, min {fine_all.min():.4f}, max {fine_all.max():.4f}; "
          f"step 1e-4 vs 1e-2 max abs diff {diff:.2e} N")
    assert diff <= 1e-4, f"the response to the stopper jump depends on the step size: {diff} N"
    # moving the stopper out grows chamber 1 and shrinks chamber 2: the force can only dip and recover
    assert fine_all.max() <= F_before * 1.01 + 1e-6, f"force spike after the jump: {fine_all.max()} N vs {F_before} N before"
