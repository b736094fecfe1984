# Prototype (issue 15, docs/study.md): does an out-of-plane position kick reveal the slow ΔLk = 2
# instability of the 600 bp circle within a few µs, where the twist-only probe does not? Prints
# E_total(t) of a kicked copy minus that of the unkicked continuation (both implicit, Δt ≤ 4.4 ns).
# Usage: PYTHONPATH=build/python /usr/bin/python3 prototypes/stability/kick_probe.py \
#            STATE|circle DLK T_US AMPLITUDE_A MODE
#   STATE: a final_state.csv to start from (rod.initial_shape), or "circle" (the twisted circle)
#   e.g. ... runs/dlk2_loose/final_state.csv 2 4 1.0 2   > dlk2_kick_m2.out
#        ... circle 1 4 1.0 2                            > dlk1_kick_m2.out
import sys, numpy as np, ibrod
state, dlk, T, amp, m = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4]), int(sys.argv[5])
def make(kick):
    cfg = ibrod.Config()
    for k, v in {"rod.excess_link": dlk, "rod.perturbation": [0.0], "time.scheme": "implicit",
                 "time.dt_ns": 4.4, "time.t_end_us": T, "run.threads": 1, "run.fftw_measure": False,
                 "output.every_us": 0.25, "time.stop_kinetic_kT": 0.0}.items():
        cfg[k] = v
    if state != "circle": cfg["rod.initial_shape"] = state
    sim = ibrod.Simulation(cfg)
    X, D = sim.positions.copy(), sim.triads.copy()
    if kick:
        c = X.mean(axis=0); phi = np.arctan2(X[:, 1] - c[1], X[:, 0] - c[0])
        X[:, 2] += amp * np.cos(m * phi)
        sim.set_state(X, D)
    return sim
out = []
for kick in (False, True):
    sim = make(kick); E = []
    while sim.time_us < T - 1e-9:
        sim.run(until_us=min(T, sim.time_us + 0.25)); o = sim.observables()
        E.append(tuple(float(np.ravel(o[k])[-1]) for k in ("time_us", "E_total_kT", "writhe")))
    out.append(np.array(E))
a, b = out
print(f"dLk={dlk} amp={amp} m={m}")
for i in range(0, len(a), max(1, len(a)//12)):
    print(f"t={a[i,0]:6.2f}  dE(kick-ref)={b[i,1]-a[i,1]:+.4e} kT  Wr ref={a[i,2]:+.2e} kick={b[i,2]:+.2e}")
print(f"t={a[-1,0]:6.2f}  dE(kick-ref)={b[-1,1]-a[-1,1]:+.4e} kT  Wr ref={a[-1,2]:+.2e} kick={b[-1,2]:+.2e}")
