"""``openral deploy real`` refusing bad input (on the emulator, not hardware): a wrong port, a
busy port, a missing motor, another robot's calibration, a manifest with duplicate motor
ids, a camera that is not there: each is one line, exit status 1, and nothing written to
the bus."""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.real.deploy_helpers import RemoteBus, openral


@pytest.fixture
def bus(tmp_path: Path) -> Iterator[RemoteBus]:
    """An emulated SO-101 bus in a process of its own, calibrated."""
    remote = RemoteBus(tmp_path)
    yield remote
    remote.close()


@pytest.mark.parametrize(
    ("case", "expected"),
    [
        ("wrong port", "no such serial port"),
        ("busy port", "the port is busy"),
        ("missing motor", "motor 5 (wrist_roll) does not answer"),
        ("another robot's calibration", "this is another robot's calibration"),
        ("duplicate motor ids", "real.feetech.motors[5].id: id 5 is already the id of"),
        ("missing camera", "camera front: cannot open /dev/video97"),
    ],
)
def test_bad_input_is_one_line_exit_1_and_nothing_written(
    bus: RemoteBus, tmp_path: Path, case: str, expected: str
) -> None:
    import serial
    from openral_core.paths import repo_root

    args = ["--transport", bus.path, "--calibration", str(bus.calibration), "--robot", "so101"]
    held = None
    if case == "wrong port":
        args[1] = "/dev/pts/no-such-port"
    elif case == "busy port":
        held = serial.Serial(bus.path, 1_000_000, exclusive=True)
    elif case == "missing motor":
        assert bus.command("silent 5").startswith("ok")
    elif case == "another robot's calibration":
        other = tmp_path / "koch.json"
        other.write_text(bus.calibration.read_text().replace('"wrist_roll"', '"wrist_twist"'))
        args[3] = str(other)
    elif case == "missing camera":
        args += ["--camera", "front=/dev/video97"]
    else:
        manifest = tmp_path / "so101" / "robot.yaml"
        manifest.parent.mkdir()
        text = (repo_root() / "robots" / "so101" / "robot.yaml").read_text()
        manifest.write_text(text.replace("{joint: gripper, id: 6}", "{joint: gripper, id: 5}"))
        args[-2:] = ["--manifest", str(manifest)]
    started = time.time()
    try:
        process = openral("deploy", "real", *args, "--duration", "1")
        _, err = process.communicate(timeout=60)
    finally:
        if held is not None:
            held.close()
    lines = [line for line in err.strip().splitlines() if not line.startswith("[INFO]")]
    assert process.returncode == 1 and len(lines) == 1, err
    assert expected in lines[0], lines[0]
    assert [line for line in bus.lines(started) if "WRITE" in line] == []
