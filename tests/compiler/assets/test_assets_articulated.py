"""Articulated assets: the URDF templates render, parse, and move the right way."""

from __future__ import annotations

import io
import xml.etree.ElementTree as ET

import jinja2
import numpy as np
import pytest
from fsvla.compiler.assets import build_asset
from fsvla.compiler.assets.articulated import TEMPLATE_DIR, render_urdf
from fsvla.compiler.assets.urdf import UrdfError, parse_urdf
from fsvla.compiler.pose import axis_angle_matrix, pose_matrix

EXPECTED = {  # kind -> (part, joint type, lower, upper)
    "drawer_cabinet": ("drawer", "prismatic", 0.0, 0.2),
    "microwave": ("door", "revolute", 0.0, np.radians(110)),
    "lidded_box": ("lid", "revolute", 0.0, np.radians(110)),
}


def test_templates_ship_next_to_the_module():
    names = {p.name for p in TEMPLATE_DIR.glob("*.urdf.j2")}
    assert {f"{kind}.urdf.j2" for kind in EXPECTED} <= names


@pytest.mark.parametrize("kind", list(EXPECTED))
def test_urdf_parses_and_links_and_joints_are_consistent(kind):
    asset = build_asset(kind)
    robot = ET.fromstring(asset.urdf)
    assert robot.tag == "robot" and robot.get("name") == kind
    links = {link.get("name") for link in robot.findall("link")}
    joints = robot.findall("joint")
    assert len(links) == len(robot.findall("link"))
    children = [j.find("child").get("link") for j in joints]
    for joint in joints:
        assert joint.find("parent").get("link") in links
        assert joint.find("child").get("link") in links
    assert len(links - set(children)) == 1  # one root
    for collision in robot.iter("collision"):
        assert [g.tag for g in collision.find("geometry")] == ["box"]
    for inertial in robot.iter("inertial"):
        assert float(inertial.find("mass").get("value")) > 0


@pytest.mark.parametrize("kind", list(EXPECTED))
def test_parts_name_their_joint_and_limits(kind):
    asset = build_asset(kind)
    part_name, joint_type, lower, upper = EXPECTED[kind]
    part = asset.part(part_name)
    joint = next(j for j in asset.joints if j.name == part.joint)
    assert (joint.type, joint.child, joint.parent) == (joint_type, part.link, asset.root_link)
    assert (joint.lower, joint.upper) == pytest.approx((lower, upper))
    assert asset.fixed_base
    with pytest.raises(KeyError, match="no part"):
        asset.part("handle")


def _part_centre(asset, part_name, q):
    """World centre of a part's collision boxes with its joint at q."""
    part = asset.part(part_name)
    joint = next(j for j in asset.joints if j.name == part.joint)
    motion = np.eye(4)
    if joint.type == "prismatic":
        motion[:3, 3] = np.asarray(joint.axis) * q
    else:
        motion[:3, :3] = axis_angle_matrix(joint.axis, q)
    transform = pose_matrix(joint.origin) @ motion
    link = next(item for item in asset.links if item.name == part.link)
    centres = [transform @ np.r_[s.pose.position, 1.0] for s in link.collision]
    return np.mean(centres, axis=0)[:3]


@pytest.mark.parametrize(
    ("kind", "direction"),
    [
        ("drawer_cabinet", (-1, 0, 0)),
        ("microwave", (-1, 0, 0)),
        ("lidded_box", (0, 0, 1)),
    ],
)
def test_opening_moves_the_part_out_of_the_front_or_up(kind, direction):
    asset = build_asset(kind)
    part_name, _, _, upper = EXPECTED[kind]
    moved = _part_centre(asset, part_name, upper) - _part_centre(asset, part_name, 0.0)
    assert np.dot(moved, direction) > 0.05


def test_size_and_travel_parameters_shape_the_urdf():
    # size is (x, y, z): depth along x (the front faces -x), width along y
    asset = build_asset("drawer_cabinet", {"size": (0.5, 0.6, 0.3), "travel": 0.3})
    assert asset.bounds.half_extents[1] == pytest.approx(0.3)
    assert next(j for j in asset.joints if j.name == "drawer_joint").upper == pytest.approx(0.3)
    with pytest.raises(ValueError, match="exceeds the drawer's depth"):
        build_asset("drawer_cabinet", {"size": (0.2, 0.4, 0.25), "travel": 0.3})


FRONT = {  # kind -> the part and its piece that sit on the front (-x) face
    "drawer_cabinet": ("drawer", "handle"),
    "microwave": ("door", "handle"),
    "lidded_box": ("lid", "knob"),
}


@pytest.mark.parametrize("kind", list(EXPECTED))
def test_the_front_faces_the_robot_at_minus_x(kind):
    asset = build_asset(kind)
    part_name, piece = FRONT[kind]
    part = asset.part(part_name)
    link = next(item for item in asset.links if item.name == part.link)
    joint = next(j for j in asset.joints if j.name == part.joint)
    (shape,) = [s for s in link.collision if s.name == piece]
    centre = (pose_matrix(joint.origin) @ np.r_[shape.pose.position, 1.0])[:3]
    depth, width, _ = asset.params["size"]
    # the handle or knob is the frontmost piece, beyond the -x face, centred or to one side
    assert centre[0] - shape.half_size[0] == pytest.approx(asset.footprint.min_xy[0])
    assert centre[0] < -depth / 2.0
    assert abs(centre[1]) < width / 2.0


@pytest.mark.parametrize(
    ("kind", "hinge", "axis"),
    [
        ("microwave", (-1, 1), (0, 0, -1)),  # vertical hinge on the left (+y) front edge
        ("lidded_box", (1, 0), (0, 1, 0)),  # horizontal hinge along the back (+x) top edge
    ],
)
def test_hinges_sit_on_the_named_edge(kind, hinge, axis):
    asset = build_asset(kind)
    (joint,) = [j for j in asset.joints if j.type == "revolute"]
    assert joint.axis == pytest.approx(axis)
    size = asset.params["size"]
    expected = [sign * extent / 2.0 for sign, extent in zip(hinge, size[:2])]
    assert joint.origin.position[:2] == pytest.approx(expected)


def test_rendering_with_a_missing_variable_fails_loudly():
    with pytest.raises(jinja2.UndefinedError):
        render_urdf("lidded_box", size=(0.2, 0.15, 0.1))


@pytest.mark.parametrize(
    ("urdf", "message"),
    [
        ("<robot name='r'><link name='a'/><link name='a'/></robot>", "used twice"),
        (
            (
                "<robot name='r'><link name='a'/><joint name='j' type='fixed'><parent link='a'/>"
                "<child link='b'/></joint></robot>"
            ),
            "not defined",
        ),
        ("<robot name='r'><link name='a'/><link name='b'/></robot>", "exactly one root"),
        (
            (
                "<robot name='r'><link name='a'/><link name='b'/><joint name='j' type='revolute'>"
                "<parent link='a'/><child link='b'/></joint></robot>"
            ),
            "needs a <limit>",
        ),
        (
            (
                "<robot name='r'><link name='a'/><link name='b'/><joint name='j' type='planar'>"
                "<parent link='a'/><child link='b'/></joint></robot>"
            ),
            "unsupported type",
        ),
        ("<robot name='r'><link name='a'>", "not well-formed"),
        ("<!DOCTYPE r [<!ENTITY x 'y'>]><robot name='r'/>", "DOCTYPE"),
    ],
)
def test_urdf_checker_rejects_broken_structure(urdf, message):
    with pytest.raises(UrdfError, match=message):
        parse_urdf(urdf)


@pytest.mark.parametrize("kind", list(EXPECTED))
def test_generated_urdf_validates_with_yourdfpy_when_installed(kind):
    yourdfpy = pytest.importorskip("yourdfpy")
    robot = yourdfpy.URDF.load(io.StringIO(build_asset(kind).urdf), load_meshes=False)
    assert robot.validate()
    assert robot.actuated_joint_names == [f"{EXPECTED[kind][0]}_joint"]


@pytest.mark.parametrize("kind", list(EXPECTED))
def test_a_part_starts_open_by_the_fraction_asked(kind):
    part, _type, lower, upper = EXPECTED[kind]
    joint = build_asset(kind).part(part).joint
    assert build_asset(kind).start_positions() == {}  # without `open`: every joint at 0
    assert build_asset(kind, {"open": 0.25}).start_positions() == {
        joint: pytest.approx(lower + 0.25 * (upper - lower))}


def test_the_bounds_hold_a_part_that_starts_open():
    shut = build_asset("drawer_cabinet", {"travel": 0.1})
    opened = build_asset("drawer_cabinet", {"travel": 0.1, "open": 0.8})
    # the drawer slides out along -x by 8 cm: the bounds reach that much further
    shut_lo = shut.bounds.center[0] - shut.bounds.half_extents[0]
    open_lo = opened.bounds.center[0] - opened.bounds.half_extents[0]
    assert open_lo == pytest.approx(shut_lo - 0.08)
    assert opened.bounds.half_extents[1:] == pytest.approx(shut.bounds.half_extents[1:])
    lid = build_asset("lidded_box", {"open": 0.9})
    assert lid.bounds.half_extents[2] > 2 * build_asset("lidded_box").bounds.half_extents[2]


def test_without_open_a_joint_whose_range_starts_below_zero_starts_at_zero():
    from fsvla.compiler.assets.model import Joint, start_positions

    joints = [Joint(name="hinge", type="revolute", parent="a", child="b", lower=-1.0, upper=1.0)]
    assert start_positions(joints, ["hinge"], {}) == {}
    assert start_positions(joints, ["hinge"], {"open": 0.5}) == {"hinge": pytest.approx(0.0)}
    assert start_positions(joints, ["hinge"], {"open": 1.0}) == {"hinge": pytest.approx(1.0)}


def test_a_door_swings_clear_of_what_its_body_stands_on():
    """The microwave's door stood on the table (its panel ran down to the body's base), so
    it dragged its weight across the table as it swung: a hand swinging or pushing it
    felt 10-25 N."""
    asset = build_asset("microwave", {"size": (0.42, 0.33, 0.26)})
    part = asset.part("door")
    link = next(item for item in asset.links if item.name == part.link)
    joint = next(j for j in asset.joints if j.name == part.joint)
    origin = pose_matrix(joint.origin)
    for shape in link.collision:
        corners = [np.r_[shape.pose.position, 1.0] + np.r_[sx, sy, sz, 0.0] * np.r_[shape.half_size, 0.0]
                   for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]
        lowest = min((origin @ c)[2] for c in corners)
        assert lowest >= 0.002, shape.name
