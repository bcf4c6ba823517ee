#!/usr/bin/env python3
"""Plots of a wellposed-point run: reads RUN_DIR/results.h5, writes PNGs there.

usage: plot_point.py RUN_DIR

Writes, for what the run holds:
  path.png      stress paths (Lode plane) and sigma_11 against eps_11
  plastic.png   plastic volume change tr(eps^p) against eps_11, when a path is plastic
  rtheta.png    directional stiffness ratio R(theta), eq. 2.5 (fig. 2.4, 2.5, 2.8 left)
  acoustic.png  smallest eigenvalue of sym(n.T.n) against the normal's angle to axis 1
  gudehus.png   strain-response envelopes, tail to tail (fig. 3.2)
  chapter3.png  envelopes of the virtual experiment with the best fits (fig. 3.4)
Lode components are compression positive (chapter 3): z hydrostatic, r deviatoric.
Run by wellposed-point with matplotlib's Agg backend (python3-matplotlib, python3-h5py).
"""
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import h5py  # noqa: E402
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "common"))
from summary_text import read_summary  # noqa: E402

plt.rcParams.update({"font.size": 11, "axes.grid": True, "grid.alpha": 0.3,
                     "figure.dpi": 110, "savefig.bbox": "tight"})


def lode(v):
    """Compression-positive axisymmetric Lode components of Abaqus-order rows."""
    z = -(v[:, 0] + v[:, 1] + v[:, 2]) / np.sqrt(3.0)
    r = -np.sqrt(2.0 / 3.0) * (v[:, 0] - 0.5 * (v[:, 1] + v[:, 2]))
    return z, r


def title(f):
    name = os.path.basename(os.path.normpath(RUN)).replace(".partial", "")
    return f"{name}  (wellposed {f.attrs['version'].decode().strip()})"


def plot_path(f, labels):
    rows = [l for l in labels if "path" in f[l] and f[l]["path/time"].shape[0] > 1]
    if not rows:
        return
    fig, ax = plt.subplots(1, 2, figsize=(12, 5))
    for l in rows:
        s = f[l]["path/stress"][:]
        e = f[l]["path/strain"][:]
        z, r = lode(s)
        ax[0].plot(z / 1e6, r / 1e6, "-o", ms=2, label=l)
        ax[1].plot(e[:, 0], s[:, 0] / 1e6, "-", label=l)
    ax[0].set_xlabel(r"$\sigma_z = -\mathrm{tr}\,\sigma/\sqrt{3}$ [MPa, deck unit/1e6]")
    ax[0].set_ylabel(r"$\sigma_r$ [MPa]")
    ax[0].set_title("stress path in the Lode plane")
    ax[1].set_xlabel(r"$\varepsilon_{11}$")
    ax[1].set_ylabel(r"$\sigma_{11}$ [MPa]")
    ax[1].set_title("axial stress against axial strain")
    for a in ax:
        a.legend()
    fig.suptitle(title(f))
    fig.savefig(os.path.join(RUN, "path.png"))
    plt.close(fig)


def plot_plastic(f, labels):
    """tr(eps^p) against eps_11 for every material whose path is plastic."""
    rows = []
    for l in labels:
        if "path/plastic_strain" not in f[l]:
            continue
        ep = f[l]["path/plastic_strain"][:]
        e = f[l]["path/strain"][:]
        norm = np.sqrt((ep[-1, :3] ** 2).sum() + 0.5 * (ep[-1, 3:] ** 2).sum())
        if norm > 1e-6 * max(np.abs(e[-1] - e[0]).max(), 1e-300):
            rows.append((l, e[:, 0], ep[:, :3].sum(axis=1), ep[-1, :3].sum() / norm))
    if not rows:
        return
    fig, ax = plt.subplots(figsize=(7.5, 5))
    for l, e11, tr, ratio in rows:
        ax.plot(e11, tr, "-", lw=1.6, label=rf"{l}: tr/$\|\varepsilon^p\|$ = {ratio:.4f}")
    ax.set_xlabel(r"$\varepsilon_{11}$")
    ax.set_ylabel(r"$\mathrm{tr}\,\varepsilon^p$ (> 0: dilation)")
    ax.ticklabel_format(style="sci", scilimits=(-3, 3))
    ax.set_title("plastic volume change along the path")
    ax.legend(fontsize=8)
    fig.suptitle(title(f))
    fig.savefig(os.path.join(RUN, "plastic.png"))
    plt.close(fig)


def plot_rtheta(f, labels):
    rows = [l for l in labels if "rtheta" in f[l]]
    if not rows:
        return
    fig = plt.figure(figsize=(13, 5.5))
    ax = fig.add_subplot(1, 2, 1)
    axp = fig.add_subplot(1, 2, 2, projection="polar")
    lo, hi = 0.0, 1.0
    for l in rows:
        th = f[l]["rtheta/theta_deg"][:]
        r = f[l]["rtheta/r"][:]
        lo, hi = min(lo, r.min()), max(hi, r.max())
        i, j = np.argmax(r), np.argmin(r)
        line, = ax.plot(th, r, lw=2,
                        label=f"{l}: R in [{r[j]:.4f}, {r[i]:.4f}]")
        ax.plot([th[i]], [r[i]], "^", color=line.get_color())
        ax.plot([th[j]], [r[j]], "v", color=line.get_color())
        thc = np.append(th, th[0] + 360.0)
        rc = np.append(r, r[0])
        axp.plot(np.radians(thc), rc - lo + 0.1, color=line.get_color(), lw=2, label=l)
    ax.axhspan(1.0, max(hi, 1.0) + 0.1, color="tab:red", alpha=0.08)
    ax.axhspan(min(lo, 0.0) - 0.1, 0.0, color="tab:blue", alpha=0.08)
    ax.axhline(1.0, color="tab:red", lw=1, ls="--")
    ax.axhline(0.0, color="tab:blue", lw=1, ls="--")
    ax.text(2, 1.02, "R > 1: plastic stiffer than elastic (Sandler-Rubin)", color="tab:red",
            fontsize=9, va="bottom")
    ax.text(2, -0.02, "R < 0: softening-like (localization)", color="tab:blue", fontsize=9,
            va="top")
    ax.set_xlim(0, 360)
    ax.set_xticks(range(0, 361, 45))
    ax.set_ylim(min(lo, 0.0) - 0.1, max(hi, 1.0) + 0.1)
    ax.set_xlabel(r"loading angle $\theta$ [deg] (0: tangent to the yield surface, "
                  r"compressive; 90: along $N$)", fontsize=9)
    ax.set_ylabel(r"$R = \dot\varepsilon:\mathbb{T}:\dot\varepsilon\,/\,"
                  r"\dot\varepsilon:\mathbb{C}:\dot\varepsilon$")
    ax.set_title("directional stiffness ratio (eq. 2.5)")
    ax.legend(loc="lower left", fontsize=9)
    axp.set_title(f"polar view: radius R - ({lo:.2f}) + 0.1", fontsize=10)
    axp.set_theta_zero_location("E")
    for rr in (0.0, 1.0):
        t = np.linspace(0, 2 * np.pi, 200)
        axp.plot(t, np.full_like(t, rr - lo + 0.1), "--", lw=1,
                 color="tab:blue" if rr == 0.0 else "tab:red")
    axp.set_yticklabels([])
    fig.suptitle(title(f), y=1.02)
    fig.savefig(os.path.join(RUN, "rtheta.png"))
    plt.close(fig)


def plot_acoustic(f, labels):
    rows = [l for l in labels if "acoustic" in f[l]]
    if not rows:
        return
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for l in rows:
        pol = f[l]["acoustic/polar_deg"][:]
        m = f[l]["acoustic/min_eig"][:]
        ax.plot(pol, m.min(axis=1) / 1e9, lw=2, label=l)
    ax.axhline(0.0, color="k", lw=1)
    ax.set_xlabel("angle between the normal n and axis 1 [deg]")
    ax.set_ylabel(r"min eigenvalue of sym($n\cdot\mathbb{T}\cdot n$) [GPa]")
    ax.set_title("acoustic tensor (eq. 1.7): <= 0 is loss of ellipticity")
    ax.legend()
    fig.suptitle(title(f), fontsize=10)
    fig.savefig(os.path.join(RUN, "acoustic.png"))
    plt.close(fig)


def ellipse(lmat, n=361, half=None):
    t = np.radians(np.linspace(0, 360, n))
    if half is not None:
        t = np.radians(np.linspace(half[0], half[1], n))
    c = np.vstack([np.cos(t), np.sin(t)])
    return lmat @ c


def plot_gudehus(f, labels):
    rows = [l for l in labels if "gudehus" in f[l]]
    if not rows:
        return
    fig, ax = plt.subplots(1, len(rows) + 1, figsize=(5.2 * (len(rows) + 1), 5))
    ds = f[rows[0]]["gudehus/dsig"][:]
    ax[0].plot(np.append(ds[:, 0], ds[0, 0]) / 1e6, np.append(ds[:, 1], ds[0, 1]) / 1e6, "-k")
    for v in ds[::max(1, len(ds) // 12)]:
        ax[0].annotate("", xy=(v[0] / 1e6, v[1] / 1e6), xytext=(0, 0),
                       arrowprops=dict(arrowstyle="->", color="0.5"))
    ax[0].set_aspect("equal")
    ax[0].set_title("stress increments (equal size)")
    ax[0].set_xlabel(r"$d\sigma_z$ [MPa] (hydrostatic compression)")
    ax[0].set_ylabel(r"$d\sigma_r$ [MPa]")
    for a, l in zip(ax[1:], rows):
        de = f[l]["gudehus/deps"][:]
        dp = f[l]["gudehus/deps_plastic"][:]
        a.plot(np.append(de[:, 0], de[0, 0]), np.append(de[:, 1], de[0, 1]), "-o", ms=3,
               label="total strain")
        a.plot(dp[:, 0], dp[:, 1], "x", color="tab:red", label="plastic strain")
        a.plot([0], [0], "k+", ms=12)
        a.set_aspect("equal", adjustable="datalim")
        a.set_title(f"{l}: strain response envelope")
        a.set_xlabel(r"$d\varepsilon_z$")
        a.set_ylabel(r"$d\varepsilon_r$")
        a.ticklabel_format(style="sci", scilimits=(-3, 3))
        a.legend(fontsize=9)
    fig.suptitle(title(f) + "  - Gudehus diagram (fig. 3.2)", y=1.03)
    fig.savefig(os.path.join(RUN, "gudehus.png"))
    plt.close(fig)


# Fit residual ||R - L S||/||R|| above which chapter3.png warns that the
# fitted M and N are not the response's directions. The best bilinear fit
# then misses the strain increments by more than a tenth of their size, so
# each fitted direction can be off by up to about asin(0.1) = 5.7 deg and
# their difference by 11.5 deg, half the smallest M-N difference of the
# dissertation's table 3.2 (20 deg) on which its conclusion rests. A
# classical (incrementally bilinear) model fits to round-off (1e-13).
RESIDUAL_WARN = 0.1
LABEL_OFFSETS = [(4, 4), (4, 4), (4, 4), (-12, -12)]  # D away from A (near them in fig. 3.4)
PRIMED_OFFSETS = [(5, 5), (5, -12), (-16, 5), (-16, -12)]  # A'-D' gather near the origin


def fit_note(summary, label):
    """(text, warn) for the panel of `label`: angles' fit residual and rank
    ratio from summary.txt, and whether the residual exceeds RESIDUAL_WARN."""
    res = summary.get(f"{label}.chapter3.residual")
    rank = summary.get(f"{label}.chapter3.rank_ratio")
    if res is None:
        return "fit residual: not in summary.txt", False
    r = float(res)
    text = f"fit residual ||R - L S||/||R|| = {r:.2g}"
    if rank is not None:
        text += f", rank ratio {float(rank):.2g}"
    if r > RESIDUAL_WARN:
        text += (f"\nWARNING: residual > {RESIDUAL_WARN:g}: the response is not incrementally "
                 "bilinear;\nM and N are a best fit (eq. 3.19-3.23), each uncertain by up to "
                 f"~{np.degrees(np.arcsin(min(r, 1.0))):.0f} deg")
    return text, r > RESIDUAL_WARN


def arrow_label(a, tip, text, color, side):
    """`text` at the arrow tip, pushed sideways (side = +1 or -1, across the
    arrow) so that two arrows a few degrees apart keep their labels apart."""
    u = tip / max(np.linalg.norm(tip), 1e-300)
    off = 14 * side * np.array([-u[1], u[0]]) + 6 * u
    a.annotate(text, tip, textcoords="offset points", xytext=off, color=color, fontsize=10,
               ha="left" if off[0] >= 0 else "right", va="bottom" if off[1] >= 0 else "top",
               bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.8))


def plot_chapter3(f, labels):
    rows = [l for l in labels if "chapter3" in f[l]]
    if not rows:
        return None
    summary = read_summary(RUN)
    fig, ax = plt.subplots(1, len(rows), figsize=(6.5 * len(rows), 6.6), squeeze=False)
    names = ["A", "B", "C", "D", "A'", "B'", "C'", "D'"]
    warned = []
    for a, l in zip(ax[0], rows):
        g = f[l]["chapter3"]
        s, r, rp = g["s"][:], g["r"][:], g["rp"][:]
        lm, le = g["l"][:], g["l_el"][:]
        m, n = g["m"][:], g["n"][:]
        mag = np.linalg.norm(s[:, 0])
        e_pl = ellipse(lm * mag)
        e_el = ellipse(le * mag)
        a.plot(e_pl[0], e_pl[1], "-", color="tab:orange", lw=1.5,
               label="best-fit plastic tangent (legs A-D)")
        a.plot(e_el[0], e_el[1], "-", color="tab:green", lw=1.5,
               label="best-fit elastic tangent (reverses)")
        a.plot(r[0], r[1], "o", color="k", label="total strain increments")
        a.plot(rp[0], rp[1], "x", color="tab:red", ms=8, label="plastic strain increments")
        for k in range(8):
            a.annotate(names[k], (r[0, k], r[1, k]), textcoords="offset points",
                       xytext=LABEL_OFFSETS[k] if k < 4 else PRIMED_OFFSETS[k - 4],
                       fontsize=9 if k < 4 else 7.5, color="k" if k < 4 else "0.35")
        scale = 0.6 * np.abs(np.hstack([r, e_pl])).max()
        th_m = np.degrees(np.arctan2(m[1], m[0])) % 360
        th_n = np.degrees(np.arctan2(n[1], n[0])) % 360
        a.annotate("", xy=scale * m, xytext=(0, 0),
                   arrowprops=dict(arrowstyle="->", color="tab:purple", lw=2))
        a.annotate("", xy=scale * n, xytext=(0, 0),
                   arrowprops=dict(arrowstyle="->", color="tab:blue", lw=2))
        # the arrow turned further counter-clockwise gets its label on that side
        ccw = ((th_m - th_n + 180.0) % 360.0 - 180.0) >= 0.0
        arrow_label(a, scale * m, rf"$\hat M$: {th_m:.1f}$^\circ$", "tab:purple",
                    1 if ccw else -1)
        arrow_label(a, scale * n, rf"$\hat N$: {th_n:.1f}$^\circ$", "tab:blue",
                    -1 if ccw else 1)
        a.plot([0], [0], "k+", ms=12)
        a.set_aspect("equal", adjustable="datalim")
        a.set_xlabel(r"$d\varepsilon_z$ (hydrostatic compression)")
        a.set_ylabel(r"$d\varepsilon_r$")
        a.ticklabel_format(style="sci", scilimits=(-3, 3))
        a.set_title(f"{l}: response envelope (fig. 3.4)")
        a.legend(fontsize=8, loc="lower left")
        text, warn = fit_note(summary, l)
        a.text(0.02, 0.98, text, transform=a.transAxes, ha="left", va="top", fontsize=8,
               color="darkred" if warn else "k",
               bbox=dict(boxstyle="round", fc="mistyrose" if warn else "white",
                         ec="darkred" if warn else "0.6", alpha=0.9))
        if warn:
            warned.append(l)
    fig.suptitle(title(f) + "  - angles from the hydrostatic compression axis (table 3.2)", y=1.02)
    fig.savefig(os.path.join(RUN, "chapter3.png"))
    plt.close(fig)
    return warned


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    RUN = sys.argv[1]
    path = os.path.join(RUN, "results.h5")
    if not os.path.exists(path):
        sys.exit(f"plot_point.py: {path} not found")
    with h5py.File(path, "r") as f:
        labels = [k for k in f.keys() if isinstance(f[k], h5py.Group)]
        plot_path(f, labels)
        plot_plastic(f, labels)
        plot_rtheta(f, labels)
        plot_acoustic(f, labels)
        plot_gudehus(f, labels)
        plot_chapter3(f, labels)
