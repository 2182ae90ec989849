"""The reference rule cascade, constant velocity, extrapolation and the warning variants."""

import numpy as np
import pytest

from monopic.camera import CameraModel
from monopic.cases import Case
from monopic.features.record import Features, GroundFeatures
from monopic.frame import EgoState
from monopic.predict.base import Mode, extrapolate_image
from monopic.predict.constant_velocity import ConstantVelocityPredictor
from monopic.predict.rules import RulePredictor, image_rule_case
from monopic.variants.path import project_path
from monopic.variants.warning import CollisionWarning, Risk

CAM = CameraModel.from_fov(768, 432, 70, 1.0, pitch_deg=5)


def feats(vx=0.0, vy=0.0, center=(400.0, 200.0), height=150.0, ground=None):
    foot = (center[0], center[1] + height / 2)
    return Features(1.0, center, foot, height, 10.0, vx, vy, ground)


@pytest.mark.parametrize(
    "vx, vy, case",
    [
        (50, -50, Case.OBLIQUE_RIGHT_AWAY),
        (-50, -50, Case.OBLIQUE_LEFT_AWAY),
        (50, 50, Case.OBLIQUE_RIGHT_TOWARD),
        (-50, 50, Case.OBLIQUE_LEFT_TOWARD),
        (50, 5, Case.PERPENDICULAR_RIGHT),
        (-50, -19, Case.PERPENDICULAR_LEFT),
        (0, 50, Case.TOWARD),
        (10, -50, Case.AWAY),
        (19.9, -19.9, Case.STILL),
        (float("nan"), 0, Case.STILL),
    ],
)
def test_rule_cascade_dead_zone_20(vx, vy, case):
    assert image_rule_case(vx, vy) is case


def test_extrapolation_keeps_only_the_case_axes():
    f = feats(vx=60, vy=8)
    p = extrapolate_image(f, Case.PERPENDICULAR_RIGHT, 1.0)
    assert p.center == (460.0, 200.0)
    p2 = RulePredictor().predict(f, 0.5)
    assert p2.case is Case.PERPENDICULAR_RIGHT and p2.center == (430.0, 200.0)


def test_constant_velocity_keeps_every_component():
    p = ConstantVelocityPredictor().predict(feats(vx=60, vy=8), 1.0)
    assert p.center == (460.0, 208.0)


def _ground(pos, vel):
    return GroundFeatures(position=pos, velocity=vel, camera=CAM)


def test_ground_mode_rules_predict_in_the_robot_frame():
    f = feats(ground=_ground((6.0, 2.0), (0.05, -1.4)))
    p = RulePredictor(mode=Mode.GROUND).predict(f, 1.0)
    assert p.case is Case.PERPENDICULAR_RIGHT
    assert p.ground == pytest.approx((6.0, 0.6))
    assert p.foot == pytest.approx(tuple(CAM.project(np.array([6.0, 0.6, 0.0]))))
    with pytest.raises(ValueError):
        RulePredictor(mode=Mode.GROUND).predict(feats(), 1.0)


def test_ground_warning_for_a_pedestrian_walking_into_the_path():
    ego = EgoState(CAM, speed=2.0)
    f = feats(ground=_ground((2.0, 1.5), (0.0, -1.4)))
    p = RulePredictor(mode=Mode.GROUND).predict(f, 1.0)
    w = CollisionWarning().assess(f, p, Mode.GROUND, (768, 432), ego)
    assert w.collision and w.risk is Risk.RED and w.time_to_contact is not None
    far = feats(ground=_ground((9.0, 1.5), (0.0, -1.4)))
    pf = RulePredictor(mode=Mode.GROUND).predict(far, 1.0)
    assert not CollisionWarning().assess(far, pf, Mode.GROUND, (768, 432), ego).collision


def test_image_warning_zone_and_risk_levels():
    ego = EgoState(CAM, speed=1.0)
    warn = CollisionWarning()
    zone = warn.zone_for((768, 432), ego, 1.0)
    # A pedestrian whose predicted foot point lands in the middle of the zone.
    inside = tuple(zone.mean(axis=0))
    f = Features(1.0, (inside[0], inside[1] - 60), inside, 120.0, 0.0, 0.0, 0.0)
    p = RulePredictor().predict(f, 1.0)
    w = warn.assess(f, p, Mode.IMAGE, (768, 432), ego)
    assert w.collision and w.risk is Risk.RED
    big = Features(1.0, (50.0, 100.0), (50.0, 330.0), 300.0, 0.0, 0.0, 0.0)
    assert warn.assess(
        big, RulePredictor().predict(big, 1.0), Mode.IMAGE, (768, 432), ego
    ).risk is (Risk.YELLOW)
    small = Features(1.0, (50.0, 100.0), (50.0, 150.0), 100.0, 0.0, 0.0, 0.0)
    assert warn.assess(
        small, RulePredictor().predict(small, 1.0), Mode.IMAGE, (768, 432), None
    ).risk is (Risk.GREEN)


def test_path_projection_finds_the_conflict_point():
    zone = np.array([[300, 300], [468, 300], [468, 432], [300, 432]], dtype=float)
    f = feats(vx=-100, vy=0, center=(700.0, 280.0), height=80.0)  # foot at v = 320
    p = RulePredictor().predict(f, 1.0)
    path = project_path(f, p, zone, length=4.0, steps=16)
    assert path.conflict_index is not None
    assert 2.0 <= path.conflict_time <= 3.0  # foot reaches u = 468 after 2.32 s


def test_every_predictor_calls_itself_by_its_registry_name():
    """Results, reports and closed-loop --policies all say '<registry name>/<mode>'."""
    from monopic.errors import UserError
    from monopic.predict.registry import make_predictor, predictor_names

    assert {"rules", "tree", "constant-velocity"} <= set(predictor_names())
    built = 0
    for name in predictor_names():
        for mode in Mode:
            try:
                predictor = make_predictor(name, mode)
            except UserError as err:  # the shipped tree is an image-mode tree
                if name == "intent-tree":  # the shipped ground tree is ground mode only
                    assert "ground mode only" in str(err) and mode is Mode.IMAGE
                    continue
                assert name == "tree" and "ground mode" in str(err)
                continue
            assert predictor.name == name and predictor.mode is mode
            built += 1
    assert built >= 6  # intent-tree/ground from the shipped ground tree included


def liar(mode, model):
    """A plug-in factory whose predictor calls itself by another name."""
    return RulePredictor(mode)


def test_a_predictor_named_otherwise_than_its_entry_point_is_refused(monkeypatch):
    from importlib.metadata import EntryPoint

    from monopic.errors import UserError
    from monopic.predict import registry

    entry = EntryPoint("mine", f"{__name__}:liar", registry.PREDICTOR_GROUP)
    monkeypatch.setattr(registry, "_registered", lambda: {"mine": entry})
    with pytest.raises(UserError, match="'mine' .* calls itself 'rules'"):
        registry.make_predictor("mine", Mode.IMAGE)
    with pytest.raises(UserError, match="unknown predictor 'id3-tree': choose from mine"):
        registry.make_predictor("id3-tree", Mode.IMAGE)
