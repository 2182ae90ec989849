"""The mannequin's materials: skin, hair, clothes and shoes in the look's colours.

The detector leans on clothing that separates the torso from the legs, and the scenario
families' clothing presets vary the clothes (dark with long sleeves, a checked shirt) to
see what else it leans on; so the look's materials are made here once, and every part
of the body refers to them by name.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco

from sim.scenario.spec import RGBA, MannequinSpec


@dataclass(frozen=True)
class Materials:
    """Names of the materials in the spec that the mannequin's geoms are drawn with."""

    skin: str
    skin_dark: str  # ears and nose: a shade darker, so they show against the face
    hair: str  # also the eyebrows
    shoes: str
    trousers: str  # also the pelvis
    shirt: str
    eye_white: str
    iris: str
    lips: str
    arm: str  # below the short sleeve: the shirt for long sleeves, bare skin otherwise


def add_materials(spec: mujoco.MjSpec, look: MannequinSpec, prefix: str) -> Materials:
    """Add the look's materials (and the shirt's check, if it has one) to `spec`.

    Added in a fixed order (the checker texture after the shirt): the spec lists its
    assets in that order, and a rebuilt scene should be the same model.
    """
    skin = _material(spec, prefix + "skin", look.skin, 0.15, 0.2)
    skin_dark_rgba = tuple(0.82 * c for c in look.skin[:3]) + (1.0,)
    skin_dark = _material(spec, prefix + "skin_dark", skin_dark_rgba, 0.15, 0.2)
    hair = _material(spec, prefix + "hair", look.hair, 0.1, 0.3)
    shoes = _material(spec, prefix + "shoes", look.shoes, 0.3, 0.4)
    trousers = _material(spec, prefix + "trousers", look.trousers, 0.05, 0.1)
    shirt = _material(spec, prefix + "shirt", look.shirt, 0.05, 0.1)
    if look.shirt_pattern == "checker":
        _check_the_shirt(spec, look, prefix, shirt)
    return Materials(
        skin=skin,
        skin_dark=skin_dark,
        hair=hair,
        shoes=shoes,
        trousers=trousers,
        shirt=shirt,
        eye_white=_material(spec, prefix + "eye_white", (0.95, 0.95, 0.93, 1.0), 0.4, 0.6),
        iris=_material(spec, prefix + "iris", (0.12, 0.08, 0.05, 1.0), 0.5, 0.8),
        lips=_material(spec, prefix + "lips", (0.62, 0.28, 0.28, 1.0), 0.2, 0.3),
        arm=shirt if look.long_sleeves else skin,
    )


def _material(spec: mujoco.MjSpec, name: str, rgba: RGBA, specular: float, shininess: float) -> str:
    """Add one plain material and return its name (what a geom refers to it by)."""
    mat = spec.add_material(name=name)
    mat.rgba = list(rgba)
    mat.specular = specular
    mat.shininess = shininess
    return name


def _check_the_shirt(spec: mujoco.MjSpec, look: MannequinSpec, prefix: str, shirt: str) -> None:
    """Turn the shirt material into a two-tone check of the shirt colour and a paler one.

    A pattern breaks up the torso's flat colour, the way real clothes often do (the
    "checker" clothing preset). The texture carries the colour, so the material itself
    goes white.
    """
    tex = spec.add_texture(
        name=prefix + "shirt_check",
        type=mujoco.mjtTexture.mjTEXTURE_2D,
        builtin=mujoco.mjtBuiltin.mjBUILTIN_CHECKER,
        width=64,
        height=64,
        rgb1=list(look.shirt[:3]),
        rgb2=[0.55 * c + 0.45 for c in look.shirt[:3]],
    )
    mat = spec.material(shirt)
    mat.rgba = [1.0, 1.0, 1.0, 1.0]
    mat.texuniform = True
    mat.texrepeat = [8.0, 8.0]
    textures = [""] * int(mujoco.mjtTextureRole.mjNTEXROLE)
    textures[int(mujoco.mjtTextureRole.mjTEXROLE_RGB)] = tex.name
    mat.textures = textures
