"""A grasped sphere twisted about the gripper's axis (issue 26 item 5): bendpam.design.twist."""

import json
import math

import pytest

from bendpam.design import Gripper
from bendpam.design.twist import grasp_twist
from bendpam.errors import InputError
from bendpam.physics.presets import bc_pam, be_pam


def _gripper(act):
    return Gripper(act.replace(L0_mm=130.0), nodes=21)


def test_be_fingers_distort_more_per_newton_than_bc_fingers():
    be = grasp_twist(_gripper(be_pam()), 180.0, 150.0, fractions=(0.5, 1.0))
    bc = grasp_twist(_gripper(bc_pam()), 180.0, 120.0, fractions=(0.5, 1.0))
    for tw in (be, bc):
        assert tw.lost_by == "friction"
        g = tw.grasp
        # the torque at the loss is the friction limit of every finger at its contact radius, by definition
        assert tw.torque_at_loss_nmm == pytest.approx(3 * 0.5 * g.normal_force_n * tw.contact_radius_mm, rel=1e-12)
        s1, s2 = tw.steps
        assert s2["contact_lateral_mm"] == pytest.approx(2 * s1["contact_lateral_mm"], rel=0.05)  # nearly linear
        assert s2["object_rotation_deg"] == pytest.approx(math.degrees(math.atan2(s2["contact_lateral_mm"],
                                                                                     tw.contact_radius_mm)))
    # the paper's finding, as a number: a BE-PAM finger gives more per newton across its plane
    assert be.lateral_compliance_mm_per_n > 1.5 * bc.lateral_compliance_mm_per_n
    d = be.to_dict()
    json.dumps(d)
    assert d["lost_by"] == "friction" and d["object_rotation_deg"] > 0


def test_the_lock_holds_the_twist_and_without_it_the_fingers_twist():
    locked = grasp_twist(_gripper(be_pam()), 180.0, 150.0, fractions=(1.0,))
    free = grasp_twist(_gripper(be_pam()), 180.0, 150.0, fractions=(1.0,), sleeve_lock=False)
    assert locked.at_loss["twist_deg"] == 0.0
    assert abs(free.at_loss["twist_deg"]) > 0.1
    assert abs(free.at_loss["contact_lateral_mm"]) > abs(locked.at_loss["contact_lateral_mm"])


def test_no_grasp_and_bad_fractions():
    tw = grasp_twist(_gripper(be_pam()), 120.0, 150.0)  # too small: the fingers do not reach it
    assert tw.lost_by == "no grasp" and tw.steps == () and "too small" in tw.note
    with pytest.raises(InputError, match="fractions"):
        grasp_twist(_gripper(be_pam()), 180.0, 150.0, fractions=(0.5, 0.2))


def test_cli_grasp_twist(capsys):
    from bendpam.cli import main

    # a sphere too small for the fingers: the twist says there is no grasp (cheap); the numbers: the API tests
    assert main(["grasp", "--preset", "be-pam", "--l0-mm", "130", "--diameter-mm", "120", "--pressure-kpa", "150",
                 "--twist", "--json"]) == 0
    res = json.loads(capsys.readouterr().out)["results"][0]
    assert res["twist"]["lost_by"] == "no grasp" and res["twist"]["torque_at_loss_nmm"] == 0.0
    assert main(["grasp", "--preset", "be-pam", "--diameter-mm", "80:280:7", "--pressure-kpa", "100", "150",
                 "--twist"]) == 2
    assert "--twist" in capsys.readouterr().err
