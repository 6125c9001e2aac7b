"""The policy seam: the wave policy, the registry and key=value parameters."""

from __future__ import annotations

import math

import numpy as np
import pytest
from openral_eval.policies import (
    Observation,
    PolicyConfigError,
    WaveConfig,
    WavePolicy,
    make_policy,
    parse_params,
)

NAMES = ("j1", "j2", "grip")
HOLD = np.array([0.5, -1.0, 0.02])
FRAME = np.zeros((4, 4, 3), np.uint8)


def observation(time_s: float, slots: tuple[str, ...] = ("camera1", "camera2")) -> Observation:
    obs: Observation = {f"observation.images.{slot}": FRAME for slot in slots}
    obs |= {"observation.state": np.zeros(3), "action_spec": (NAMES, HOLD), "time_s": time_s}
    return obs


def test_wave_adds_a_sinusoid_to_the_hold_on_the_chosen_slots_only() -> None:
    policy = WavePolicy(WaveConfig(amplitude=0.2, period_s=4.0, action_slots=("j2",)))
    assert np.allclose(policy.act(observation(0.0)), HOLD)
    quarter = policy.act(observation(1.0))  # sin(π/2) = 1: the peak
    assert np.allclose(quarter, HOLD + np.array([0.0, 0.2, 0.0]))
    t = 2.7
    assert np.allclose(
        policy.act(observation(t)),
        HOLD + np.array([0.0, 0.2 * math.sin(2 * math.pi * t / 4.0), 0.0]),
    )


def test_wave_without_chosen_slots_moves_every_slot() -> None:
    action = WavePolicy(WaveConfig(amplitude=0.1, period_s=4.0)).act(observation(1.0))
    assert np.allclose(action, HOLD + 0.1)


def test_wave_refuses_to_act_without_its_required_slots() -> None:
    policy = make_policy("wave")
    assert policy.required_slots == ("camera1", "camera2")
    with pytest.raises(ValueError, match="camera2"):
        policy.act(observation(0.0, slots=("camera1",)))


def test_wave_names_the_real_action_slots_when_configured_with_unknown_ones() -> None:
    policy = make_policy("wave", {"action_slots": "j2,elbow"})
    with pytest.raises(
        PolicyConfigError,
        match="action_slots elbow are not action slots; the HAL's are: j1, j2, grip",
    ):
        policy.act(observation(0.0))


def test_make_policy_converts_string_parameters_by_field_type() -> None:
    policy = make_policy(
        "wave",
        parse_params(["amplitude=0.3", "period_s=2", "required_slots=camera1", "action_slots="]),
    )
    assert isinstance(policy, WavePolicy)
    assert policy.config == WaveConfig(
        amplitude=0.3, period_s=2.0, action_slots=(), required_slots=("camera1",)
    )


@pytest.mark.parametrize(
    ("name", "params", "message"),
    [
        ("dance", {}, "unknown policy 'dance'; available: wave, scripted_lift"),
        ("wave", {"speed": "1"}, "unknown parameter 'speed'.*valid: amplitude, period_s"),
        ("wave", {"amplitude": "big"}, "amplitude='big': Input should be a valid number"),
        ("wave", {"period_s": "0"}, "period_s must be > 0"),
    ],
)
def test_bad_policy_names_and_parameters_raise_one_clear_error(
    name: str, params: dict[str, str], message: str
) -> None:
    with pytest.raises(PolicyConfigError, match=message):
        make_policy(name, params)


def test_parse_params_rejects_items_without_equals() -> None:
    with pytest.raises(PolicyConfigError, match="'amplitude' is not key=value"):
        parse_params(["amplitude"])


def test_a_subclass_keeps_its_parents_action_mode() -> None:
    from openral_eval.policy import action_mode
    from openral_eval.scripted_lift import LiftConfig, ScriptedLift

    class Tuned(ScriptedLift):
        pass

    assert action_mode(Tuned(LiftConfig())) == "ee_delta_pose"
