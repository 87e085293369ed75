"""The drivetrain sizing rules are versioned (faultgen.model.sizing.RULE_VERSIONS): rule 1, faultgen's
peak-torque rule before the rated load sized the drives (issue 60, part 3), stays available bit for bit,
so that the benchmark's frozen track versions, whose third-party robots were added with it, stay
makeable; rule 2 is ``robots add``'s default. A robot folder records the rule that sized it, and a
track version names its rule (``sizing``; rule 1 when it names none).
"""

import warnings

import pytest
from test_bench import TINY
from test_robot_import import PACKAGES, URDFS

from faultgen.bench import make, tracks
from faultgen.model import folder, importers, sizing


def kr210():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", importers.GeometryDropped)
        return importers.read(URDFS["kr210"], PACKAGES)


def test_rule_1_gives_the_old_sizing_numbers_and_rule_2_the_new():
    """rtb-data's KR210 L150 URDF (effort limits 0: none; rated payload guessed, 496 kg) sized by the
    code before rule 2 (commit ea0ea65^, ``sizing.size(arm)``; the same numbers are in the
    ``drivetrain.toml`` that ``faultgen robots add kr210`` wrote there): motor torque limits of axes 1,
    2 and 6 267.6254948979878, 436.7003153914853 and 2.975898707460459 N m, gear ratio of axis 2
    234.16535330834876. Rule 2 (ea0ea65) gives axis 2 691.3109827496692 N m."""
    arm = kr210()
    old = sizing.sized(arm, rule=1)
    assert old.rule == 1 and old.loads is None
    limits = [axis.motor_torque_limit for axis in old.drivetrain.axes]
    assert limits[0] == 267.6254948979878 and limits[1] == 436.7003153914853 and limits[5] == 2.975898707460459
    assert old.drivetrain.axes[1].gear_ratio == 234.16535330834876
    assert old.drivetrain.axes[1].coulomb_pos == sizing.COULOMB_SHARE * 436.7003153914853
    assert "1.5 x max gravity torque" in old.origin[2]["motor_torque_limit"]
    new = sizing.sized(arm)  # the default: rule 2
    assert new.rule == sizing.RULE == 2
    assert new.drivetrain.axes[1].motor_torque_limit == 691.3109827496692
    assert sizing.size(arm, rule=1)[0] == old.drivetrain
    with pytest.raises(ValueError, match=r"sizing rule 3: expected one of 1, 2"):
        sizing.sized(arm, rule=3)


def test_a_robot_folder_records_the_rule_that_sized_it(tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", importers.GeometryDropped)
        one = folder.add("kr210", URDFS["kr210"], tmp_path / "one", packages=PACKAGES, rule=1)
        two = folder.add("kr210", URDFS["kr210"], tmp_path / "two", packages=PACKAGES)
    assert (one.rule, two.rule) == (1, 2)
    assert folder.sizing_rule(one.folder) == 1 and folder.sizing_rule(two.folder) == 2
    assert "by sizing rule 1 (faultgen.model.sizing.RULE_VERSIONS): the peak-torque rule" in (
        one.folder / "README.md").read_text()
    assert one.robot.motor_torque_limit[1] == 436.7003153914853  # the numbers of the test above
    assert two.robot.motor_torque_limit[1] == 691.3109827496692
    assert folder.sizing_rule(tmp_path) is None  # a folder without drivetrain.toml records none
    with pytest.raises(ValueError, match="sizing rule 0"):
        folder.add("kr210", URDFS["kr210"], tmp_path / "zero", packages=PACKAGES, rule=0)


TRACK = TINY.format(robot="irb6700") + """
[[versions]]
version = 2
like = 1
sizing = 2

[[versions]]
version = 3
like = 2
"""


def test_a_track_version_names_its_sizing_rule_and_rule_1_without():
    import tomllib

    assert tracks.SIZING_RULES == tuple(sizing.RULE_VERSIONS)
    track = tracks.parse(tomllib.loads(TRACK), "t.toml")
    assert [track.versions[n].sizing for n in (1, 2, 3)] == [1, 2, 2]  # like takes it with the recipe
    for bad in ("3", "true", '"2"'):
        with pytest.raises(ValueError, match=r"t.toml: version 2: sizing = .*: expected one of 1, 2"):
            tracks.parse(tomllib.loads(TRACK.replace("sizing = 2", f"sizing = {bad}")), "t.toml")
    for name in tracks.names():  # every version frozen so far was made with rule 1
        for version in tracks.load(name).versions.values():
            assert version.sizing == 1, (name, version.number)


def test_bench_make_adds_a_versions_robots_with_its_rule(tmp_path):
    recipe = tracks.load("sim-to-real").version(1)
    added = make.add_robots(recipe, tmp_path / "robots")
    assert folder.sizing_rule(added["kr210"]) == 1
    from faultgen.model import robots

    assert robots.load(added["kr210"]).motor_torque_limit[1] == 436.7003153914853
    assert not make._other_sizing(recipe, tmp_path / "robots")
    two = tracks.Version(number=9, parts=recipe.parts, train_seeds=[0], test_seeds=[1], robots=recipe.robots,
                         sizing=2)
    assert make._other_sizing(two, tmp_path / "robots") == ["kr210"]  # a make would not resume these runs
