"""pvpython on a virtual X server of our own, the one way the project runs ParaView without a display
(verification/paraview_check.py through ``tresca_py.verify.paraview``, and python/tests/test_hostile_tools.py).

Other sessions on this machine start and stop X servers at the same time. ``xvfb-run -a pvpython`` per call
aborted 3 times in 4 with "bad X server connection" while another Xvfb ran; a server of our own, on a display
it picks itself and reports (``-displayfd``), lost the connection 3 times in about 40 runs. So every pvpython
runs on our own server, and a run that lost its server (SIGABRT with that message) is repeated once on a new
server: the outcome under test is the script's, not the X server's. Nothing else is retried.
"""
import os
import subprocess

BAD_X = "bad X server connection"


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
        setpriv command; the other keywords go to subprocess.run, output captured as text); repeated once on
        a restarted server if pvpython lost its X server (``BAD_X``)."""
        prefix = kwargs.pop("prefix", ())
        kwargs.setdefault("timeout", 600)
        for attempt in range(2):
            p = subprocess.run([*prefix, "pvpython", *map(str, args)], capture_output=True, text=True,
                               env=self.env, **kwargs)
            if BAD_X not in p.stderr or attempt:
                return p
            self.restart()
