#!/usr/bin/env python3
"""Plots of a wellposed-point run: reads RUN_DIR/results.h5, writes PNGs there.

usage: plot_point.py RUN_DIR

Writes, for what the run holds:
  path.png      stress paths (Lode plane) and sigma_11 against eps_11
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


def plot_chapter3(f, labels):
    rows = [l for l in labels if "chapter3" in f[l]]
    if not rows:
        return
    fig, ax = plt.subplots(1, len(rows), figsize=(6.5 * len(rows), 6), squeeze=False)
    names = ["A", "B", "C", "D", "A'", "B'", "C'", "D'"]
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
                       xytext=(4, 4), fontsize=9)
        scale = 0.6 * np.abs(np.hstack([r, e_pl])).max()
        th_m = np.degrees(np.arctan2(m[1], m[0])) % 360
        th_n = np.degrees(np.arctan2(n[1], n[0])) % 360
        a.annotate("", xy=scale * m, xytext=(0, 0),
                   arrowprops=dict(arrowstyle="->", color="tab:purple", lw=2))
        a.annotate("", xy=scale * n, xytext=(0, 0),
                   arrowprops=dict(arrowstyle="->", color="tab:blue", lw=2))
        a.text(*(scale * m), rf" $\hat M$: {th_m:.1f}$^\circ$", color="tab:purple")
        a.text(*(scale * n), rf" $\hat N$: {th_n:.1f}$^\circ$", color="tab:blue")
        a.plot([0], [0], "k+", ms=12)
        a.set_aspect("equal", adjustable="datalim")
        a.set_xlabel(r"$d\varepsilon_z$ (hydrostatic compression)")
        a.set_ylabel(r"$d\varepsilon_r$")
        a.ticklabel_format(style="sci", scilimits=(-3, 3))
        a.set_title(f"{l}: response envelope (fig. 3.4)")
        a.legend(fontsize=8, loc="lower left")
    fig.suptitle(title(f) + "  - angles from the hydrostatic compression axis (table 3.2)", y=1.02)
    fig.savefig(os.path.join(RUN, "chapter3.png"))
    plt.close(fig)


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
        plot_rtheta(f, labels)
        plot_acoustic(f, labels)
        plot_gudehus(f, labels)
        plot_chapter3(f, labels)
