"""What the kill -9 and checkpoint tests of tests/regression/parallel and
tests/regression/parallel_2d share: running a program (under a launcher
such as mpirun) and killing a launched run with every rank it started."""
import os
import signal
import subprocess
import sys
import time


def session_members(sid):
    """Live processes of session `sid`: the launcher and every rank it
    started (Open MPI puts each rank in a process group of its own, so
    killing the launcher's group alone would leave the ranks running)."""
    pids = []
    for d in os.listdir('/proc'):
        if not d.isdigit():
            continue
        try:
            with open('/proc/%s/stat' % d) as f:
                fields = f.read().rsplit(')', 1)[1].split()
        except OSError:
            continue
        if int(fields[3]) == sid and fields[0] != 'Z':
            pids.append(int(d))
    return pids


def kill_session(sid, seconds=10.0):
    """SIGKILL every process of session `sid` (a run started with
    start_new_session=True) until none is left, or `seconds` have passed."""
    deadline = time.time() + seconds
    while time.time() < deadline:
        pids = session_members(sid)
        if not pids:
            return
        for pid in pids:
            try:
                os.kill(pid, signal.SIGKILL)
            except OSError:
                pass
        time.sleep(0.01)


def run(cmd):
    """Run `cmd` to the end; stop the test with its output unless it exits 0."""
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if r.returncode != 0:
        sys.exit('FAIL: %s exited %d\n%s' % (' '.join(cmd), r.returncode, r.stdout[-3000:]))
    return r.stdout


def writer_problem(written, ranks, parallel_hdf5):
    """Why the `h5_writer` line of a run's summary.txt (`written`) is not
    the one a run on `ranks` ranks must report (None when it is): with
    parallel HDF5 every run on more than one rank writes run.h5 through
    MPI-IO collectively; a run on one rank, or any run of a build on serial
    HDF5, has rank 0 write it."""
    want = 'mpio-collective' if parallel_hdf5 and ranks > 1 else 'rank0-gather'
    if written != want:
        return 'h5_writer = %s on %d rank(s), expected %s' % (written, ranks, want)
    return None


def layout_problems(ref, run):
    """How the layout of HDF5 file `run` differs from that of `ref` (h5py
    files): datasets missing or extra, another type or shape, root
    attributes missing, extra or of other values. Empty when the same."""
    import h5py
    import numpy as np
    names = {}
    for label, f in (('ref', ref), ('run', run)):
        found = []
        f.visit(lambda n: found.append(n) if isinstance(f[n], h5py.Dataset) else None)
        names[label] = set(found)
    bad = ['%s (missing)' % n for n in sorted(names['ref'] - names['run'])]
    bad += ['%s (extra)' % n for n in sorted(names['run'] - names['ref'])]
    for n in sorted(names['ref'] & names['run']):
        if ref[n].dtype != run[n].dtype or ref[n].shape != run[n].shape:
            bad.append('%s (%s %s, expected %s %s)' % (n, run[n].dtype, run[n].shape,
                                                        ref[n].dtype, ref[n].shape))
    for k in sorted(set(ref.attrs) | set(run.attrs)):
        if k not in run.attrs or k not in ref.attrs:
            bad.append('attribute %s (%s)' % (k, 'missing' if k not in run.attrs else 'extra'))
        elif not np.array_equal(np.asarray(ref.attrs[k]), np.asarray(run.attrs[k])):
            bad.append('attribute %s (another value)' % k)
    return bad
