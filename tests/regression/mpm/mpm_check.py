#!/usr/bin/env python3
"""Regression checks of wellposed-mpm (1D): run the driver on a deck and
compare summary figures, or station histories between runs, with stated
tolerances. Each mode exits 0 on success, 1 with a message otherwise.

  mpm_check.py run   EXE DECK NAME [driver args] [check ...]
      check: KEY=VALUE:TOL   |summary[KEY] - VALUE| <= TOL
             KEY=WORD        the summary's word (true, blended) is WORD
             KEY<VALUE, KEY>VALUE
             KEY/KEY2=VALUE:TOL  ratio of two summary figures
             KEY-KEY2=VALUE:TOL  difference of two summary figures
  mpm_check.py fail  REGEX EXE DECK NAME [driver args]
      the run must exit non-zero, print REGEX (Python re, searched in
      stderr) and leave no finished output folder ROOT/NAME.
  mpm_check.py order EXE DECK NAME BOUND DX1 DX2 [driver args]
      runs at DX1 and DX2 (DX2 < DX1), measures the L2 error of the station
      histories of sigma_xx against d'Alembert (the load history shifted by
      x / C_E) and requires the observed order log(e1/e2)/log(DX1/DX2) > BOUND.
  mpm_check.py same  TOL EXE DECK NAME [driver args] -- [driver args of run B]
      two runs of the same deck; max |sigma_xx(A) - sigma_xx(B)| over all
      stations and samples, over the load peak, must be <= TOL.
  mpm_check.py ratio KEY BELOW EXE DECK NAME [driver args] -- [driver args of run B]
      two runs of the same deck (B typically on a finer grid); the summary
      figure KEY of B over that of A must be below BELOW.
  mpm_check.py sls   PEAK_TOL L2_TOL EXE DECK NAME [driver args]
      a Duvaut-Lions run (PROPS(11) = tau > 0) of a small raised-cosine
      pulse on a state at yield, against the linearised model: a standard
      linear solid with instantaneous modulus M_e = rho C_E^2 and relaxed
      modulus M_p = rho C_P^2, M(w) = (M_p + i w tau M_e)/(1 + i w tau),
      solved exactly in frequency (the boundary history times
      exp(-i k x), k = w sqrt(rho/M(w))). At every station the peak must
      agree within PEAK_TOL relative, and the history within L2_TOL
      (relative L2) over the pulse's main lobe (where the linear solution is >= 0; behind
      it the linear model keeps relaxing into a compressive undershoot that
      the model does not have, since its trial stress unloads elastically).

Driver arguments are anything after NAME that is not a check (overrides are
group.key=value: a dot before '=').
"""
import math
import os
import re
import shutil
import subprocess
import sys


def split_args(items):
    args, checks = [], []
    for a in items:
        m = re.match(r"^([A-Za-z0-9_]+)([-/][A-Za-z0-9_]+)?(=|<|>)", a)
        if m and not a.startswith("-"):
            checks.append(a)
        else:
            args.append(a)
    return args, checks


def run(exe, deck, name, args, root=None):
    root = root or os.path.join(os.getcwd(), "mpm_check_" + name)
    if os.path.isdir(root):
        shutil.rmtree(root)
    os.makedirs(root)
    cmd = [exe, "--out", root, "--name", name, "--no-plot", deck] + args
    p = subprocess.run(cmd, capture_output=True, text=True)
    return p, os.path.join(root, name), cmd


def summary(folder):
    vals = {}
    with open(os.path.join(folder, "summary.txt")) as f:
        for line in f:
            line = line.split("#", 1)[0].strip()
            if "=" in line:
                k, v = line.split("=", 1)
                vals[k.strip()] = v.strip()
    return vals


def num(vals, key):
    if key not in vals:
        raise SystemExit(f"FAIL: summary.txt has no key {key}")
    v = vals[key]
    try:
        return float(v)
    except ValueError:
        return v   # a word (true, false, a scheme's name): compared as text


def evaluate(vals, check):
    m = re.match(r"^([A-Za-z0-9_]+)(?:([-/])([A-Za-z0-9_]+))?(=|<|>)(.*)$", check)
    k1, op2, k2, op, rhs = m.groups()
    a = num(vals, k1)
    if op2:
        b = num(vals, k2)
        a = a / b if op2 == "/" else a - b
    label = k1 + (op2 + k2 if op2 else "")
    if op == "=":
        if ":" in rhs:
            ref, tol = rhs.split(":")
            ok = abs(a - float(ref)) <= float(tol)
            return ok, f"{label} = {a:.7g}, expected {ref} +- {tol}"
        ok = str(a) == rhs
        return ok, f"{label} = {a}, expected {rhs}"
    ref = float(rhs)
    ok = a < ref if op == "<" else a > ref
    return ok, f"{label} = {a:.7g}, expected {op} {ref}"


def need_ok(p, cmd):
    if p.returncode != 0:
        print(" ".join(cmd))
        print(p.stdout[-3000:])
        print(p.stderr[-3000:])
        raise SystemExit(f"FAIL: exit status {p.returncode}")


def mode_run(argv):
    exe, deck, name = argv[:3]
    args, checks = split_args(argv[3:])
    p, folder, cmd = run(exe, deck, name, args)
    need_ok(p, cmd)
    vals = summary(folder)
    bad = 0
    for c in checks:
        ok, msg = evaluate(vals, c)
        print(("ok   " if ok else "FAIL ") + msg)
        bad += not ok
    bad += xdmf_problems(folder)
    return 1 if bad else 0


def xdmf_problems(folder):
    """A run with particle snapshots has a run.xdmf that describes them."""
    import h5py
    with h5py.File(os.path.join(folder, "run.h5"), "r") as f:
        nsnap = int(f["snapshots/count"][0]) if "snapshots/count" in f else 0
    if nsnap == 0:
        return 0
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    import xdmf_check
    found = xdmf_check.problems(folder, grids=nsnap)
    for msg in found:
        print("FAIL " + msg)
    if not found:
        print("ok   run.xdmf describes the %d snapshots" % nsnap)
    return len(found)


def mode_fail(argv):
    regex, exe, deck, name = argv[:4]
    p, folder, cmd = run(exe, deck, name, argv[4:])
    print(" ".join(cmd))
    print("exit status", p.returncode)
    print("stderr:", p.stderr.strip())
    if p.returncode == 0:
        print("FAIL: the run succeeded")
        return 1
    if not re.search(regex, p.stderr, re.S):
        print(f"FAIL: stderr does not match {regex!r}")
        return 1
    if os.path.exists(folder):
        print(f"FAIL: {folder} exists: a failed run left output that looks finished")
        return 1
    print("ok   non-zero exit, clear message, no finished output")
    return 0


def histories(folder):
    import h5py
    import numpy as np
    with h5py.File(os.path.join(folder, "run.h5"), "r") as f:
        t = f["stations/time"][()]
        x = f["stations/x"][()]
        s = f["stations/sigma_xx"][()]
        names = f.attrs["numbers_names"]
        if isinstance(names, bytes):
            names = names.decode()
        nums = dict(zip(names.split(), f.attrs["numbers"]))
    return np.asarray(t), np.asarray(x), np.asarray(s), nums


def load_shape(t, duration, kind):
    import numpy as np
    u = np.clip(t / duration, 0.0, 1.0)
    if kind == "cosine":
        return 0.5 * (1.0 - np.cos(2.0 * np.pi * u))
    return 1.0 - np.abs(2.0 * u - 1.0)


def dalembert_error(folder, kind):
    import numpy as np
    t, x, s, nums = histories(folder)
    c, peak, dur = nums["c_elastic"], nums["load_peak"], nums["load_duration"]
    ds = s - s[:, :1]
    err2, ref2 = 0.0, 0.0
    for i, xi in enumerate(x):
        exact = peak * load_shape(t - xi / c, dur, kind)
        err2 += np.sum((ds[i] - exact) ** 2)
        ref2 += np.sum(exact ** 2)
    return math.sqrt(err2 / ref2)


def mode_order(argv):
    exe, deck, name, bound, dx1, dx2 = argv[:6]
    args = argv[6:]
    kind = "cosine" if any(a == "load.pulse='cosine'" for a in args) else None
    with open(deck) as f:
        text = f.read()
    if kind is None:
        kind = "cosine" if re.search(r"pulse\s*=\s*'cosine'", text) else "triangle"
    errs = []
    for dx in (dx1, dx2):
        p, folder, cmd = run(exe, deck, f"{name}_dx{dx}", args + [f"grid.dx={dx}"])
        need_ok(p, cmd)
        errs.append(dalembert_error(folder, kind))
        print(f"dx = {dx}: relative L2 error against d'Alembert = {errs[-1]:.4e}")
    order = math.log(errs[0] / errs[1]) / math.log(float(dx1) / float(dx2))
    ok = order > float(bound)
    print(("ok   " if ok else "FAIL ") + f"observed order {order:.3f}, bound > {bound}")
    return 0 if ok else 1


def mode_same(argv):
    import numpy as np
    tol, exe, deck, name = argv[:4]
    rest = argv[4:]
    k = rest.index("--")
    a_args, b_args = rest[:k], rest[k + 1:]
    pa, fa, ca = run(exe, deck, name + "_a", a_args)
    need_ok(pa, ca)
    pb, fb, cb = run(exe, deck, name + "_b", b_args)
    need_ok(pb, cb)
    _, _, sa, nums = histories(fa)
    _, _, sb, _ = histories(fb)
    n = min(sa.shape[1], sb.shape[1])
    diff = float(np.max(np.abs(sa[:, :n] - sb[:, :n]))) / abs(nums["load_peak"])
    ok = diff <= float(tol)
    print(("ok   " if ok else "FAIL ") +
          f"max |sigma_xx(A) - sigma_xx(B)| / load peak = {diff:.3e}, tolerance {tol}")
    return 0 if ok else 1


def mode_ratio(argv):
    key, below, exe, deck, name = argv[:5]
    rest = argv[5:]
    k = rest.index("--")
    vals = []
    for tag, args in (("_a", rest[:k]), ("_b", rest[k + 1:])):
        p, folder, cmd = run(exe, deck, name + tag, args)
        need_ok(p, cmd)
        vals.append(num(summary(folder), key))
        print(f"run {tag[1:].upper()} ({' '.join(args)}): {key} = {vals[-1]:.6g}")
    ratio = vals[1] / vals[0]
    ok = ratio < float(below)
    print(("ok   " if ok else "FAIL ") + f"{key}(B) / {key}(A) = {ratio:.4f}, required < {below}")
    return 0 if ok else 1


def linear_dl_histories(t, xs, nums, tau):
    """Stress increments at the stations xs of the linearised Duvaut-Lions
    bar driven by the raised-cosine boundary pulse: a standard linear solid
    (see the module doc), evaluated by FFT on a window four times the run
    long; one row per station, sampled at t."""
    import numpy as np
    rho = nums["density"]
    m_e, m_p = rho * nums["c_elastic"] ** 2, rho * nums["c_plastic"] ** 2
    n = 1 << 16
    dt = 4.0 * t[-1] / n
    tt = np.arange(n) * dt
    load = nums["load_peak"] * load_shape(tt, nums["load_duration"], "cosine")
    w = 2.0 * np.pi * np.fft.rfftfreq(n, dt)
    modulus = (m_p + 1j * w * tau * m_e) / (1.0 + 1j * w * tau)
    k = w * np.sqrt(rho / modulus)
    spectrum = np.fft.rfft(load)
    return np.array([np.interp(t, tt, np.fft.irfft(spectrum * np.exp(-1j * k * x), n))
                     for x in xs])


def mode_sls(argv):
    import h5py
    import numpy as np
    peak_tol, l2_tol = float(argv[0]), float(argv[1])
    exe, deck, name = argv[2:5]
    p, folder, cmd = run(exe, deck, name, argv[5:])
    need_ok(p, cmd)
    t, x, s, nums = histories(folder)
    with h5py.File(os.path.join(folder, "run.h5"), "r") as f:
        tau = float(f.attrs["props"][10])
    if tau <= 0.0:
        print("FAIL the run has no Duvaut-Lions relaxation time (PROPS(11) = 0)")
        return 1
    ok = True
    linear = linear_dl_histories(t, x, nums, tau)
    for i, xi in enumerate(x):
        ds = s[i] - s[i, 0]
        lin = linear[i]
        lobe = lin >= 0.0
        peak_err = abs(ds.max() - lin.max()) / lin.max()
        l2 = float(np.linalg.norm((ds - lin)[lobe]) / np.linalg.norm(lin[lobe]))
        good = peak_err <= peak_tol and l2 <= l2_tol
        ok = ok and good
        print(("ok   " if good else "FAIL ") +
              f"x = {xi:g} m: peak {ds.max():.5g} Pa, linear model {lin.max():.5g} Pa "
              f"(growth {lin.max() / nums['load_peak']:.3f} x the load peak), "
              f"relative error {peak_err:.3e} (tolerance {peak_tol:g}), "
              f"main-lobe L2 {l2:.3e} (tolerance {l2_tol:g})")
    return 0 if ok else 1


def main(argv):
    if len(argv) < 2:
        sys.stderr.write(__doc__)
        return 2
    modes = {"run": mode_run, "fail": mode_fail, "order": mode_order, "same": mode_same,
             "sls": mode_sls, "ratio": mode_ratio}
    return modes[argv[1]](argv[2:])


if __name__ == "__main__":
    sys.exit(main(sys.argv))
