"""faultgen's xacro expander (faultgen.model.xacro): the xacro robot descriptions use, expanded as
xacro does (tests/test_hostile_robots.py compares it with xacrodoc on rtb-data's files), and the
bounds that keep a hostile file from exhausting memory or recursing for ever."""

import re
import xml.etree.ElementTree as ET

import pytest

from faultgen.model import xacro
from faultgen.model.builder import ArmError

NS = 'xmlns:xacro="http://www.ros.org/wiki/xacro"'


def expand(tmp_path, body, **files):
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    source = tmp_path / "top.xacro"
    source.write_text(f'<robot name="r" {NS}>{body}</robot>')
    return ET.fromstring(xacro.expand(source))


def names(root, tag="link"):
    return [e.get("name") for e in root.iter(tag)]


def test_properties_macros_blocks_conditions_and_args(tmp_path):
    root = expand(
        tmp_path,
        '<xacro:property name="L" value="${2 * h}"/><xacro:property name="h" value="0.25"/>'
        '<xacro:property name="blk"><inertial/></xacro:property>'
        '<xacro:arg name="side" default="left"/>'
        '<xacro:macro name="m" params="n k:=3 s:=^ *first **rest">'
        '<link name="${n}_${k}_${s}_${L}"><xacro:insert_block name="first"/><xacro:insert_block name="rest"/>'
        '<xacro:insert_block name="blk"/></link>'
        '<xacro:property name="up" value="${k + 1}" scope="parent"/></xacro:macro>'
        '<xacro:property name="s" value="\'out\'"/>'
        '<xacro:m n="a"><visual/><collision/><collision/></xacro:m>'
        '<link name="after_${up}"/>'
        '<xacro:if value="${L > 0.4 and not False}"><link name="if_$(arg side)"/></xacro:if>'
        '<xacro:unless value="1"><link name="never"/></xacro:unless>'
        '<link name="${radians(180) == pi} ${max(1, 2)} ${1 if h &lt; 1 else 2} $${literal}"/>',
    )
    assert names(root) == ["a_3_out_0.5", "after_4", "if_left", "True 2 1 ${literal}"]
    link = root.find("link")
    assert [c.tag for c in link] == ["visual", "collision", "collision", "inertial"]


@pytest.mark.parametrize(
    "body, message",
    [
        ('<link name="${__import__(\'os\')}"/>', "function __import__()"),
        ('<link name="${[1][0]}"/>', "subscript"),
        ('<link name="${\'a\' * 100}"/>', "Mult"),
        ('<link name="${(lambda: 1)()}"/>', "function"),
        ('<link name="${open(\'x\')}"/>', "function open()"),
        ('<link name="${10 ** 400}"/>', "Numerical result out of range"),
        ('<link name="${undefined}"/>', "no property 'undefined'"),
        ('<xacro:include filename="x.xacro" ns="n"/>', "only filename"),
        ('<xacro:call macro="m"/>', "<xacro:call>"),
        ('<xacro:element xacro:name="link"/>', "<xacro:element>"),
        ('<xacro:property name="a" value="${a}"/><link name="${a}"/>', "in terms of itself"),
        ('<xacro:macro name="m" params=""><xacro:m/></xacro:macro><xacro:m/>', "nested macro calls"),
    ],
)
def test_what_it_does_not_take_is_refused_naming_the_construct(tmp_path, body, message):
    with pytest.raises(ArmError, match=r"top\.xacro: .*" + re.escape(message)):
        expand(tmp_path, body)


def test_a_file_that_expands_exponentially_is_refused(tmp_path):
    # 2^40 links from 40 macros each calling the one below twice
    macros = '<xacro:macro name="m0" params=""><link name="x"/></xacro:macro>' + "".join(
        f'<xacro:macro name="m{k}" params=""><xacro:m{k - 1}/><xacro:m{k - 1}/></xacro:macro>' for k in range(1, 41)
    )
    with pytest.raises(ArmError, match=f"more than {xacro.MAX_ELEMENTS} elements"):
        expand(tmp_path, macros + "<xacro:m40/>")


def test_a_file_that_includes_itself_is_refused(tmp_path):
    with pytest.raises(ArmError, match="includes itself"):
        expand(tmp_path, '<xacro:include filename="top.xacro"/>')


@pytest.mark.parametrize(
    "body, message",
    [
        # properties doubling a string: 2^40 characters
        ('<xacro:property name="p0" value="ab"/>'
         + "".join(f'<xacro:property name="p{k}" value="${{p{k - 1} + p{k - 1}}}"/>' for k in range(1, 41))
         + '<link name="${p40}"/>', "a string of more than"),
        ('<link name="${' + "+".join(["1"] * 100_000) + '}"/>', "nested too deeply"),
        ("".join(f'<xacro:property name="q{k}" value="${{q{k - 1}}}"/>' for k in range(1, 20_000))
         + '<xacro:property name="q0" value="1"/><link name="${q19999}"/>', "nested too deeply"),
        ('<link name="${' + "*".join(["99999999999"] * 40) + '}"/>', ""),
    ],
)
def test_expressions_that_would_grow_without_bound_are_refused_or_kept_small(tmp_path, body, message):
    if message:
        with pytest.raises(ArmError, match=message):
            expand(tmp_path, body)
    else:  # a product of large integers becomes a float, refused as out of range past 1e308
        with pytest.raises(ArmError, match="out of range"):
            expand(tmp_path, body)
