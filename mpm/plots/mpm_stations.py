#!/usr/bin/env python3
"""Station histories of a wellposed-mpm run, like fig. 2.3-2.10.

usage: mpm_stations.py RUN.h5 OUT.png [--reference OTHER.h5 [LABEL]] [--make COMMAND]

Plots the axial stress increment sigma_xx - sigma_xx(0) (MPa, tension
positive) against time (ms) at every station, with the measured head and
tail of summary.txt (ticks at half the load peak) and grey guide lines,
each labelled with its speed, only where that speed applies:
  x/C_P   the ideal head (C_P from the run's metadata, the UMAT's loading
          modulus at the initial state; for an overlocal run, h_zeta /= 0,
          the local speed with h_eta + h_zeta, the low-frequency limit of its
          dispersion relation that its head runs at; docs/research/figures.md);
  x/C_E + tau  the ideal end of the pulse.
Neither is drawn where summary.txt beside RUN.h5 gives the ideal arrivals
as not_applicable (C_P < C_E: the plastic wave trails the elastic one, as
with the extended flow rule); the title says so.

A reference run (the deck's &output reference) is drawn dashed on the same
axes, station by station at the same x (the dissertation's convention).
When OTHER.h5 does not exist or cannot be read, the figure carries a note
saying so and the COMMAND that makes it, and the same line is printed: a
missing reference is never left out silently.
"""
import argparse
import math
import os
import sys

import h5py
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "common"))
from summary_text import read_summary  # noqa: E402

GUIDE = "0.6"          # grey of the guide lines
NA = "not_applicable"  # the summary's word for a figure that does not apply
# a head guide at C_P is drawn when the measured head speed is within this
# of it: 10 times the mesh's own error on the rate-independent wave (0.2 %,
# fig. 2.3 left: c_head / C_P = 0.998)
HEAD_APPLIES = 0.02


def text_attr(f, name):
    v = f.attrs[name]
    return v.decode() if isinstance(v, bytes) else str(v)


def load(path):
    """The run's station histories (ms, MPa increments) and its numbers."""
    with h5py.File(path, "r") as f:
        t = f["stations/time"][()] * 1e3
        x = f["stations/x"][()]
        s = f["stations/sigma_xx"][()]
        nums = dict(zip(text_attr(f, "numbers_names").split(), f.attrs["numbers"]))
        nums["props"] = list(f.attrs["props"]) if "props" in f.attrs else []
        nums["mass"] = text_attr(f, "mass") if "mass" in f.attrs else "lumped"
        nums["heads"] = f["measures/t_head"][()] * 1e3 if "measures/t_head" in f else None
        nums["tails"] = f["measures/t_tail"][()] * 1e3 if "measures/t_tail" in f else None
        title = text_attr(f, "title")
    ds = (s - s[:, :1]) / 1e6
    return t, x, ds, nums, title


def number(text):
    """The summary value `text` as a float, None when absent or not a number."""
    try:
        return float(text)
    except (TypeError, ValueError):
        return None


def uniaxial_plastic_speed(props, density, h):
    """C_P of a uniaxial-strain wave for the regular Drucker-Prager model in
    the case study's triaxial-compression state with slope h (the closed form
    of wellposed_tangent_analysis: uniaxial_modulus)."""
    k, g, beta, beta_p = props[0], props[1], props[2], props[3]
    r3 = math.sqrt(3.0)
    m = k + 4.0 * g / 3.0 - (3 * k * beta_p - 2 * g / r3) * (3 * k * beta - 2 * g / r3) / (
        g + 9 * k * beta * beta_p + h * math.sqrt(0.5 + 3 * beta_p ** 2))
    return math.sqrt(m / density) if m > 0 else float("nan")


def guides(nums, summary):
    """([(kind, speed, label)], [reasons a guide is not drawn]). kind is
    'head' (t = x/C) or 'end' (t = x/C + tau)."""
    c_e, c_p = nums["c_elastic"], nums["c_plastic"]
    ideal = summary.get("station_1_t_head_ideal")
    if ideal == NA or (ideal is None and not c_p > c_e):
        return [], ["no x/C_P, x/C_E + tau guides: C_P < C_E, the ideal arrivals do not apply "
                    "(summary: not_applicable)"]
    props = nums["props"]
    head = (c_p, f"x/C_P: ideal head, C_P = {c_p:.0f} m/s")
    skipped = []
    h_zeta = props[11] if len(props) > 12 else 0.0
    if h_zeta != 0.0 and props[12] > 0.0:
        # overlocal: the UMAT's local modulus has h_eta alone; the head runs at
        # the low-frequency speed, h_eta + h_zeta (docs/research/figures.md, fig. 2.10)
        local = uniaxial_plastic_speed(props, nums["density"], props[5])
        low = uniaxial_plastic_speed(props, nums["density"], props[5] + h_zeta)
        if abs(local - c_p) <= 1e-6 * c_p and math.isfinite(low):
            head = (low, f"x/C_P: ideal head, C_P(h_eta + h_zeta) = {low:.0f} m/s "
                         f"\n(overlocal, low frequency; h_eta alone: {c_p:.0f} m/s)")
        else:
            head = None
            skipped.append("no x/C_P guide: the overlocal low-frequency C_P has no closed "
                           "form for this model and state")
    elif len(props) > 10 and props[10] > 0.0:
        head = (c_p, f"x/C_P: ideal head, rate-independent\nC_P = {c_p:.0f} m/s (De -> 0)")
        ratio = number(summary.get("c_head_over_c_plastic"))
        if ratio is not None and abs(ratio - 1.0) > HEAD_APPLIES:
            # viscoplastic: the rate-independent C_P is the De -> 0 limit only
            head = None
            skipped.append(f"no x/C_P guide: the head runs at {ratio:.2f} C_P, the "
                           f"rate-independent C_P (De -> 0) does not apply at this De")
    out = [("head",) + head] if head else []
    out.append(("end", c_e, f"x/C_E + tau: ideal end, C_E = {c_e:.0f} m/s"))
    return out, skipped


def load_reference(path, label, make):
    """(data or None, note or None): the reference run, or why it is not drawn."""
    how = f"; make it with: {make}" if make else ""
    if not os.path.exists(path):
        return None, f"reference '{label}' not drawn: {path} has not been made yet{how}"
    try:
        return load(path), None
    except (OSError, KeyError, ValueError) as e:
        return None, f"reference '{label}' not drawn: {path} cannot be read ({e}){how}"


def draw(run, out, reference=None, label=None, make=None):
    """Draw RUN.h5's stations into OUT (PNG); returns (fig, ax, info) where
    info holds 'guides', 'skipped', 'reference_drawn' (stations drawn dashed)
    and 'note' (why the reference is not drawn, or None)."""
    t, x, ds, nums, title = load(run)
    summary = read_summary(os.path.dirname(os.path.abspath(run)))
    lines, skipped = guides(nums, summary)
    ref, note = (None, None)
    if reference:
        label = label or os.path.basename(os.path.dirname(os.path.abspath(reference)))
        ref, note = load_reference(reference, label, make)
    fig, ax = plt.subplots(figsize=(12.5, 5.2))
    tau = nums["load_duration"] * 1e3
    drawn = 0
    for i, xi in enumerate(x):
        line, = ax.plot(t, ds[i], lw=1.0, label=f"x = {xi:.0f} m")
        if ref is not None:
            rt, rx, rds = ref[0], ref[1], ref[2]
            match = [j for j, r in enumerate(rx) if abs(r - xi) <= 1e-6 * max(1.0, abs(xi))]
            if match:
                ax.plot(rt, rds[match[0]], "--", lw=0.8, color=line.get_color())
                drawn += 1
        if nums["heads"] is not None:
            half = 0.5 * nums["load_peak"] / 1e6
            ax.plot([nums["heads"][i], nums["tails"][i]], [half, half], "|",
                    color=line.get_color(), ms=8)
        for kind, c, text in lines:
            tt = xi / c * 1e3 + (tau if kind == "end" else 0.0)
            ax.axvline(tt, color=GUIDE, lw=0.6, ls="-" if kind == "head" else "-.", zorder=0,
                       label=text if i == 0 else None)
    if ref is not None and drawn == 0:
        note = f"reference '{label}' not drawn: it has no station at these x"
    if ref is not None and drawn:
        ax.plot([], [], "k--", lw=0.8, label=f"dashed: {label}")
    if note:
        ax.text(0.99, 0.02, note, transform=ax.transAxes, ha="right", va="bottom", fontsize=7.5,
                color="darkred", wrap=True,
                bbox=dict(boxstyle="round", fc="mistyrose", ec="darkred", alpha=0.9))
        print(f"mpm_stations.py: {note}", flush=True)
    ax.axhline(nums["load_peak"] / 1e6, color="0.5", lw=0.5, ls=":")
    ax.set_xlabel("time (ms)")
    ax.set_ylabel(r"$\sigma_{xx} - \sigma_{xx}^0$ (MPa, tension +)")
    sub = (f"dx = {nums['dx']:g} m, CFL {nums['cfl']:g}, {nums['mass']} mass; ticks: measured "
           f"head/tail at half the load peak")
    if ref is not None and drawn:
        sub += f"; dashed: {label}"
    for s in skipped:
        sub += "\n" + s
    ax.set_title(title + "\n" + sub, fontsize=9)
    hs, ls = ax.get_legend_handles_labels()
    order = sorted(range(len(ls)), key=lambda j: (not ls[j].startswith("x = "),
                                                 not ls[j].startswith("dashed"), j))
    # outside the axes: the peaks of figs. 2.7-2.10 fill the upper left corner
    ax.legend([hs[j] for j in order], [ls[j] for j in order], fontsize=7.5, loc="upper left",
              bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    return fig, ax, {"guides": lines, "skipped": skipped, "reference_drawn": drawn, "note": note}


def main(argv):
    p = argparse.ArgumentParser(prog="mpm_stations.py", description=__doc__.split("\n")[0])
    p.add_argument("run", metavar="RUN.h5")
    p.add_argument("out", metavar="OUT.png")
    p.add_argument("--reference", nargs="+", metavar="OTHER.h5 [LABEL]")
    p.add_argument("--make", metavar="COMMAND")
    a = p.parse_args(argv[1:])
    reference, label = (a.reference + [None])[:2] if a.reference else (None, None)
    if a.reference and len(a.reference) > 2:
        p.error("--reference takes OTHER.h5 and at most one LABEL")
    fig, _, _ = draw(a.run, a.out, reference, label, a.make)
    plt.close(fig)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
