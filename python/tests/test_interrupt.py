"""Ctrl-C stops surftrack.extract in every stage, smoothing and decimation included
(docs/python.md): a child process runs a long extraction, is sent SIGINT once it has spent a
second in the stage, and must end with KeyboardInterrupt within a few seconds. Uninterrupted,
the smoothing (100000 iterations) runs for minutes and the decimation (a ball of about 240,000
triangles, reduce=0.999) for well over ten seconds on this project's machines."""
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import surftrack

CHILD = r"""
import sys
import numpy as np
import surftrack

stage_wanted, n = sys.argv[1], int(sys.argv[2])
i, j, k = np.ogrid[:n, :n, :n]
ball = ((i - n / 2) ** 2 + (j - n / 2) ** 2 + (k - n / 2) ** 2 < (0.4 * n) ** 2).astype(np.uint8)


def progress(stage, index, stages, surfels):
    if stage == stage_wanted:
        print(stage, flush=True)


kwargs = {"smooth": {"smooth": 100000}, "decimate": {"reduce": 0.999}}[stage_wanted]
try:
    surftrack.extract(ball, label=1, mode="largest", progress=progress, **kwargs)
except KeyboardInterrupt:
    print("KeyboardInterrupt", flush=True)
    sys.exit(3)
print("finished", flush=True)
"""

# SIGINT to the end of the child: what "a few seconds" means here.
PATIENCE = 5.0


@pytest.mark.parametrize("stage,n", [("smooth", 48), ("decimate", 200)])
def test_sigint_stops_a_long_refinement(stage, n):
    package_dir = str(Path(surftrack.__file__).resolve().parents[1])
    env = dict(os.environ, PYTHONPATH=package_dir + os.pathsep + os.environ.get("PYTHONPATH", ""))
    child = subprocess.Popen([sys.executable, "-c", CHILD, stage, str(n)], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, env=env)
    try:
        assert child.stdout.readline().strip() == stage, child.stderr.read()
        time.sleep(1.0)
        assert child.poll() is None, "the stage ended within a second: the test would prove nothing"
        child.send_signal(signal.SIGINT)
        out, err = child.communicate(timeout=PATIENCE)  # (a stop that never comes fails below)
    except subprocess.TimeoutExpired:
        child.kill()
        child.communicate()
        pytest.fail(f"{stage}: still running {PATIENCE} s after SIGINT")
    assert child.returncode == 3 and out.strip() == "KeyboardInterrupt", (child.returncode, out, err)
