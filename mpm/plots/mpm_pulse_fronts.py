#!/usr/bin/env python3
"""Fronts of a pulse with a secondary rise, per station (fig. 2.10 right).

usage: mpm_pulse_fronts.py RUN [RUN ...] [--threshold PA] [--markdown FILE]

RUN is a run folder of wellposed-mpm (its run.h5). For every station of
every run, with s(t) = sigma_xx(t) - sigma_xx(0) (tension positive):

  head       last upward crossing of the threshold (default: half the load
             peak) before the station peak (the summary's t_head)
  plateau    s at head + 2 ms: the level of the primary pulse
  secondary  when the peak exceeds 1.5 x plateau, the time of the largest
             ds/dt between head + 2 ms and the peak: the front of the
             secondary pulse; else none
  peak       max s, and its time
  tail       first downward crossing of the threshold after the peak
  min after  the smallest s after the peak (to the end of the record)
  drop       how long after the peak s first falls below a fifth of the load
             peak (a dispersed tail that stays above it: none)

and per run the speeds of the head, secondary and tail fronts (least squares
of x against t over the stations that have the front). With two runs or
more, every run after the first is compared with the first: the delays of
its head and secondary fronts and its peak ratio per station. Prints
markdown tables (and writes them to FILE with --markdown).
"""
import os
import sys

PLATEAU_DELAY = 2.0e-3  # s after the head: the primary pulse's level
SECONDARY_RATIO = 1.5   # peak over plateau above which a secondary pulse counts


def crossing(t, s, level, i0, i1, upward):
    """Linearly interpolated crossing time of `level` in samples i0..i1."""
    for i in range(i0, i1):
        a, b = s[i], s[i + 1]
        if (upward and a < level <= b) or (not upward and a > level >= b):
            return t[i] + (level - a) / (b - a) * (t[i + 1] - t[i])
    return float("nan")


def fronts(folder, threshold=None):
    import h5py
    import numpy as np
    with h5py.File(os.path.join(folder, "run.h5"), "r") as f:
        t = np.asarray(f["stations/time"][()])
        sig = np.asarray(f["stations/sigma_xx"][()])
        xs = np.asarray(f["stations/x"][()])
        names = f.attrs["numbers_names"]
        if isinstance(names, bytes):
            names = names.decode()
        nums = dict(zip(names.split(), f.attrs["numbers"]))
    if threshold is None:
        threshold = 0.5 * abs(nums.get("load_peak", 10.0e6))
    rows = []
    for x, s in zip(xs, sig):
        s = s - s[0]
        k = int(np.argmax(s))
        head = float("nan")
        for i in range(k - 1, -1, -1):
            if s[i] < threshold <= s[i + 1]:
                head = crossing(t, s, threshold, i, i + 1, True)
                break
        tail = crossing(t, s, threshold, k, len(t) - 1, False)
        plateau = float(np.interp(head + PLATEAU_DELAY, t, s))
        second = float("nan")
        if s[k] > SECONDARY_RATIO * plateau:
            j0 = int(np.searchsorted(t, head + PLATEAU_DELAY))
            if j0 < k:
                rate = np.gradient(s[j0:k + 1], t[j0:k + 1])
                second = float(t[j0 + int(np.argmax(rate))])
        low = crossing(t, s, 0.4 * threshold, k, len(t) - 1, False)
        rows.append(dict(x=float(x), head=head, plateau=plateau, second=second,
                         peak=float(s[k]), t_peak=float(t[k]), tail=tail,
                         min_after=float(s[k:].min()), drop=low - float(t[k])))
    return rows


def speed(rows, key):
    """Least-squares slope of x against t over the stations with the front."""
    pts = [(r[key], r["x"]) for r in rows if r[key] == r[key]]
    if len(pts) < 2:
        return float("nan")
    n = len(pts)
    mt = sum(p[0] for p in pts) / n
    mx = sum(p[1] for p in pts) / n
    stt = sum((p[0] - mt) ** 2 for p in pts)
    return sum((p[0] - mt) * (p[1] - mx) for p in pts) / stt


def fmt(v, scale=1.0, digits=2):
    return "-" if v != v else f"{v * scale:.{digits}f}"


def main(argv):
    runs, threshold, md = [], None, None
    k = 1
    while k < len(argv):
        if argv[k] in ("--threshold", "--markdown"):
            if k + 1 >= len(argv):
                sys.stderr.write(f"mpm_pulse_fronts: {argv[k]} needs a value\n")
                return 2
            if argv[k] == "--threshold":
                threshold = float(argv[k + 1])
            else:
                md = argv[k + 1]
            k += 2
        elif argv[k].startswith("-"):
            sys.stderr.write(f"mpm_pulse_fronts: unknown option {argv[k]}\n{__doc__}")
            return 2
        else:
            runs.append(argv[k])
            k += 1
    if not runs:
        sys.stderr.write(__doc__)
        return 2
    for r in runs:
        if not os.path.isfile(os.path.join(r, "run.h5")):
            sys.stderr.write(f"mpm_pulse_fronts: no run.h5 in {r}\n")
            return 1
    out = []
    table = {r: fronts(r, threshold) for r in runs}
    for r in runs:
        rows = table[r]
        out.append(f"### {os.path.basename(os.path.normpath(r))}\n")
        out.append("| x (m) | head (ms) | plateau (MPa) | secondary front (ms) | peak (MPa) "
                   "| t_peak (ms) | tail (ms) | min after peak (MPa) | drop (ms) |")
        out.append("|---|---|---|---|---|---|---|---|---|")
        for w in rows:
            out.append(f"| {w['x']:g} | {fmt(w['head'], 1e3)} | {fmt(w['plateau'], 1e-6)} | "
                       f"{fmt(w['second'], 1e3)} | {fmt(w['peak'], 1e-6)} | "
                       f"{fmt(w['t_peak'], 1e3)} | {fmt(w['tail'], 1e3)} | "
                       f"{fmt(w['min_after'], 1e-6)} | {fmt(w['drop'], 1e3)} |")
        out.append("")
        out.append(f"speeds (m/s): head {fmt(speed(rows, 'head'), 1, 0)}, secondary front "
                   f"{fmt(speed(rows, 'second'), 1, 0)}, tail {fmt(speed(rows, 'tail'), 1, 0)}\n")
    base = runs[0]
    for r in runs[1:]:
        out.append(f"### {os.path.basename(os.path.normpath(r))} against "
                   f"{os.path.basename(os.path.normpath(base))}\n")
        out.append("| x (m) | head delay (ms) | secondary delay (ms) | peak ratio |")
        out.append("|---|---|---|---|")
        for a, b in zip(table[base], table[r]):
            out.append(f"| {a['x']:g} | {fmt(b['head'] - a['head'], 1e3, 3)} | "
                       f"{fmt(b['second'] - a['second'], 1e3, 3)} | "
                       f"{fmt(b['peak'] / a['peak'], 1, 3)} |")
        out.append("")
    text = "\n".join(out)
    print(text)
    if md:
        with open(md, "w") as f:
            f.write(text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
