"""``openral deploy sim --view``: the graph drawn in headless Chromium while it runs.

The franka tabletop graph with ``--view`` prints the page's address beside its interfaces,
serves the data stream on 127.0.0.1 only, and within
:data:`~tests.docs.view_screenshot.DRAW_WAIT_S` the page shows the floor, the table, the
arm's links and a camera frame (the graph's own ROS frames, passed on); the graph still
publishes ``/joint_states`` and ends cleanly on SIGTERM.
"""

from __future__ import annotations

import re
import time
from pathlib import Path

from openral_nodes.runtime import claim_domain_id

from tests.docs.headless_chromium import listening
from tests.docs.view_screenshot import free_port_pair, photograph
from tests.ros.lifecycle_client import deploy_output, deploy_sim
from tests.ros.ros_helpers import FRANKA_SCENE


def test_the_running_graph_is_drawn_in_the_browser(tmp_path: Path) -> None:
    port = free_port_pair()
    with deploy_sim(
        FRANKA_SCENE, claim_domain_id(), tmp_path, ["--view", "--view-port", str(port)]
    ) as process:
        deadline = time.monotonic() + 90.0
        while "view:" not in deploy_output(tmp_path)[0] and time.monotonic() < deadline:
            assert process.poll() is None, deploy_output(tmp_path)[1]
            time.sleep(0.5)
        line = re.search(r"view:\s+(\S+)", deploy_output(tmp_path)[0])
        assert line, deploy_output(tmp_path)
        assert listening(port + 1) == ["127.0.0.1"]
        seen = photograph(line.group(1), tmp_path / "deploy_view.png")
        print(f"screenshot: {seen}")
        assert seen.drawn(), seen
        process.terminate()
        assert process.wait(30) == 0
    out, err = deploy_output(tmp_path)
    assert "clean shutdown" in out
    assert "Traceback" not in err and "view:" not in err, err
