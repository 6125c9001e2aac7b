"""``openral deploy sim --record DIR``: ``openral ros record`` in a child process.

The recorder runs in its own interpreter, so subscribing to and writing every topic never
competes with the control loop for the GIL. It starts before the graph comes up (it picks
topics up as they appear) and is stopped with SIGINT after the graph has shut down, so the
bag holds the run from first message to last and is closed properly.
"""

from __future__ import annotations

import signal
import subprocess
import sys
from pathlib import Path

from openral_core.errors import OpenralError

STOP_WAIT_S = 60.0
"""How long the recorder may take to write what it holds and close the bag [s]."""


def start_recording(folder: Path, overwrite: bool, domain_id: int) -> subprocess.Popen[bytes]:
    """Check ``folder`` (here, so a clash is one line before anything starts), then start
    the recorder on ``domain_id``."""
    from openral_nodes.bag_writer import new_bag_folder

    new_bag_folder(folder, overwrite)
    command = [sys.executable, "-m", "openral_cli.main", "ros", "record", str(folder)]
    return subprocess.Popen([*command, "--domain-id", str(domain_id)])


def stop_recording(recorder: subprocess.Popen[bytes]) -> None:
    """Ask the recorder to finish (SIGINT) and wait for it to close the bag.

    Raises:
        OpenralError: It did not finish in time (it is killed; ``--repair`` recovers the
            bag), or it ended with an error (it printed the reason).
    """
    if recorder.poll() is None:
        recorder.send_signal(signal.SIGINT)
    try:
        code = recorder.wait(STOP_WAIT_S)
    except subprocess.TimeoutExpired:
        recorder.kill()
        recorder.wait()
        raise OpenralError(
            f"the recorder did not close its bag within {STOP_WAIT_S:g} s and was killed; "
            "`openral ros record FOLDER --repair` recovers what it wrote"
        ) from None
    if code != 0:
        raise OpenralError(f"the recorder ended with exit status {code} (its reason is above)")
