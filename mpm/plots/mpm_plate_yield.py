"""Where an ELASTIC plate would first yield: the clamped platen's corners or the weak zone.

usage: mpm_plate_yield.py RUN_DIR [T]

RUN_DIR is a wellposed-mpm plate run of an elastic plate (a yield strength
no particle reaches) with particle snapshots (&output snapshot_dt), e.g.
inputs/fig4_2_elastic_corner.nml. For every case (mesh h), from each
snapshot's sigma_xx, sigma_yy, sigma_xy (plane strain, elastic:
sigma_zz = nu (sigma_xx + sigma_yy), K and G from run.h5's props) the
ratio r = sqrt(J2)/k of
  - the corner particle: the one nearest each top corner of the deformable
    body, (0, H - h) and (W, H - h) (the platen holds the node row at
    y = H - h and above: docs/research/bands.md, "The platen"), k = K_STRONG;
  - the weak zone: the largest over its particles (x < WEAK_X, y < WEAK_Y
    initially), k = K_WEAK;
  - mid-height: the mean over the particle row(s) nearest y = H/2;
  - the row under the platen, middle: the mean over the particles of the
    cell row under the platen's layer (H - 2h <= y < H - h initially) in
    the middle third of the width, against which the corner particle shows
    whether the platen layer loads the row's ends more than its middle (a
    platen with friction would);
and prints one markdown row per case: r at time T (default 4 ms), corner
over weak, and the time at which each first reaches r = 1 (linear between
snapshots): where the plastic plate's first yield is predicted to be
(docs/research/bands.md, "The clamped corner yields first").
"""
import os
import sys

import h5py
import numpy as np

K_STRONG, K_WEAK = 400e6, 375e6      # Pa: fig. 4.1 (section 4.7)
WEAK_X, WEAK_Y = 1.0, 1.0            # m: the weak zone [0, 1] x [0, 1]


def sqrt_j2(snap, nu):
    sx, sy, sxy = snap["sigma_xx"][()], snap["sigma_yy"][()], snap["sigma_xy"][()]
    sz = nu * (sx + sy)
    p = (sx + sy + sz) / 3.0
    return np.sqrt(0.5 * ((sx - p) ** 2 + (sy - p) ** 2 + (sz - p) ** 2) + sxy ** 2)


def first_reach(ts, rs):
    """The time r first reaches 1, linear between samples (None: never)."""
    for i in range(1, len(ts)):
        if rs[i] >= 1.0 > rs[i - 1]:
            return ts[i - 1] + (1.0 - rs[i - 1]) / (rs[i] - rs[i - 1]) * (ts[i] - ts[i - 1])
    return None


def case_yield(group, h, nu, t_at):
    """The case's ratios at t_at and the times each reaches yield."""
    names = sorted([s for s in group if s.startswith("snap_")],
                   key=lambda s: float(group[s]["time"][0]))
    xy0 = group[names[0]]["xy"][()]
    width = float(np.max(xy0[:, 0]) + np.min(xy0[:, 0]))
    height = float(np.max(xy0[:, 1]) + np.min(xy0[:, 1]))
    weak = (xy0[:, 0] < WEAK_X) & (xy0[:, 1] < WEAK_Y)
    k = np.where(weak, K_WEAK, K_STRONG)
    below = xy0[:, 1] < height - h
    corners = [int(np.argmin(np.where(below, np.hypot(xy0[:, 0] - x, xy0[:, 1] - (height - h)),
                                      np.inf))) for x in (0.0, width)]
    mid = np.abs(xy0[:, 1] - 0.5 * height) < 0.5 * h
    row = ((xy0[:, 1] >= height - 2.0 * h) & below & (np.abs(xy0[:, 0] - 0.5 * width)
                                                     < width / 6.0))
    ts, rc, rw, rm, rr = [], [], [], [], []
    for s in names:
        r = sqrt_j2(group[s], nu) / k
        ts.append(float(group[s]["time"][0]))
        rc.append(max(r[i] for i in corners))
        rw.append(float(np.max(r[weak])))
        rm.append(float(np.mean(r[mid])))
        rr.append(float(np.mean(r[row])))
    j = int(np.argmin(np.abs(np.array(ts) - t_at)))
    return {"h": h, "t": ts[j], "corner": rc[j], "weak": rw[j], "mid": rm[j], "row": rr[j],
            "distance": float(np.hypot(xy0[corners[1], 0] - width,
                                       xy0[corners[1], 1] - (height - h))),
            "t_corner": first_reach(ts, rc), "t_weak": first_reach(ts, rw)}


def yield_table(run_dir, t_at=4.0e-3):
    """One dict per case (coarsest first)."""
    with h5py.File(os.path.join(run_dir, "run.h5"), "r") as f:
        kk, gg = float(f.attrs["props"][0]), float(f.attrs["props"][1])
        lam = kk - 2.0 * gg / 3.0
        nu = lam / (2.0 * (lam + gg))
        tags = sorted(f["cases"], key=lambda s: -float(s[1:]))
        return [case_yield(f["cases"][t], float(t[1:]), nu, t_at) for t in tags]


def main(argv):
    t_at = float(argv[2]) if len(argv) > 2 else 4.0e-3
    ms = lambda v: "never" if v is None else "%.2f" % (1e3 * v)
    print("| h (m) | corner particle's distance (m) | sqrt(J2)/k at %.2f ms: corner, weak max, "
          "mid-height, row under the platen (middle) | corner / weak | yield reached (ms): "
          "corner, weak |" % (1e3 * t_at))
    print("|---|---|---|---|---|")
    for c in yield_table(argv[1], t_at):
        print("| %g | %.3f | %.3f, %.3f, %.3f, %.3f | %.2f | %s, %s |" % (
            c["h"], c["distance"], c["corner"], c["weak"], c["mid"], c["row"],
            c["corner"] / c["weak"], ms(c["t_corner"]), ms(c["t_weak"])))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
