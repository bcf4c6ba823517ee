"""Plots of a wellposed-mpm axisymmetric run (the cylinder in r-z).

usage: mpm_axisymmetric.py RUN_DIR
       mpm_axisymmetric.py --compare OUT.png RUN_DIR [RUN_DIR ...]

Reads RUN_DIR/run.h5 (its last snapshot, snapshots/snap_N) and summary.txt, and writes beside them:
  radial_stress.png   sigma_rr, sigma_tt, sigma_zz of every particle against r,
                      with the closed form the run compared with (&cylinder
                      closed_form = 'lame' or 'hill');
  plastic_strain.png  ||eps^p|| over the r-z section (when any particle yielded).
--compare draws ||eps^p|| of each run's last snapshot side by side into
OUT.png, on one colour scale (meshes and models of one specimen), and
prints for each the largest ||eps^p||, where it is, and the zone's width
there: the FWHM of ||eps^p|| in z along the axis (particles within 0.3
cell of the innermost) and in r across that height (within 0.3 cell).
"""
import math
import os
import sys

import h5py
import matplotlib
import matplotlib.pyplot as plt
import numpy as np
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "common"))
from summary_text import read_summary  # noqa: E402


def last_snapshot(h5):
    group = h5["snapshots"]
    names = sorted((k for k in group.keys() if k.startswith("snap_")),
                   key=lambda s: int(s.split("_")[1]))
    return group[names[-1]]


def lame(a, b, pa, pb, nu, r):
    """Lame's sigma_rr, sigma_tt, sigma_zz (tension +; pressures compression +)."""
    ca = (pa * a**2 - pb * b**2) / (b**2 - a**2)
    cb = (pa - pb) * a**2 * b**2 / (b**2 - a**2)
    return ca - cb / r**2, ca + cb / r**2, 2.0 * nu * ca + 0.0 * r


def hill(a, b, k, c, r):
    """Hill's sigma_rr, sigma_tt, sigma_zz at r, plastic out to c (tension +)."""
    p = k * (2.0 * math.log(c / a) + 1.0 - c**2 / b**2)
    if r < c:
        rr = -p + 2.0 * k * math.log(r / a)
        tt = rr + 2.0 * k
    else:
        rr = -k * c**2 * (1.0 / r**2 - 1.0 / b**2)
        tt = k * c**2 * (1.0 / r**2 + 1.0 / b**2)
    return rr, tt, 0.5 * (rr + tt)


def ramp(t, t_ramp):
    if t_ramp <= 0.0:
        return 1.0
    return 0.5 * (1.0 - math.cos(math.pi * min(1.0, t / t_ramp)))


def main(run_dir):
    matplotlib.use("Agg")
    sm = read_summary(run_dir)
    with h5py.File(os.path.join(run_dir, "run.h5"), "r") as h5:
        snap = last_snapshot(h5)
        rz = np.asarray(snap["rz"]).reshape(-1, 2)
        s = {k: np.asarray(snap[k]).ravel() for k in ("sigma_rr", "sigma_tt", "sigma_zz")}
        ep = np.asarray(snap["plastic_strain"]).ravel()
        t = float(np.asarray(snap["time"]).ravel()[0])
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for key, colour in (("sigma_rr", "C0"), ("sigma_tt", "C1"), ("sigma_zz", "C2")):
        ax.plot(rz[:, 0], s[key] * 1e-6, ".", color=colour, ms=3, label=key + " (MPM)")
    if sm.get("closed_form") == "lame" and "lame_poisson" in sm:
        a, b = float(sm["r_inner"]), float(sm["r_outer"])
        f = ramp(t, float(sm["pressure_ramp"]))
        r = np.linspace(max(a, 1e-9 * b), b, 200)
        ex = lame(a, b, f * float(sm["p_inner"]), f * float(sm["p_outer"]),
                  float(sm["lame_poisson"]), r)
        for e, colour in zip(ex, ("C0", "C1", "C2")):
            ax.plot(r, e * 1e-6, "-", color=colour, lw=1)
        ax.plot([], [], "k-", lw=1, label="Lame (plane strain)")
    if sm.get("closed_form") == "hill" and "hill_plastic_radius" in sm:
        a, b = float(sm["r_inner"]), float(sm["r_outer"])
        k, c = float(sm["hill_yield_k"]), float(sm["hill_plastic_radius"])
        r = np.linspace(a, b, 200)
        ex = np.array([hill(a, b, k, c, x) for x in r]).T
        for e, colour in zip(ex, ("C0", "C1", "C2")):
            ax.plot(r, e * 1e-6, "-", color=colour, lw=1)
        ax.axvline(c, color="0.6", lw=0.8, ls=":")
        ax.plot([], [], "k-", lw=1, label="Hill (plane strain, nu = 1/2)")
    ax.set_xlabel("r (m)")
    ax.set_ylabel("stress (MPa)")
    ax.set_title("%s at t = %.3g ms" % (sm.get("scene", ""), t * 1e3))
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(run_dir, "radial_stress.png"), dpi=120)
    if ep.max() > 0.0:
        fig, ax = plt.subplots(figsize=(4.8, 6.0))
        sc = ax.scatter(rz[:, 0], rz[:, 1], c=ep, s=6, cmap="viridis")
        fig.colorbar(sc, ax=ax, label="||eps^p||")
        ax.set_aspect("equal")
        ax.set_xlabel("r (m)")
        ax.set_ylabel("z (m)")
        fig.tight_layout()
        fig.savefig(os.path.join(run_dir, "plastic_strain.png"), dpi=120)


def fwhm(x, v):
    """The extent of x where v is at least half its largest (0 without any)."""
    if v.size == 0 or v.max() <= 0.0:
        return 0.0
    kept = x[v >= 0.5 * v.max()]
    return float(kept.max() - kept.min())


def zone(rz, ep, h):
    """The largest ||eps^p||, its (r, z), its FWHM along the axis and across."""
    j = int(np.argmax(ep))
    axis = rz[:, 0] < rz[:, 0].min() + 0.3 * h
    across = np.abs(rz[:, 1] - rz[j, 1]) < 0.3 * h
    return ep[j], rz[j], fwhm(rz[axis, 1], ep[axis]), fwhm(rz[across, 0], ep[across])


def compare(out, run_dirs):
    matplotlib.use("Agg")
    panels = []
    for d in run_dirs:
        with h5py.File(os.path.join(d, "run.h5"), "r") as h5:
            snap = last_snapshot(h5)
            panels.append((os.path.basename(os.path.normpath(d)),
                           np.asarray(snap["rz"]).reshape(-1, 2),
                           np.asarray(snap["plastic_strain"]).ravel(),
                           float(np.asarray(snap["time"]).ravel()[0])))
    for (name, rz, ep, t), d in zip(panels, run_dirs):
        h = float(read_summary(d)["dx"])
        peak, at, along, across = zone(rz, ep, h)
        print("%s t = %.4g s: largest ||eps^p|| %.3f at (%.2f, %.2f) m, FWHM along the axis "
              "%.2f m, across %.2f m" % (name, t, peak, at[0], at[1], along, across))
    top = max(p[2].max() for p in panels)
    fig, axes = plt.subplots(1, len(panels), figsize=(2.6 * len(panels) + 1.0, 5.2),
                             squeeze=False)
    for ax, (name, rz, ep, t) in zip(axes[0], panels):
        sc = ax.tricontourf(rz[:, 0], rz[:, 1], ep, levels=np.linspace(0.0, top, 21),
                            cmap="viridis")
        ax.set_aspect("equal")
        ax.set_title("%s\nt = %.1f ms" % (name, t * 1e3), fontsize=8)
        ax.set_xlabel("r (m)")
    axes[0][0].set_ylabel("z (m)")
    fig.colorbar(sc, ax=list(axes[0]), label="||eps^p||", format="%.2f")
    fig.savefig(out, dpi=80)


if __name__ == "__main__":
    if len(sys.argv) >= 4 and sys.argv[1] == "--compare":
        compare(sys.argv[2], sys.argv[3:])
    elif len(sys.argv) == 2:
        main(sys.argv[1])
    else:
        sys.exit(__doc__)
