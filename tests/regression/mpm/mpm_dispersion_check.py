#!/usr/bin/env python3
"""Regression check of fig. 2.10 left: wave speeds of the overlocal model
measured in wellposed-mpm against the library's dispersion relation.

  mpm_dispersion_check.py EXE ORACLE DECK TOL CELLS F1 [F2 ...]

For each frequency F the deck (an overlocal material on the cone, &load
pulse = 'ramp_sine' with its amplitude) runs on a scene sized by the
predicted wavelength with CELLS cells per wavelength
(mpm/plots/mpm_dispersion.py: scene_overrides, measure; here the
stations span 1 to 2.5 wavelengths and the fit windows 3 periods): once as
given and once with h_zeta = 0, the local model with h_eta alone, whose
exact speed is the high-frequency bound c_hi. The local run measures the
grid's phase lag at this f and dx, which is second order,
c_MPM = c (1 - C (kappa dx)^2): C from the local run, and the overlocal
speed corrected by its own (kappa dx)^2. Passes when, at every frequency,
  - |c_corrected / c_predicted - 1| <= TOL;
  - the corrected speed lies at least 4 TOL from both local speeds (the
    bounds), so neither a run without the average (local h_eta + h_zeta)
    nor one whose average vanishes (local h_eta) can pass;
  - every station's fitted phase lies within 0.02 rad of the straight line,
    and sigma_xx and the plastic strain z only increase over the fit windows
    (the particles keep loading: the linearisation applies).
Exit status 0 on success, 1 with a message otherwise.
"""
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "..", "mpm", "plots"))
import mpm_dispersion as md  # noqa: E402


def main(argv):
    if len(argv) < 7:
        sys.stderr.write(__doc__)
        return 2
    exe, orc, deck = argv[1:4]
    tol, cells = float(argv[4]), float(argv[5])
    freqs = [float(v) for v in argv[6:]]
    root = os.path.join(os.getcwd(), "mpm_check_dispersion")
    os.makedirs(root, exist_ok=True)
    try:
        density, stress, props, text = md.probe(exe, deck, root)
        amplitude = md.deck_amplitude(text)
        bounds, pred = md.oracle(orc, density, stress, props, freqs)
        c_e, c_lo, c_hi = bounds
        c_slow = min(md.slowest_group_velocity(orc, density, stress, props, max(freqs)),
                     c_lo, c_hi)
        print(f"library: C_E = {c_e:.2f}, local h_eta + h_zeta = {c_lo:.2f}, "
              f"local h_eta = {c_hi:.2f} m/s; slowest group velocity {c_slow:.2f} m/s")
        ok = True
        for f, pr in zip(freqs, pred):
            tag = f"f{f:g}"
            over, dx, _ = md.scene_overrides(f, pr["c_phase"], c_slow, max(c_lo, c_hi),
                                             amplitude, cells, "overlocal_" + tag,
                                             last=2.5, periods=5.0)
            folder, wall = md.run_mpm(exe, deck, root, "overlocal_" + tag, over)
            m = md.measure(folder, f, c_slow)
            over_l = [o for o in over if not o.startswith("scene.name")] + \
                [f"scene.name='local_{tag}'", "material.h_zeta=0"]
            folder_l, wall_l = md.run_mpm(exe, deck, root, "local_" + tag, over_l)
            ml = md.measure(folder_l, f, c_slow)
            lag_coef = (1.0 - ml["c"] / c_hi) / (ml["kappa"] * dx) ** 2
            c_corr = m["c"] / (1.0 - lag_coef * (m["kappa"] * dx) ** 2)
            rel = c_corr / pr["c_phase"] - 1.0
            sep = min(abs(c_corr / c_lo - 1.0), abs(c_corr / c_hi - 1.0))
            checks = [
                (abs(rel) <= tol, f"corrected / predicted - 1 = {rel:+.4%} (tolerance {tol:.2%})"),
                (sep >= 4.0 * tol, f"distance to the nearer local speed {sep:.3%} "
                                   f"(required >= {4.0 * tol:.2%})"),
                (max(m["phase_rms"], ml["phase_rms"]) <= 0.02,
                 f"phase RMS about the line {m['phase_rms']:.2e} / {ml['phase_rms']:.2e} rad"),
                (min(m["min_rate"], m["min_zrate"], ml["min_rate"], ml["min_zrate"]) > 0.0,
                 f"least d sigma_xx/dt {m['min_rate']:.3g} Pa/s, least dz/dt "
                 f"{m['min_zrate']:.3g} /s over the windows (loading)"),
            ]
            print(f"f = {f:g} Hz (kappa = {pr['kappa']:.3f} rad/m, dx = {dx:g} m, "
                  f"{pr['c_phase'] / f / dx:.0f} cells per wavelength, {wall:.1f} s + "
                  f"{wall_l:.1f} s): predicted {pr['c_phase']:.2f} m/s; MPM {m['c']:.2f}, "
                  f"local h_eta {ml['c']:.2f} (exact {c_hi:.2f}: grid lag "
                  f"{ml['c'] / c_hi - 1.0:+.3%}), corrected {c_corr:.2f} m/s")
            for good, msg in checks:
                print(("  ok   " if good else "  FAIL ") + msg)
                ok = ok and good
    except md.RunError as e:
        print(f"FAIL {e}")
        return 1
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
