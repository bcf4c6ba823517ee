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
