"""``openral deploy sim --view`` from outside: the franka tabletop graph prints the page's
address beside its interfaces, serves the page and the data stream on 127.0.0.1 only, and
ends cleanly on SIGTERM. What the graph sends to the view is tested in process
(``tests/bridge/test_view_bridge.py``), and what a browser draws of a view in
``tests/docs/test_browser_view.py`` (a deploy graph and Chromium on two cores take 90 s to
show the same picture).
"""

from __future__ import annotations

import re
import time
from pathlib import Path

from openral_nodes.runtime import claim_domain_id

from tests.docs.headless_chromium import listening
from tests.docs.view_screenshot import free_port_pair, view_url
from tests.ros.lifecycle_client import deploy_output, deploy_sim
from tests.ros.ros_helpers import FRANKA_SCENE


def test_the_running_graph_serves_its_view_on_loopback(tmp_path: Path) -> None:
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
        assert line.group(1) == view_url(port)
        assert listening(port) == listening(port + 1) == ["127.0.0.1"]
        process.terminate()
        assert process.wait(30) == 0
    out, err = deploy_output(tmp_path)
    assert "clean shutdown" in out
    assert "Traceback" not in err and "view:" not in err, err
