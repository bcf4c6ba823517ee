#!/usr/bin/env python3
"""The MPM's wake behind a plastic 1D pulse against the continuum's own
(docs/research/waves.md, "Against the continuum").

usage: wake_continuum.py EXE DECK NAME [overrides...] [dev<X] [dev>X] [--fe-dx DX]

Runs wellposed-mpm on DECK (a bar of the wake deck's kind: a Drucker-Prager
material with the regular flow rule and linear hardening, uniaxial strain, a
preload, a triangle or raised-cosine traction pulse at x = 0) and solves the
same bar independently: lumped-mass linear finite elements, central
differences, CFL 0.5, the closed-form cone return (eq. 4.36) on every
element, at DX (default 1/64 m, 16 times finer than the fig. 2.8 grid; it
differs from 1/128 m by 0.010 MPa at most in the window). At each station, over the
window t > x/C_P + 2 tau (behind the slowest, plastic, front plus one pulse
duration), it prints the continuum's wake, max |sigma_xx - sigma_xx(0)|,
and the MPM's deviation from it, max and RMS of |sigma_MPM - sigma_FE|.
`dev<X` / `dev>X` (Pa) check the largest deviation over the stations: the
wake oscillation the scheme adds, without the smooth signal the continuum
itself leaves behind a plastic pulse. Exit 1 on a failed check.
"""
import math
import os
import re
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mpm_check  # noqa: E402


def deck_value(deck, group, key, overrides):
    """The text of `key = ...` in namelist group `group`: the run's override
    `group.key=value` if it has one, else the deck's."""
    for a in overrides:
        if a.lower().startswith(f"{group}.{key}=".lower()):
            return a.split("=", 1)[1].strip().strip("'\"")
    m = re.search(r"&%s\b(.*?)/" % group, deck, re.S | re.I)
    if not m:
        raise SystemExit(f"FAIL: the deck has no &{group} group")
    k = re.search(r"\b%s\s*=\s*(.*?)(?:,\s*[A-Za-z_]+\s*=|$)" % key, m.group(1), re.S | re.I)
    if not k:
        raise SystemExit(f"FAIL: &{group} has no {key}")
    return k.group(1).strip().strip("'\"")


def bar(folder, overrides):
    """The material, preload and load of the MPM run, from its run.h5 and
    the overrides it was run with."""
    import h5py
    with h5py.File(os.path.join(folder, "run.h5"), "r") as f:
        props = np.asarray(f.attrs["props"], dtype=float)
        deck = f.attrs["deck"]
        deck = deck.decode() if isinstance(deck, bytes) else deck
    k_, g_, beta, beta_p, k0, h = props[:6]
    if np.any(props[6:13] != 0.0):
        raise SystemExit("FAIL: the continuum reference has the regular flow rule with linear "
                         "hardening only (PROPS 7-13 must be 0)")
    s0 = [float(v) for v in deck_value(deck, "initial", "stress", overrides).split(",")[:3]]
    base = float(deck_value(deck, "load", "base", overrides))
    pulse = deck_value(deck, "load", "pulse", overrides)
    return dict(K=k_, G=g_, beta=beta, beta_p=beta_p, k0=k0, h=h, s0=np.array(s0),
                base=base, pulse=pulse)


def continuum(mat, rho, peak, tau, stations, t_end, dx):
    """Station histories of sigma_xx of the finite-element bar (long enough
    that nothing returns from its far end before t_end)."""
    kb, g = mat["K"], mat["G"]
    c = math.sqrt((kb + 4.0 * g / 3.0) / rho)
    n = int(math.ceil((c * t_end + max(stations) + 1.0) / dx))
    dt = 0.5 * dx / c
    sig = np.tile(mat["s0"][:, None], (1, n))
    z = np.zeros(n)
    v = np.zeros(n + 1)
    m = np.full(n + 1, rho * dx)
    m[0] = m[-1] = 0.5 * rho * dx
    n_m = math.sqrt(0.5 + 3.0 * mat["beta_p"] ** 2)
    a_m = (g + 9.0 * kb * mat["beta"] * mat["beta_p"]) / n_m
    keys = [int(x / dx) for x in stations]
    ts, hist = [], [[] for _ in stations]
    t = 0.0
    while t < t_end:
        shape = float(mpm_check.load_shape(t, tau, mat["pulse"]))
        f = np.zeros(n + 1)
        f[:-1] += sig[0]
        f[1:] -= sig[0]
        f[0] -= mat["base"] + peak * shape
        v += dt * f / m
        v[-1] = 0.0
        de = (v[1:] - v[:-1]) * dt / dx
        st = sig + kb * de
        st[0] += 2.0 * g * (de - de / 3.0)
        st[1:] += 2.0 * g * (-de / 3.0)
        i1 = st.sum(0)
        s = st - i1 / 3.0
        q = np.sqrt((s ** 2).sum(0))
        ftr = q / math.sqrt(2.0) + mat["beta"] * i1 - (mat["k0"] + mat["h"] * z)
        pl = ftr > 0.0
        if pl.any():
            # cone return, eq. 4.36: x = f_tr/(a + h), deviator shrunk
            x = np.where(pl, ftr / (a_m + mat["h"]), 0.0)
            x_max = q * n_m / (math.sqrt(2.0) * g)
            if np.any(x[pl] >= x_max[pl]):
                raise SystemExit("FAIL: the continuum reference reached the apex")
            shrink = 1.0 - x / np.where(pl, x_max, 1.0)
            i1n = i1 - 9.0 * kb * mat["beta_p"] * x / n_m
            st = np.where(pl, shrink * s + i1n / 3.0, st)
            z = z + x
        sig = st
        t += dt
        ts.append(t)
        for k, e in enumerate(keys):
            hist[k].append(sig[0, e])
    return np.array(ts), np.array(hist)


def compare(folder, overrides, fe_dx):
    """Per station: the continuum's wake and the MPM's deviation (Pa)."""
    t, x, s, nums = mpm_check.histories(folder)
    mat = bar(folder, overrides)
    tau = nums["load_duration"]
    tf, sf = continuum(mat, nums["density"], nums["load_peak"], tau, list(x), t[-1], fe_dx)
    rows = []
    for i, xi in enumerate(x):
        w = t > xi / nums["c_plastic"] + 2.0 * tau
        ref = np.interp(t, tf, sf[i])
        d = (s[i] - ref)[w]
        rows.append((xi, np.max(np.abs(ref[w] - mat["s0"][0])), np.max(np.abs(d)),
                     math.sqrt(np.mean(d ** 2)), np.max(np.abs(s[i][w] - s[i][0]))))
    return rows


def main(argv):
    fe_dx = 1.0 / 64.0
    if "--fe-dx" in argv:
        i = argv.index("--fe-dx")
        fe_dx = float(argv[i + 1])
        argv = argv[:i] + argv[i + 2:]
    if len(argv) < 4:
        print(__doc__)
        return 2
    exe, deck, name = argv[1:4]
    checks = [a for a in argv[4:] if re.match(r"^dev[<>]", a)]
    args = [a for a in argv[4:] if a not in checks]
    p, folder, cmd = mpm_check.run(exe, deck, name, args)
    mpm_check.need_ok(p, cmd)
    rows = compare(folder, args, fe_dx)
    for xi, cont, dmax, drms, own in rows:
        print(f"station {xi:5.1f} m: continuum's wake {cont / 1e6:.3f} MPa, the MPM's "
              f"{own / 1e6:.3f}; deviation max {dmax / 1e6:.3f} MPa, RMS {drms / 1e6:.3f}")
    dev = max(r[2] for r in rows)
    bad = 0
    for c in checks:
        ref = float(c[4:])
        ok = dev < ref if c[3] == "<" else dev > ref
        print(("ok   " if ok else "FAIL ") + f"dev = {dev:.4g} Pa, expected {c[3]} {ref:g}")
        bad += not ok
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
