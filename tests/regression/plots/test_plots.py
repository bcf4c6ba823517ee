#!/usr/bin/env python3
"""What the plot scripts draw, on small synthetic runs.

test_plots.py            the unit tests below (python unittest)
test_plots.py --e2e EXE  wellposed-mpm on decks/plot_ref_run.nml, whose
                         &output reference is decks/plot_ref_base.nml:
                         first without the reference run (the run's log and
                         stations.png say so and give the command), then
                         that command, then again (no note: drawn dashed).

mpm_stations.py: the reference run drawn dashed station by station when
present; a note on the figure and a printed line with the command that
makes it when absent or unreadable; no guide line where the summary gives
the ideal arrivals as not_applicable (C_P < C_E), nor a viscoplastic head
guide where the measured head runs more than 2 % off C_P; the overlocal head guide
at the low-frequency speed C_P(h_eta + h_zeta), whose closed form is
checked against C_P = 2045.09 m/s (h = 0, point_fig2_4) and the local
speeds 2132.37 / 1989.18 m/s of docs/research/figures.md (fig. 2.10 left).
plot_point.py: chapter3.png warns when a fit residual exceeds
RESIDUAL_WARN, and only then.
"""
import contextlib
import io
import os
import re
import shlex
import subprocess
import sys
import tempfile
import unittest

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, '..', '..', '..'))
sys.path.insert(0, os.path.join(ROOT, 'mpm', 'plots'))
sys.path.insert(0, os.path.join(ROOT, 'point', 'plots'))
import mpm_stations  # noqa: E402
import plot_point  # noqa: E402

# Sandler-Rubin case (docs/research/cases.md, A): K, G, beta, beta_p, k0, h, k_lim,
# z_ref, P_v, P_d, tau, h_zeta, L
PROPS = [4.0e9, 1.5e9, 0.315, 0.0, 5.066e6, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]


def write_run(folder, x=(100.0, 200.0, 300.0), c_e=1732.05, c_p=2045.09, props=PROPS,
              summary=None, shift=0.0):
    """A run folder with run.h5 (three triangles) and summary.txt."""
    os.makedirs(folder, exist_ok=True)
    t = np.linspace(0.0, 0.3, 601)
    sxx = np.array([-100e6 + 10e6 * np.maximum(0.0, 1 - abs(t - xi / c_p - 1e-3 - shift) / 1e-3)
                    for xi in x])
    with h5py.File(os.path.join(folder, 'run.h5'), 'w') as f:
        f['stations/time'] = t
        f['stations/x'] = np.array(x)
        f['stations/sigma_xx'] = sxx
        f['measures/t_head'] = np.array([xi / c_p for xi in x])
        f['measures/t_tail'] = np.array([xi / c_e + 2e-3 for xi in x])
        f.attrs['title'] = 'synthetic'
        f.attrs['props'] = np.array(props)
        f.attrs['numbers_names'] = 'dx dt cfl c_elastic c_plastic load_peak load_duration ' \
                                   'density ppc'
        f.attrs['numbers'] = np.array([0.25, 2.9e-5, 0.2, c_e, c_p, 10e6, 2e-3, 2000.0, 2.0])
    with open(os.path.join(folder, 'summary.txt'), 'w') as f:
        f.write(summary if summary is not None else
                'station_1_t_head_ideal = 5.0E-002  # s, x/C_P + tau/4\n')
    return os.path.join(folder, 'run.h5')


def guide_lines(ax):
    return [l for l in ax.get_lines() if l.get_color() == mpm_stations.GUIDE]


def dashed(ax):
    return [l for l in ax.get_lines() if l.get_linestyle() == '--' and len(l.get_xdata()) > 0]


class Stations(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = self.tmp.name
        self.png = os.path.join(self.dir, 'out.png')

    def tearDown(self):
        mpm_stations.plt.close('all')
        self.tmp.cleanup()

    def draw(self, run, *args):
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            fig, ax, info = mpm_stations.draw(run, self.png, *args)
        self.assertTrue(os.path.getsize(self.png) > 0)
        return ax, info, out.getvalue()

    def test_reference_drawn_dashed_at_matching_stations(self):
        run = write_run(os.path.join(self.dir, 'a'))
        # the reference has the first two stations of the run and one elsewhere
        ref = write_run(os.path.join(self.dir, 'b'), x=(100.0, 200.0, 350.0), shift=1e-3)
        ax, info, printed = self.draw(run, ref, 'h = 0', 'make-it')
        self.assertEqual(info['reference_drawn'], 2)
        self.assertEqual(len(dashed(ax)), 2)
        self.assertIsNone(info['note'])
        self.assertEqual(printed, '')
        self.assertIn('dashed: h = 0', ax.get_legend_handles_labels()[1])
        self.assertIn('dashed: h = 0', ax.get_title())

    def test_missing_reference_noted_with_its_command(self):
        run = write_run(os.path.join(self.dir, 'a'))
        missing = os.path.join(self.dir, 'none', 'run.h5')
        ax, info, printed = self.draw(run, missing, 'h = 0', 'wellposed-mpm inputs/x.nml')
        self.assertEqual(info['reference_drawn'], 0)
        self.assertEqual(dashed(ax), [])
        for where in (info['note'], printed, ' '.join(t.get_text() for t in ax.texts)):
            self.assertIn('has not been made yet', where)
            self.assertIn('make it with: wellposed-mpm inputs/x.nml', where)
            self.assertIn(missing, where)

    def test_unreadable_reference_noted_not_raised(self):
        run = write_run(os.path.join(self.dir, 'a'))
        bad = os.path.join(self.dir, 'bad.h5')
        with open(bad, 'w') as f:
            f.write('not hdf5')
        ax, info, printed = self.draw(run, bad, 'h = 0', 'cmd')
        self.assertIn('cannot be read', info['note'])
        self.assertIn('cannot be read', printed)
        self.assertEqual(dashed(ax), [])

    def test_guides_labelled_with_their_speed(self):
        run = write_run(os.path.join(self.dir, 'a'))
        ax, info, _ = self.draw(run)
        self.assertEqual(len(guide_lines(ax)), 2 * 3)
        labels = [l.get_label() for l in guide_lines(ax) if not l.get_label().startswith('_')]
        self.assertEqual(len(labels), 2)
        self.assertTrue(any('C_P = 2045 m/s' in s for s in labels), labels)
        self.assertTrue(any('C_E = 1732 m/s' in s for s in labels), labels)
        # head guide at x/C_P (ms)
        heads = sorted(l.get_xdata()[0] for l in guide_lines(ax) if l.get_linestyle() == '-')
        np.testing.assert_allclose(heads, [x / 2045.09 * 1e3 for x in (100, 200, 300)])

    def test_no_guides_where_not_applicable(self):
        summary = ('station_1_t_head_ideal = not_applicable  # C_P < C_E: ...\n'
                   'station_1_t_tail_ideal = not_applicable  # C_P < C_E: ...\n')
        run = write_run(os.path.join(self.dir, 'a'), c_p=1489.26, summary=summary)
        ax, info, _ = self.draw(run)
        self.assertEqual(guide_lines(ax), [])
        self.assertEqual(info['guides'], [])
        self.assertIn('C_P < C_E', ax.get_title())

    def test_no_guides_without_summary_when_plastic_slower(self):
        run = write_run(os.path.join(self.dir, 'a'), c_p=1489.26)
        os.remove(os.path.join(self.dir, 'a', 'summary.txt'))
        ax, _, _ = self.draw(run)
        self.assertEqual(guide_lines(ax), [])

    def test_closed_form_speeds(self):
        c = mpm_stations.uniaxial_plastic_speed
        self.assertAlmostEqual(c(PROPS, 2000.0, 0.0), 2045.09, delta=0.005)
        self.assertAlmostEqual(c(PROPS, 2000.0, -0.5e9), 2132.37, delta=0.005)
        self.assertAlmostEqual(c(PROPS, 2000.0, 0.5e9), 1989.18, delta=0.005)

    def test_overlocal_head_guide_at_low_frequency_speed(self):
        props = list(PROPS)
        props[5], props[11], props[12] = 0.5e9, -1.0e9, 1.0   # h_eta, h_zeta, L
        run = write_run(os.path.join(self.dir, 'a'), c_p=1989.1837, props=props)
        ax, info, _ = self.draw(run)
        head = [g for g in info['guides'] if g[0] == 'head']
        self.assertEqual(len(head), 1)
        self.assertAlmostEqual(head[0][1], 2132.37, delta=0.01)
        self.assertIn('2132 m/s', head[0][2])
        lines = sorted(l.get_xdata()[0] for l in guide_lines(ax) if l.get_linestyle() == '-')
        np.testing.assert_allclose(lines, [x / head[0][1] * 1e3 for x in (100, 200, 300)])

    def test_overlocal_without_closed_form_draws_no_head_guide(self):
        props = list(PROPS)
        props[5], props[11], props[12] = 0.5e9, -1.0e9, 1.0
        run = write_run(os.path.join(self.dir, 'a'), c_p=1900.0, props=props)  # not closed form's
        ax, info, _ = self.draw(run)
        self.assertEqual([g for g in info['guides'] if g[0] == 'head'], [])
        self.assertIn('no x/C_P guide', ax.get_title())

    def test_viscoplastic_head_guide_only_where_the_head_runs_at_c_p(self):
        props = list(PROPS)
        props[10] = 0.01                                    # tau: Duvaut-Lions
        near = 'station_1_t_head_ideal = 5.0E-002\nc_head_over_c_plastic = 0.993\n'
        run = write_run(os.path.join(self.dir, 'a'), props=props, summary=near)
        _, info, _ = self.draw(run)
        head = [g for g in info['guides'] if g[0] == 'head']
        self.assertEqual(len(head), 1)
        self.assertIn('De -> 0', head[0][2])
        slow = 'station_1_t_head_ideal = 5.0E-002\nc_head_over_c_plastic = 0.871\n'
        run = write_run(os.path.join(self.dir, 'b'), props=props, summary=slow)
        ax, info, _ = self.draw(run)
        self.assertEqual([g for g in info['guides'] if g[0] == 'head'], [])
        self.assertIn('0.87 C_P', ax.get_title())
        self.assertEqual(len([g for g in info['guides'] if g[0] == 'end']), 1)

    def test_command_line(self):
        run = write_run(os.path.join(self.dir, 'a'))
        r = subprocess.run([sys.executable, mpm_stations.__file__, run, self.png, '--reference',
                            os.path.join(self.dir, 'x', 'run.h5'), 'lab', '--make', 'do this'],
                           capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("reference 'lab' not drawn", r.stdout)
        self.assertIn('make it with: do this', r.stdout)


def write_point_run(folder, residual):
    """A wellposed-point run folder with one chapter3 specimen 'efr'."""
    os.makedirs(folder, exist_ok=True)
    ang = np.radians([90, 180, 60, 125])
    s = np.hstack([np.vstack([np.cos(ang), np.sin(ang)]),
                   -np.vstack([np.cos(ang), np.sin(ang)])]) * 1e6
    lm = np.array([[1.0, 0.3], [0.3, 2.0]]) * 1e-10
    r = lm @ s
    with h5py.File(os.path.join(folder, 'results.h5'), 'w') as f:
        f.attrs['version'] = np.bytes_('0.0.0')   # as the driver writes it
        g = f.create_group('efr/chapter3')
        g['s'], g['r'], g['rp'] = s, r, 0.9 * r
        g['l'], g['l_el'] = lm, 0.5 * lm
        g['m'], g['n'] = np.array([-1.0, 0.02]), np.array([-1.0, -0.02])
    with open(os.path.join(folder, 'summary.txt'), 'w') as f:
        f.write(f'efr.chapter3.residual = {residual!r}  # ||R - L S||/||R||\n'
                'efr.chapter3.rank_ratio = 5.8E-002\n')


class Chapter3(unittest.TestCase):
    def run_plot(self, residual):
        with tempfile.TemporaryDirectory() as d:
            write_point_run(d, residual)
            plot_point.RUN = d
            with h5py.File(os.path.join(d, 'results.h5'), 'r') as f:
                warned = plot_point.plot_chapter3(f, ['efr'])
            self.assertTrue(os.path.getsize(os.path.join(d, 'chapter3.png')) > 0)
            return warned

    def test_warning_above_threshold_only(self):
        w = plot_point.RESIDUAL_WARN
        self.assertEqual(self.run_plot(0.6618), ['efr'])
        self.assertEqual(self.run_plot(1.01 * w), ['efr'])
        self.assertEqual(self.run_plot(0.99 * w), [])
        self.assertEqual(self.run_plot(1.4e-13), [])

    def test_note_text(self):
        text, warn = plot_point.fit_note({'efr.chapter3.residual': '6.6E-001',
                                          'efr.chapter3.rank_ratio': '5.8E-002'}, 'efr')
        self.assertTrue(warn)
        self.assertIn('0.66', text)
        self.assertIn('WARNING', text)
        self.assertIn('rank ratio 0.058', text)
        text, warn = plot_point.fit_note({}, 'efr')
        self.assertFalse(warn)
        self.assertIn('not in summary.txt', text)


def e2e(exe):
    """The deck's reference through wellposed-mpm (see the module text)."""
    decks = os.path.join(HERE, 'decks')
    with tempfile.TemporaryDirectory() as out:
        def run(cmd):
            r = subprocess.run(cmd, capture_output=True, text=True)
            print(r.stdout[-1500:], r.stderr[-1500:])
            if r.returncode != 0:
                sys.exit(f'FAIL: {cmd} exited {r.returncode}')
            return r.stdout
        deck = os.path.join(decks, 'plot_ref_run.nml')
        first = run([exe, '--out', out, '--checkpoint-every', '0', deck])
        m = re.search(r"reference 'h = 0 \(dashed\)' not drawn: (\S+) has not been made yet; "
                      r"make it with: (.*)$", first, re.M)
        if not m:
            sys.exit('FAIL: the log does not say that the reference run is missing')
        if m.group(1) != os.path.join(out, 'plot_ref_base', 'run.h5'):
            sys.exit(f'FAIL: reference looked up at {m.group(1)}')
        if not os.path.exists(os.path.join(out, 'plot_ref_run', 'stations.png')):
            sys.exit('FAIL: no stations.png')
        run(shlex.split(m.group(2)) + ['--checkpoint-every', '0'])   # the printed command
        second = run([exe, '--out', out, '--checkpoint-every', '0', deck])
        if 'not drawn' in second or not os.path.exists(os.path.join(out, 'plot_ref_base',
                                                                    'run.h5')):
            sys.exit('FAIL: the reference run made by the printed command was not drawn')
    print('e2e: reference noted when missing, made by the printed command, then drawn')
    return 0


if __name__ == '__main__':
    if len(sys.argv) == 3 and sys.argv[1] == '--e2e':
        sys.exit(e2e(sys.argv[2]))
    unittest.main()
