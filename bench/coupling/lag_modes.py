#!/usr/bin/env python3
"""Amplification factors of the interphase exchange, sequential vs staggered coupling.

The table of docs/coupling-schemes.md "Stability limit". Linear model per unit volume: gas
velocity u with the implicit drag K (v_bar - u) (coredemFoam's fvm::Sp), a = dt/tau_g,
tau_g = eps_g rho_g / K; particles v relaxing exactly to the gas of the step start within the
step, b = dt/tau_p, tau_p = eps_s rho_p / K; v_bar the window average sent to the gas.
sequential: the gas of step n uses v_bar^n; staggered: v_bar^(n-1). Prints |lambda| of the
decaying modes (the mode u = v has lambda = 1). Usage: bench/coupling/lag_modes.py
"""
import numpy as np


def matrix(a, b, staggered):
    e = np.exp(-b)
    w = (1 - e) / b  # weight of v^n in v_bar^n = u^n + (v^n - u^n) w
    if not staggered:  # state (u, v)
        return np.array([[(1 + a * (1 - w)) / (1 + a), a * w / (1 + a)], [1 - e, e]])
    # state (u^n, v^n, v_bar^(n-1))
    return np.array([[1 / (1 + a), 0, a / (1 + a)], [1 - e, e, 0], [1 - w, w, 0]])


def decaying(m):
    ev = sorted(np.linalg.eigvals(m), key=lambda z: -abs(z))
    return [z for z in ev if abs(z - 1) > 1e-9]


print("| b = dt/tau_p | a = dt/tau_g | staggered |lambda| (sign) | sequential |lambda| |")
print("|---|---|---|---|")
for b in (0.01, 0.1, 1, 10):
    for a in (1, 10, 100):
        s = decaying(matrix(a, b, True))[0]
        q = decaying(matrix(a, b, False))[0]
        sign = " (-)" if abs(s.imag) < 1e-12 and s.real < 0 else ""
        print(f"| {b} | {a} | {abs(s):.2f}{sign} | {abs(q):.2f} |")
