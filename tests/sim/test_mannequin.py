"""The mannequin's parts agree: every name under the prefix, each landmark on its own limb."""

from __future__ import annotations

import mujoco
import pytest

from sim.scenario.spec import MannequinSpec
from sim.world.mannequin import BLAZEPOSE_NAMES, N_LANDMARKS, Mannequin, build_mannequin

# Body part each BlazePose landmark must hang from ("{s}" is the landmark's side).
PART = {
    "shoulder": "upper_arm_{s}",
    "elbow": "forearm_{s}",
    "wrist": "hand_{s}",
    "pinky": "hand_{s}",
    "index": "hand_{s}",
    "thumb": "hand_{s}",
    "hip": "thigh_{s}",
    "knee": "shin_{s}",
    "ankle": "foot_{s}",
    "heel": "foot_{s}",
    "foot_index": "foot_{s}",
}


def _two_mannequins() -> mujoco.MjModel:
    spec = mujoco.MjSpec()
    build_mannequin(spec, MannequinSpec.adult(shirt_pattern="checker"), "a_")
    build_mannequin(spec, MannequinSpec.child(long_sleeves=True), "b_")
    return spec.compile()


def _names(model: mujoco.MjModel, kind: str, count: int) -> list[str]:
    return [getattr(model, kind)(i).name for i in range(count)]


def test_every_part_names_its_elements_under_the_prefix() -> None:
    model = _two_mannequins()
    kinds = {
        "body": model.nbody,
        "joint": model.njnt,
        "geom": model.ngeom,
        "site": model.nsite,
        "material": model.nmat,
        "texture": model.ntex,
    }
    for kind, count in kinds.items():
        names = [n for n in _names(model, kind, count) if n != "world"]
        assert all(n.startswith(("a_", "b_")) for n in names), (kind, names)
        if kind != "texture":  # only the checked shirt has one
            a = [n[2:] for n in names if n.startswith("a_")]
            b = [n[2:] for n in names if n.startswith("b_")]
            assert a == b, kind
    sites = _names(model, "site", model.nsite)
    # Model order is body order (left arm before right), so compare as a set.
    assert sorted(n for n in sites if n.startswith("a_")) == [f"a_lm{i:02d}" for i in range(33)]
    assert N_LANDMARKS == 33


@pytest.mark.parametrize("index", range(N_LANDMARKS))
def test_each_landmark_sits_on_its_own_body_part(index: int) -> None:
    model = _two_mannequins()
    mannequin = Mannequin(model, MannequinSpec.adult(), "a_")
    name = BLAZEPOSE_NAMES[index]
    body = model.body(model.site_bodyid[mannequin.landmark_sites[index]]).name
    side, _, joint = name.partition("_")
    expected = "head" if joint not in PART else PART[joint].format(s=side[0])
    if index <= 10:
        assert joint not in PART, name  # the face: nose, eyes, ears, mouth
    assert body == "a_" + expected, name
