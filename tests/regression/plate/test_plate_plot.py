#!/usr/bin/env python3
"""What mpm/plots/mpm_plate.py draws (fig. 4.2, 4.4), on a synthetic run.

test_plate_plot.py              the unit tests below (python unittest)
test_plate_plot.py --run DIR    checks a finished plate run: every case with a
                                band stage has a snapshot at that stage (the
                                panels are drawn there) and plastic_strain.png
                                exists

The contour panels: each case at its band stage (summary band_stage_time),
one colour scale for all panels (0 to the largest ||eps^p|| of the panels),
the fitted centre line and the lines FWHM/2 either side of it (normal
distance) marked.
"""
import os
import sys
import tempfile
import unittest

import h5py
import matplotlib
import numpy as np

matplotlib.use("Agg")
HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "mpm", "plots"))
import mpm_plate  # noqa: E402

# two cases: (tag, dx, stage time, peak ||eps^p|| at the stage, x0, slope, FWHM)
CASES = [("h0.5", 0.5, 6.9e-3, 0.02, 1.0, 0.5, 1.4),
         ("h0.25", 0.25, 6.8e-3, 0.05, 1.2, 0.4, 0.6)]
TIMES = [0.0, 2.5e-3, 5.0e-3, 6.85e-3, 7.5e-3]


def write_run(folder):
    """run.h5 with a Gaussian band x = x0 + slope y per case, and summary.txt."""
    lines = []
    with h5py.File(os.path.join(folder, "run.h5"), "w") as f:
        for tag, dx, t_stage, peak, x0, slope, fwhm in CASES:
            s = dx / 2
            xs, ys = np.meshgrid(np.arange(s / 2, 4.0, s), np.arange(s / 2, 5.0, s))
            xy = np.column_stack([xs.ravel(), ys.ravel()])
            dist = (xy[:, 0] - x0 - slope * xy[:, 1]) / np.sqrt(1 + slope ** 2)
            band = np.exp(-4 * np.log(2) * (dist / fwhm) ** 2)
            for i, t in enumerate(TIMES):
                g = f.create_group("cases/%s/snap_%d" % (tag, i + 1))
                g["time"] = np.array([t])
                g["xy"] = xy
                # growing in time: the stage snapshot (nearest t_stage) holds `peak`
                g["plastic_strain"] = peak * band * t / t_stage
            f["cases/%s/curve" % tag] = np.zeros((3, 3))
            f["cases/%s/iterations" % tag] = np.zeros(3, dtype=int)
            f["cases/%s/n_plastic" % tag] = np.zeros(3, dtype=int)
            lines += ["%s.band_stage_time = %r  # s" % (tag, t_stage),
                      "%s.band_fwhm_normal = %r  # m" % (tag, fwhm),
                      "%s.band_angle_deg = %r" % (tag, np.degrees(np.arctan2(1.0, slope))),
                      "%s.band_line_x0 = %r" % (tag, x0),
                      "%s.band_line_slope = %r" % (tag, slope)]
    with open(os.path.join(folder, "summary.txt"), "w") as f:
        f.write("\n".join(lines) + "\n")


class Panels(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        write_run(self.tmp.name)
        self.h5 = h5py.File(os.path.join(self.tmp.name, "run.h5"), "r")
        self.sm = mpm_plate.read_summary(self.tmp.name)
        self.fig, self.levels = mpm_plate.contour_figure(self.h5["cases"], self.sm,
                                                         [c[0] for c in CASES])
        self.axes = self.fig.axes[:len(CASES)]

    def tearDown(self):
        matplotlib.pyplot.close(self.fig)
        self.h5.close()
        self.tmp.cleanup()

    def test_each_panel_at_its_stage(self):
        for ax, (tag, _, t_stage, *_rest) in zip(self.axes, CASES):
            near = min(TIMES, key=lambda t: abs(t - t_stage))
            self.assertIn("t = %.2f ms" % (1e3 * near), ax.get_title())
            self.assertIn("stage %.2f ms" % (1e3 * t_stage), ax.get_title())

    def test_one_colour_scale_up_to_the_largest_value(self):
        levels = list(self.levels.values())
        self.assertEqual(len(levels), len(CASES))
        largest = 0.0
        for tag, _, t_stage, *_rest in CASES:
            i = min(range(len(TIMES)), key=lambda k: abs(TIMES[k] - t_stage))
            snap = self.h5["cases/%s/snap_%d" % (tag, i + 1)]
            largest = max(largest, float(np.max(snap["plastic_strain"][()])))
        for lv in levels:
            np.testing.assert_allclose(lv, levels[0])
            self.assertAlmostEqual(lv[0], 0.0)
            self.assertAlmostEqual(lv[-1], largest, delta=1e-12)

    def test_width_marked_normal_to_the_line(self):
        for ax, (tag, _, _, _, x0, slope, fwhm) in zip(self.axes, CASES):
            drawn = [ln for ln in ax.get_lines() if len(ln.get_xdata()) == 2]
            centre = [ln for ln in drawn if ln.get_linestyle() == "-"]
            sides = [ln for ln in drawn if ln.get_linestyle() == "--"]
            self.assertEqual((len(centre), len(sides)), (1, 2))
            y = np.asarray(centre[0].get_ydata())
            np.testing.assert_allclose(centre[0].get_xdata(), x0 + slope * y)
            for ln in sides:
                # normal distance of each side line from the centre line: FWHM/2
                d = (np.asarray(ln.get_xdata()) - x0 - slope * y) / np.sqrt(1 + slope ** 2)
                np.testing.assert_allclose(np.abs(d), 0.5 * fwhm, rtol=1e-12)
            self.assertIn("FWHM %.2f m" % fwhm, ax.get_title())

    def test_no_width_said_not_marked(self):
        sm = dict(self.sm)
        sm["h0.5.band_fwhm_normal"] = "not_applicable"
        fig, _ = mpm_plate.contour_figure(self.h5["cases"], sm, ["h0.5"])
        ax = fig.axes[0]
        self.assertIn("FWHM not_applicable", ax.get_title())
        self.assertEqual([ln for ln in ax.get_lines() if len(ln.get_xdata()) == 2], [])
        matplotlib.pyplot.close(fig)

    def test_main_writes_the_figures(self):
        self.assertEqual(mpm_plate.main(["mpm_plate.py", self.tmp.name] + [c[0] for c in CASES]), 0)
        for name in ("plastic_strain.png", "stress_strain.png"):
            self.assertTrue(os.path.getsize(os.path.join(self.tmp.name, name)) > 0, name)


def check_run(run_dir):
    """A finished run: a snapshot at each case's stage, and plastic_strain.png."""
    sm = mpm_plate.read_summary(run_dir)
    staged = 0
    with h5py.File(os.path.join(run_dir, "run.h5"), "r") as f:
        for tag in f["cases"]:
            t_stage = mpm_plate.number(sm, tag + ".band_stage_time")
            if t_stage is None:
                continue
            staged += 1
            t = float(mpm_plate.stage_snapshot(f["cases"][tag], t_stage)["time"][0])
            if abs(t - t_stage) > 1e-12 + 1e-9 * t_stage:
                sys.exit("FAIL: %s: the panel's snapshot is at %r s, its stage at %r s"
                         % (tag, t, t_stage))
    if staged == 0:
        sys.exit("FAIL: no case reached its band stage")
    if not os.path.exists(os.path.join(run_dir, "plastic_strain.png")):
        sys.exit("FAIL: no plastic_strain.png")
    print("%d case(s): a snapshot at each band stage; plastic_strain.png drawn" % staged)
    return 0


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--run":
        sys.exit(check_run(sys.argv[2]))
    unittest.main()
