#!/usr/bin/env python3
"""Regression check of the generalized Duvaut-Lions form (PROPS(15) = 1) in
wellposed-mpm: a small raised-cosine pulse on a state at yield.

  gdl_check.py PEAK_TOL RISE_TOL RATIO_TOL EXE DECK NAME [driver args]

While the quasi-static state loads plastically the form is the standard
linear solid of tests/regression/mpm/mpm_check.py (mode sls): instantaneous
modulus M_e = rho C_E^2, relaxed M_p = rho C_P^2. At every station the peak
must agree with that linear solution within PEAK_TOL (relative) and the
rising flank (up to the linear peak) within RISE_TOL (relative L2). Behind
the pulse the quasi-static state unloads elastically, C : d eps - d sigma_qs
= 0, so the overstress decays as exp(-t/tau) at every particle and z
approaches z_qs alike: the increments of z at a station over successive
windows of length w must shrink by exp(-w/tau), within RATIO_TOL relative
(the default form has no such tail: it stops flowing when its trial stress
unloads). Stations whose record ends before three windows are skipped for
that check, but one at least must be checked.
"""
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "mpm"))
import mpm_check  # noqa: E402

WINDOW = 5.0e-3  # s, the tail windows
TAIL_START = 8.0e-3  # s after the linear peak: the pulse (10 ms) has passed


def main(argv):
    if len(argv) < 7:
        sys.stderr.write(__doc__)
        return 2
    import h5py
    import numpy as np
    peak_tol, rise_tol, ratio_tol = (float(v) for v in argv[1:4])
    exe, deck, name = argv[4:7]
    p, folder, cmd = mpm_check.run(exe, deck, name, argv[7:])
    mpm_check.need_ok(p, cmd)
    t, x, s, nums = mpm_check.histories(folder)
    with h5py.File(os.path.join(folder, "run.h5"), "r") as f:
        tau = float(f.attrs["props"][10])
        form = float(f.attrs["props"][14]) if len(f.attrs["props"]) > 14 else 0.0
        z = np.asarray(f["stations/z"][()])
    if tau <= 0.0 or form != 1.0:
        print("FAIL the run is not the generalized Duvaut-Lions form (PROPS(11) > 0, "
              "PROPS(15) = 1)")
        return 1
    linear = mpm_check.linear_dl_histories(t, x, nums, tau)
    ok, tails = True, 0
    expected = math.exp(-WINDOW / tau)
    for i, xi in enumerate(x):
        ds = s[i] - s[i, 0]
        lin = linear[i]
        k = int(np.argmax(lin))
        rise = (t <= t[k]) & (lin >= 0.0)
        peak_err = abs(ds.max() - lin.max()) / lin.max()
        l2 = float(np.linalg.norm((ds - lin)[rise]) / np.linalg.norm(lin[rise]))
        good = peak_err <= peak_tol and l2 <= rise_tol
        line = (f"x = {xi:g} m: peak {ds.max():.5g} Pa, linear model {lin.max():.5g} Pa, "
                f"relative error {peak_err:.3e} (tolerance {peak_tol:g}), rising-flank L2 "
                f"{l2:.3e} (tolerance {rise_tol:g})")
        times = [t[k] + TAIL_START + j * WINDOW for j in range(3)]
        if times[-1] <= t[-1]:
            inc = np.diff(np.interp(times, t, z[i]))
            ratio = inc[1] / inc[0] if inc[0] > 0.0 else float("nan")
            err = abs(ratio / expected - 1.0)
            tails += 1
            good = good and err <= ratio_tol
            line += (f"; tail: z increments over {WINDOW * 1e3:g} ms shrink by {ratio:.7f}, "
                     f"exp(-w/tau) = {expected:.7f}, relative error {err:.2e} "
                     f"(tolerance {ratio_tol:g})")
        ok = ok and good
        print(("ok   " if good else "FAIL ") + line)
    if tails == 0:
        print("FAIL no station's record covers the tail windows")
        ok = False
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
