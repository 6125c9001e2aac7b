"""The light of a native scene: the headlight, a key and a fill light from above, and the
robot model's own lights, held to one budget so that no surface is lit past white.

MuJoCo adds up every light that falls on a surface (ambient, plus each light's diffuse
intensity times the cosine of its angle, plus specular highlights) and clips the sum at
white. Menagerie models bring a light of 0.7 of their own, MuJoCo's headlight adds 0.4 and
0.5 of specular, and a scene's own lights more: a camera that looks straight down at a
table got more than twice what makes white, and 88 % of the wrist camera's pixels were
clipped. Here the headlight is fixed and every other light (the scene's and the model's,
whose directions are kept) is scaled so their diffuse and specular intensities add up to
:data:`LIGHT_DIFFUSE` and :data:`LIGHT_SPECULAR`.
"""

from __future__ import annotations

import mujoco
import numpy as np

HEADLIGHT_AMBIENT = 0.25
"""Light every surface gets wherever it faces (the headlight's ambient term)."""
HEADLIGHT_DIFFUSE = 0.2
"""The headlight shines along each camera's view: surfaces facing the camera get this."""
HEADLIGHT_SPECULAR = 0.0
"""No highlight from the camera's own direction (a camera looking straight down at a
table would see the whole table top as one highlight)."""
LIGHT_DIFFUSE = 0.5
"""Sum of the diffuse intensities of all other lights: a surface facing every light at
once gets at most ``HEADLIGHT_AMBIENT + HEADLIGHT_DIFFUSE + LIGHT_DIFFUSE`` (0.95) of its
colour."""
LIGHT_SPECULAR = 0.1
"""Sum of the specular intensities of all other lights."""
KEY_DIRECTION = (0.2, 0.3, -1.0)
FILL_DIRECTION = (0.4, -0.5, -1.0)
FILL_SHARE = 0.4
"""The fill light's intensity relative to the key light's, before the budget."""


def add_scene_lights(spec: mujoco.MjSpec) -> None:
    """The headlight (see the constants) and two directional lights from above, a key light
    and a weaker fill light from the other side (their intensities are set by
    :func:`balance_lights` once the robot's lights are in)."""
    headlight = spec.visual.headlight
    headlight.ambient = np.full(3, HEADLIGHT_AMBIENT, dtype=np.float32)
    headlight.diffuse = np.full(3, HEADLIGHT_DIFFUSE, dtype=np.float32)
    headlight.specular = np.full(3, HEADLIGHT_SPECULAR, dtype=np.float32)
    for name, direction, share in (
        ("scene_key_light", KEY_DIRECTION, 1.0),
        ("scene_fill_light", FILL_DIRECTION, FILL_SHARE),
    ):
        spec.worldbody.add_light(
            name=name,
            type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL,
            dir=list(direction),
            diffuse=[share] * 3,
            specular=[share] * 3,
            castshadow=False,
        )


def balance_lights(spec: mujoco.MjSpec) -> None:
    """Scale every light of ``spec`` (the scene's and the attached models') so their diffuse
    intensities add up to :data:`LIGHT_DIFFUSE` and their specular ones to
    :data:`LIGHT_SPECULAR`; the headlight's is the only ambient light."""
    lights = list(spec.lights)
    diffuse = sum(float(np.max(light.diffuse)) for light in lights)
    specular = sum(float(np.max(light.specular)) for light in lights)
    for light in lights:
        light.ambient = [0.0, 0.0, 0.0]
        if diffuse > 0:
            light.diffuse = np.asarray(light.diffuse) * (LIGHT_DIFFUSE / diffuse)
        if specular > 0:
            light.specular = np.asarray(light.specular) * (LIGHT_SPECULAR / specular)
