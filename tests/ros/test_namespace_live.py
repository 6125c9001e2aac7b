"""``deploy sim --namespace arm`` puts the whole graph under ``/arm``, as a robot's driver
launched in a namespace: topics, services, the actions and the controller manager; nothing
stays at the root. A namespace ROS refuses is one line naming the option."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from controller_manager_msgs.srv import ListControllers
from openral_nodes.runtime import Spinner, claim_domain_id, ros_session
from sensor_msgs.msg import JointState

from tests.conftest import ROBOTS
from tests.ros.lifecycle_client import deploy_output, deploy_sim
from tests.ros.ros_helpers import Probe, wait_until

SCENE = ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml"
START_WAIT_S = 90.0


@pytest.fixture(scope="module")
def probe(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Probe]:
    logs = tmp_path_factory.mktemp("namespace")
    domain = claim_domain_id()
    with ros_session(domain_id=domain) as context:
        probe = Probe(context, {"/arm/joint_states": JointState}, name="namespace_client")
        with (
            Spinner(context) as spinner,
            deploy_sim(SCENE, domain, logs, ("--namespace", "arm")) as p,
        ):
            spinner.add_node(probe.node)
            probe.wait_count("/arm/joint_states", 1, timeout_s=START_WAIT_S)
            assert p.poll() is None, deploy_output(logs)
            yield probe
        probe.node.destroy_node()  # type: ignore[no-untyped-call]


def test_every_name_of_the_graph_is_under_the_namespace(probe: Probe) -> None:
    node = probe.node

    topics_wanted = {
        "/arm/joint_states", "/arm/tf", "/arm/tf_static", "/arm/clock", "/arm/robot_description",
        "/arm/dynamic_joint_states", "/arm/openral/cameras/wrist/image",
    }  # fmt: skip
    services_wanted = {
        "/arm/controller_manager/list_controllers", "/arm/openral/estop",
        "/arm/gripper_controller/gripper_cmd/_action/send_goal",
        "/arm/joint_trajectory_controller/follow_joint_trajectory/_action/send_goal",
    }  # fmt: skip

    def discovered() -> bool:  # discovery on a loaded machine takes its time
        topics = {name for name, _ in node.get_topic_names_and_types()}
        services = {name for name, _ in node.get_service_names_and_types()}
        return topics_wanted <= topics and services_wanted <= services

    wait_until(discovered, 30.0, "the namespaced topics and services")
    topics = {name for name, _ in node.get_topic_names_and_types()}
    services = {name for name, _ in node.get_service_names_and_types()}
    assert topics_wanted <= topics, topics_wanted - topics
    assert services_wanted <= services, services_wanted - services
    ours = {"/joint_states", "/tf", "/clock", "/robot_description", "/dynamic_joint_states"}
    assert not ours & topics, ours & topics
    assert not any(s.startswith(("/controller_manager/", "/openral/")) for s in services)
    client = node.create_client(ListControllers, "/arm/controller_manager/list_controllers")
    assert client.wait_for_service(timeout_sec=10.0)
    future = client.call_async(ListControllers.Request())
    wait_until(future.done, 10.0, "list_controllers")
    assert "joint_trajectory_controller" in {c.name for c in future.result().controller}


def test_a_namespace_ros_refuses_is_one_line(tmp_path: Path) -> None:
    openral = Path(sys.executable).parent / "openral"
    command = [str(openral), "deploy", "sim", "--config", str(SCENE), "--no-viewer",
               "--namespace", "9 bad", "--duration", "1"]  # fmt: skip
    result = subprocess.run(command, capture_output=True, text=True, timeout=120)
    assert result.returncode != 0
    lines = [line for line in result.stderr.splitlines() if "--namespace" in line]
    assert lines and "Traceback" not in result.stderr, result.stderr
