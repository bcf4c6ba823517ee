"""Plots of a wellposed-mpm plate run (chapter 4, fig. 4.2-4.6).

usage: mpm_plate.py RUN_DIR TAG [TAG ...]

Reads RUN_DIR/run.h5 and writes, beside it:
  plastic_strain.png  contours of ||eps^p||, one panel per case (as fig. 4.2
                      and 4.4) on one colour scale, each at its band
                      stage (summary.txt band_stage_time: the run writes a
                      snapshot there; the last snapshot when there is none),
                      the fitted centre line and its +- FWHM/2 lines marked;
  stress_strain.png   applied stress against apparent axial strain, all
                      cases (as fig. 4.3, 4.5, 4.6);
  iterations.png      nonlocal iterations per plastic step (when iterated);
  newton.png          an implicit run's Newton histories (<tag>_newton.csv):
                      the relative residual after each solve, every step,
                      and the solves and step size against time.
"""
import sys
import os

import h5py
import matplotlib
import matplotlib.pyplot as plt
import matplotlib.tri as mtri
import numpy as np


def last_snapshot(group):
    names = [k for k in group.keys() if k.startswith("snap_")]
    names.sort(key=lambda s: int(s.split("_")[1]))
    return group[names[-1]]


def read_summary(run_dir):
    values = {}
    path = os.path.join(run_dir, "summary.txt")
    if os.path.exists(path):
        with open(path) as f:
            for line in f:
                line = line.split("#", 1)[0]
                if "=" in line:
                    k, v = line.split("=", 1)
                    values[k.strip()] = v.strip()
    return values


def number(values, key):
    try:
        return float(values[key])
    except (KeyError, ValueError):
        return None


def stage_snapshot(group, t_stage):
    """The snapshot nearest t_stage (the last one when t_stage is None)."""
    if t_stage is None:
        return last_snapshot(group)
    names = [k for k in group.keys() if k.startswith("snap_")]
    return group[min(names, key=lambda s: abs(float(group[s]["time"][0]) - t_stage))]


def mark_band(ax, sm, tag, height):
    """The fitted centre line x = x0 + slope y and the lines FWHM/2 either side."""
    x0, slope = number(sm, tag + ".band_line_x0"), number(sm, tag + ".band_line_slope")
    w = number(sm, tag + ".band_fwhm_normal")
    if sm.get(tag + ".band_fwhm_normal") == "not_applicable":
        return ", FWHM not_applicable (summary.txt says why)"
    if x0 is None or slope is None or w is None:
        return ""
    y = np.linspace(0.2 * height, 0.8 * height, 2)
    off = 0.5 * w * np.sqrt(1.0 + slope ** 2)   # horizontal offset of a normal distance w/2
    ax.plot(x0 + slope * y, y, "w-", lw=0.9)
    for sgn in (-1.0, 1.0):
        ax.plot(x0 + slope * y + sgn * off, y, "w--", lw=0.7)
    return ", FWHM %.2f m at %.0f deg" % (w, number(sm, tag + ".band_angle_deg"))


def contour_figure(cases, sm, tags):
    """||eps^p|| of each case at its band stage, one panel per case on one
    colour scale (0 to the largest value of all panels), the fitted centre
    line and the lines FWHM/2 either side of it marked. Returns the figure
    and each panel's contour levels."""
    n = len(tags)
    drawn = {}
    snaps = {tag: stage_snapshot(cases[tag], number(sm, tag + ".band_stage_time")) for tag in tags}
    fig, axes = plt.subplots(1, n, figsize=(3.2 * n + 1.2, 4.6), squeeze=False)
    vmax = 0.0
    for tag in tags:
        vmax = max(vmax, float(np.max(snaps[tag]["plastic_strain"][()])))
    vmax = vmax if vmax > 0 else 1.0
    levels = np.linspace(0.0, vmax, 21)
    for ax, tag in zip(axes[0], tags):
        snap = snaps[tag]
        xy = snap["xy"][()]
        ep = snap["plastic_strain"][()]
        tri = mtri.Triangulation(xy[:, 0], xy[:, 1])
        # drop long triangles that bridge outside the body
        p = xy[tri.triangles]
        edge = np.max(np.linalg.norm(p - np.roll(p, 1, axis=1), axis=2), axis=1)
        tri.set_mask(edge > 3.0 * np.median(edge))
        cs = ax.tricontourf(tri, ep, levels=levels, cmap="viridis", extend="max")
        drawn[tag] = cs.levels
        ax.set_aspect("equal")
        # the fit window is 0.2-0.8 of the plate's height (its top: the highest particle)
        label = mark_band(ax, sm, tag, float(np.max(xy[:, 1])))
        ax.set_xlim(float(np.min(xy[:, 0])) - 0.1, float(np.max(xy[:, 0])) + 0.1)
        stage = number(sm, tag + ".band_stage_time")
        ax.set_title("%s, t = %.2f ms%s\n%s" % (
            tag, 1e3 * float(snap["time"][0]),
            "" if stage is None else " (stage %.2f ms)" % (1e3 * stage), label.lstrip(", ")),
            fontsize=7)
        ax.set_xlabel("x (m)")
    axes[0][0].set_ylabel("y (m)")
    fig.colorbar(cs, ax=axes[0].tolist(), label="||eps^p||", shrink=0.85)
    return fig, drawn


def main(argv):
    run_dir, tags = argv[1], argv[2:]
    h5 = h5py.File(os.path.join(run_dir, "run.h5"), "r")
    cases = h5["cases"]

    sm = read_summary(run_dir)
    fig, _ = contour_figure(cases, sm, tags)
    fig.savefig(os.path.join(run_dir, "plastic_strain.png"), dpi=130)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(6.0, 4.2))
    for tag in tags:
        c = cases[tag]["curve"][()]
        ax.plot(100.0 * c[:, 1], 1e-6 * c[:, 2], label=tag, lw=1.2)
    ax.set_xlabel("apparent axial strain (% change in height)")
    ax.set_ylabel("applied stress (MPa, compression +)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(run_dir, "stress_strain.png"), dpi=130)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(6.0, 3.6))
    any_it = False
    for tag in tags:
        it = cases[tag]["iterations"][()]
        npl = cases[tag]["n_plastic"][()]
        mask = (npl > 0) & (it > 0)
        if np.any(mask):
            any_it = True
            steps = np.nonzero(mask)[0] + 1
            ax.plot(steps, it[mask], ".", ms=2, label="%s (mean %.2f, max %d)"
                    % (tag, it[mask].mean(), it[mask].max()))
    if any_it:
        ax.set_xlabel("step")
        ax.set_ylabel("nonlocal iterations")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(os.path.join(run_dir, "iterations.png"), dpi=130)
    plt.close(fig)
    newton_figure(run_dir, tags)
    return 0


def newton_figure(run_dir, tags):
    """newton.png from the cases' <tag>_newton.csv, when the run was implicit."""
    runs = [(t, os.path.join(run_dir, t + "_newton.csv")) for t in tags]
    runs = [(t, p) for t, p in runs if os.path.exists(p)]
    if not runs:
        return
    fig, (a, b) = plt.subplots(1, 2, figsize=(10.0, 3.8))
    c = b.twinx()
    for tag, path in runs:
        d = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
        step, t, dt, it, res = d[:, 0], d[:, 1], d[:, 2], d[:, 3], d[:, 4]
        for k in np.unique(step):
            m = step == k
            a.semilogy(it[m], np.maximum(res[m], 1e-17), "-", lw=0.5, alpha=0.5)
        last = np.r_[step[1:] != step[:-1], True]
        b.plot(t[last], it[last], ".", ms=3, label=tag + ": solves")
        c.semilogy(t[last], dt[last], "-", lw=0.8, label=tag + ": step size")
    a.set_xlabel("Newton solve")
    a.set_ylabel("residual / force scale")
    a.grid(alpha=0.3)
    b.set_xlabel("time (s)")
    b.set_ylabel("solves in the step")
    c.set_ylabel("step size (s)")
    b.grid(alpha=0.3)
    b.legend(fontsize=7, loc="upper left")
    c.legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    fig.savefig(os.path.join(run_dir, "newton.png"), dpi=130)
    plt.close(fig)


if __name__ == "__main__":
    matplotlib.use("Agg")
    sys.exit(main(sys.argv))
