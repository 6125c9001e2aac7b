"""Policy parameters into the policy's own config type: a pydantic model or a dataclass,
nested values from JSON or dotted keys, strings kept as text, one-line errors."""

from __future__ import annotations

from dataclasses import dataclass, field

import pydantic
import pytest
from openral_eval.policy import PolicyConfigError
from openral_eval.policy_config import config_fields, parse_config, parse_params


class Target(pydantic.BaseModel):
    x: float = 0.4
    z: float = 0.2


class ReachConfig(pydantic.BaseModel):
    name: str = "reach"
    gain: float = pydantic.Field(default=1.0, gt=0)
    steps: int = 10
    cameras: tuple[str, ...] = ("camera1",)
    offsets: list[float] = []
    target: Target = Target()


@dataclass(frozen=True)
class Limits:
    low: float = -1.0
    high: float = 1.0


@dataclass(frozen=True)
class PlainConfig:
    scale: float = 1.0
    limits: Limits = field(default_factory=Limits)


def _reach(**params: str) -> ReachConfig:
    config = parse_config(ReachConfig, params, "reach")
    assert isinstance(config, ReachConfig)
    return config


def test_values_are_json_where_json_and_text_for_a_str_field() -> None:
    config = _reach(name="123", gain="0.5", steps="3", offsets="[0.1, 0.2]", cameras="a,b")
    assert (config.name, config.gain, config.steps) == ("123", 0.5, 3)
    assert config.offsets == [0.1, 0.2] and config.cameras == ("a", "b")


def test_a_nested_value_from_json_or_a_dotted_key() -> None:
    assert _reach(target='{"x": 0.5, "z": 0.3}').target == Target(x=0.5, z=0.3)
    assert _reach(**{"target.z": "0.25"}).target == Target(x=0.4, z=0.25)  # x keeps its default


def test_a_dataclass_config_takes_the_same_forms() -> None:
    config = parse_config(PlainConfig, {"scale": "2", "limits.high": "0.5"}, "plain")
    assert config == PlainConfig(scale=2.0, limits=Limits(low=-1.0, high=0.5))


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ({"speed": "1"}, "unknown parameter 'speed' for policy 'reach'; valid: name, gain"),
        ({"gain": "-1"}, "reach parameter gain='-1': Input should be greater than 0"),
        ({"steps": "many"}, "reach parameter steps='many': Input should be a valid integer"),
        ({"target.x": "far"}, "reach parameter target.x='far': Input should be a valid number"),
        ({"target": "[1, 2]"}, "reach parameter target='\\[1, 2\\]': Input should be a valid"),
        ({"name.first": "a"}, "reach parameter name.first: name holds no fields"),
    ],
)
def test_a_bad_parameter_is_one_line_naming_it(params: dict[str, str], message: str) -> None:
    with pytest.raises(PolicyConfigError, match=message) as raised:
        parse_config(ReachConfig, params, "reach")
    assert "\n" not in str(raised.value)


def test_items_must_be_key_value_and_fields_list_their_defaults() -> None:
    assert parse_params(["a=1", 'b={"c": 2}', "a=3"]) == {"a": "3", "b": '{"c": 2}'}
    with pytest.raises(PolicyConfigError, match="'oops' is not key=value"):
        parse_params(["oops"])
    fields = config_fields(ReachConfig)
    assert list(fields) == ["name", "gain", "steps", "cameras", "offsets", "target"]
    assert fields["target"][1] == Target() and fields["gain"][0] is float
