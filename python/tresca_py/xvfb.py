"""pvpython on a virtual X server of our own, the one way the project runs ParaView without a display
(verification/paraview_check.py through ``tresca_py.verify.paraview``, and python/tests/test_hostile_tools.py).

Other sessions on this machine start and stop X servers at the same time. ``xvfb-run -a pvpython`` per call
aborted 3 times in 4 with "bad X server connection" while another Xvfb ran; a server of our own, on a display
it picks itself and reports (``-displayfd``), lost the connection 3 times in about 40 runs. So every pvpython
runs on our own server, and a run that lost its server (SIGABRT with that message) is repeated on a new
server, up to ``ATTEMPTS`` runs in all: the outcome under test is the script's, not the X server's. Nothing else
is retried. pvpython runs one at a time on the machine (an exclusive ``flock`` on ``LOCK``): ``make test``
runs pytest on every core (pytest-xdist), and two ParaView tests of different workers at once lost their servers
twice in a row in one of four runs.
"""
import fcntl
import os
import subprocess
import tempfile

BAD_X = "bad X server connection"
#: runs of one pvpython call at most, the first included (each further one on a restarted server)
ATTEMPTS = 3
#: the lock file that serialises pvpython calls between processes
LOCK = os.path.join(tempfile.gettempdir(), "tresca-cr-pvpython.lock")


class VirtualDisplay:
    """An Xvfb of our own, on a free display it reports when it is ready; ``env`` has its DISPLAY.
    A context manager (the server stops on exit)."""

    def __init__(self):
        self.server, self.env = None, None
        self.start()

    def start(self):
        self.server = subprocess.Popen(["Xvfb", "-displayfd", "1", "-screen", "0", "1600x1200x24", "-nolisten",
                                        "tcp"], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        number = self.server.stdout.readline().strip()
        if not number.isdigit():
            self.stop()
            raise RuntimeError("Xvfb did not start (it reported no display number)")
        self.env = dict(os.environ, DISPLAY=":" + number)

    def stop(self):
        if self.server is not None:
            self.server.terminate()
            self.server.wait()
            self.server.stdout.close()
            self.server = None

    def restart(self):
        self.stop()
        self.start()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.stop()

    def pvpython(self, args, **kwargs):
        """``subprocess.run([*prefix, "pvpython", *args])`` on this display (keyword ``prefix``: e.g. a
        setpriv command; the other keywords go to subprocess.run, output captured as text); repeated on a
        restarted server while pvpython lost its X server (``BAD_X``), ``ATTEMPTS`` runs at most; one
        pvpython at a time (``LOCK``)."""
        prefix = kwargs.pop("prefix", ())
        kwargs.setdefault("timeout", 600)
        with open(LOCK, "a") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            for attempt in range(ATTEMPTS):
                p = subprocess.run([*prefix, "pvpython", *map(str, args)], capture_output=True, text=True,
                                   env=self.env, **kwargs)
                if BAD_X not in p.stderr or attempt == ATTEMPTS - 1:
                    return p
                self.restart()
