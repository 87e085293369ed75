"""Expand a xacro file to URDF without running code: faultgen's own restricted expander.

xacro's own processor (and ``xacrodoc``, which calls it) evaluates ``${...}`` with Python's
``eval`` behind a name filter that strings get past, and offers ``$(env)``, ``$(cwd)``,
``load_yaml`` and includes from anywhere: a xacro from a stranger could run commands and copy
files into the robot. This expander understands the part of xacro robot descriptions use and
refuses the rest, naming the construct and the file (:class:`~faultgen.model.builder.ArmError`):

- ``xacro:property`` (``value``, ``default``, a block as its body, ``scope="parent"|"global"``),
  looked up lazily as xacro does; ``xacro:arg`` with a literal default and ``$(arg name)``;
- ``xacro:macro`` with parameters ``p``, ``p:=default``, ``p:=^``, ``p:=^|default``, ``*block``
  and ``**blocks``; ``xacro:insert_block``; ``xacro:if`` / ``xacro:unless``;
- ``xacro:include`` of a file inside the top file's folder or a package folder the caller names
  (``$(find pkg)`` gives only those; ``$(dirname)`` the including file's folder); a relative name
  is resolved against the including file's folder;
- ``${expr}`` by an evaluator over Python's syntax tree that knows numbers, strings, ``True`` /
  ``False``, property names, ``+ - * / // % **``, comparisons, ``and or not``, ``a if c else b``,
  ``pi``, ``e`` and the math functions of :data:`FUNCTIONS` (also as ``math.NAME``): no attribute
  access, subscripts, keywords, comprehensions or lambdas, no other function.

Bounds: :data:`MAX_FILE_BYTES` per file, :data:`MAX_INCLUDE_DEPTH` nested includes,
:data:`MAX_ELEMENTS` elements in the expanded document, :data:`MAX_CALL_DEPTH` nested macro calls,
:data:`MAX_TEXT` characters in one evaluated string, :data:`MAX_EXPRESSION` characters in one
``${...}`` (checked before Python's parser sees it). The work in all: :data:`MAX_STEPS` macro calls,
block insertions and includes, which copy or read at most :data:`MAX_COPIED` characters of xacro
(a macro's body once per call, a block once per insertion, a file once per include); and the
expanded document holds at most :data:`MAX_OUTPUT` characters. A file over a bound is refused
as it is reached, naming the file, the macro, block, include, element or expression, and the bound.
"""

from __future__ import annotations

import ast
import copy
import re
import xml.etree.ElementTree as ET
from pathlib import Path

from faultgen.inputs import inside
from faultgen.inputs import resolved as resolve
from faultgen.model.builder import ArmError
from faultgen.model.sources import hint, parse_xml, read_bytes
from faultgen.model.xacro_expressions import Undefined, evaluate, short

MAX_FILE_BYTES = 10_000_000
MAX_INCLUDE_DEPTH = 20
MAX_ELEMENTS = 50_000  # a 7-axis URDF has a few hundred; the link bound (mjcf.MAX_LINKS) is 500
MAX_CALL_DEPTH = 50
MAX_TEXT = 100_000
# rtb-data's 58 xacros (ABB, KUKA, Franka, Trossen, Clearpath, PUMA; 55 of which expand) need at most
# 13 macro calls + 6 block insertions + 4 includes (each at most 13, 6, 4), 36 000 characters copied
# or read, a 25 000-character URDF and 46 characters in one ${...}
MAX_STEPS = 10_000  # macro calls, block insertions and includes in all
MAX_COPIED = 20_000_000  # characters those copy or read: twice an included file's MAX_FILE_BYTES
MAX_OUTPUT = 10_000_000  # characters of the expanded URDF: a URDF file's own bound (sources.MAX_DESCRIPTION_BYTES)
MAX_EXPRESSION = 1_000  # characters in one ${...}: within what Python's parser nests without a MemoryError

def is_xacro_namespace(tag: str) -> bool:
    return tag.startswith("{") and tag[1 : tag.index("}")].rstrip("/#").endswith("xacro")


def _local(tag: str) -> str:
    return tag.split("}", 1)[1] if tag.startswith("{") else tag


class _Scope:
    """Properties (lazily evaluated text, or a block) with a parent scope, as xacro's ``Table``."""

    def __init__(self, parent: _Scope | None = None):
        self.parent, self.raw, self.done, self.busy = parent, {}, {}, set()

    def root(self) -> _Scope:
        return self if self.parent is None else self.parent.root()

    def define(self, name: str, value, evaluated: bool = False) -> None:
        self.raw[name] = value
        self.done.pop(name, None)
        if evaluated:
            self.done[name] = value

    def has(self, name: str) -> bool:
        return name in self.raw or (self.parent is not None and self.parent.has(name))

    def get(self, name: str, expander: _Expander):
        if name in self.done:
            return self.done[name]
        if name in self.raw:
            if name in self.busy:
                raise ArmError(f"{expander.where}: property {name!r} is defined in terms of itself")
            value = self.raw[name]
            if isinstance(value, str):
                self.busy.add(name)
                try:
                    value = _literal(expander.text(value, self))
                finally:
                    self.busy.discard(name)
            self.done[name] = value
            return value
        if self.parent is None:
            raise Undefined(name)
        return self.parent.get(name, expander)


def _literal(value):
    """A property's text as xacro takes it: quoted -> the string, else int, float or bool if it
    reads as one."""
    if not isinstance(value, str):
        return value
    if len(value) >= 2 and value[0] == value[-1] == "'":
        return value[1:-1]
    if "_" in value:
        return value
    for convert in (int, float):
        try:
            return convert(value)
        except ValueError:
            pass
    return {"true": True, "True": True, "false": False, "False": False}.get(value, value)


def _truth(value, where: str, what: str) -> bool:
    if isinstance(value, str):
        value = _literal(value.strip())
    if isinstance(value, (bool, int, float)) and not isinstance(value, str):
        return bool(value)
    raise ArmError(f"{where}: {what} = {value!r}; expected true, false, 1 or 0")


def _text_of(value) -> str:
    return str(value)


class _Expander:
    def __init__(self, top: Path, packages: dict[str, Path]):
        self.top = top
        self.roots = [top.parent.resolve(), *(Path(p).resolve() for p in packages.values())]
        self.packages = {name: Path(p).resolve() for name, p in packages.items()}
        self.files: list[Path] = []
        self.args: dict[str, str] = {}
        self.macros: dict[str, tuple[list, ET.Element, int]] = {}  # params, body, the body's _size
        self.elements = 0
        self.calls = 0
        self.steps = 0
        self.copied = 0
        self.output = 0

    @property
    def where(self) -> str:
        return str(self.files[-1] if self.files else self.top)

    def refuse(self, construct: str, why: str = "") -> ArmError:
        return ArmError(
            f"{self.where}: xacro {construct} refused{': ' + why if why else ''} (faultgen expands xacro "
            'without running code; docs/robots.md, "xacro", lists what it takes)'
        )

    def over(self, construct: str, why: str) -> ArmError:
        """A bound on the work or the output passed (no construct missing): the file, the construct
        where it was passed and the bound."""
        return ArmError(
            f"{self.where}: xacro {construct} refused: {why} (a bound of faultgen's xacro expander; "
            'docs/reliability.md, "Threat model: robot descriptions")'
        )

    # ---------------------------------------------------------------------- files --
    def parse(self, path: Path) -> ET.Element:
        if len(self.files) >= MAX_INCLUDE_DEPTH:
            raise self.refuse(f"include of {path}", f"more than {MAX_INCLUDE_DEPTH} nested includes")
        if path in self.files:
            raise self.refuse(f"include of {path}", "it includes itself")
        if self.files:  # an include: a step of the work, its bytes copied (the top file is read once)
            self.step(f"include of {path}")
        data = read_bytes(path, MAX_FILE_BYTES, "xacro file", ArmError)
        if self.files:
            self.copy(f"include of {path}", len(data))
        return parse_xml(data, path, ArmError)

    def step(self, construct: str) -> None:
        """One more macro call, block insertion or include (:data:`MAX_STEPS` in all)."""
        self.steps += 1
        if self.steps > MAX_STEPS:
            raise self.over(
                construct, f"the file needs more than {MAX_STEPS} macro calls, block insertions and includes in all"
            )

    def copy(self, construct: str, chars: int) -> None:
        """``chars`` more characters of xacro copied or read (:data:`MAX_COPIED` in all)."""
        self.copied += chars
        if self.copied > MAX_COPIED:
            raise self.over(
                construct,
                f"the file's macro calls, block insertions and includes copy more than {MAX_COPIED} characters "
                "of xacro in all",
            )

    def emit(self, node: ET.Element) -> None:
        """``node`` (expanded) is in the output: its characters count (:data:`MAX_OUTPUT` in all)."""
        self.output += _size(node, deep=False)
        if self.output > MAX_OUTPUT:
            raise self.over(f"<{_local(node.tag)}>", f"the expanded document holds more than {MAX_OUTPUT} characters")

    def resolve_include(self, name: str) -> Path:
        base = self.files[-1].parent
        path = Path(name) if Path(name).is_absolute() else base / name
        resolved = resolve(path)
        if not any(inside(resolved, root) for root in self.roots):
            raise self.refuse(
                f'include filename="{name}"',
                f"{resolved} is outside the xacro's folder {self.roots[0]} and the --package folders",
            )
        return resolved

    # ---------------------------------------------------------------------- text --
    def text(self, text: str, scope: _Scope):
        """Evaluate ``$(...)`` and ``${...}`` in ``text``: the value itself if the text is one
        ``${...}``, else the pieces joined as a string."""
        pieces = []
        i = 0
        while i < len(text):
            j = text.find("$", i)
            if j < 0 or j + 1 >= len(text):
                pieces.append(text[i:])
                break
            pieces.append(text[i:j])
            opener = text[j + 1]
            if opener == "$" and j + 2 < len(text) and text[j + 2] in "{(":  # $${ and $$( escape
                pieces.append(text[j + 1 : j + 3])
                i = j + 3
                continue
            if opener not in "{(":
                pieces.append("$")
                i = j + 1
                continue
            close = "}" if opener == "{" else ")"
            depth, k = 0, j + 1
            while k < len(text):
                depth += text[k] == opener
                depth -= text[k] == close
                if depth == 0:
                    break
                k += 1
            if depth:
                raise self.refuse(f"text {text!r}", f"unclosed ${opener}")
            inner = text[j + 2 : k]
            pieces.append(self.expression(inner, scope) if opener == "{" else self.substitution(inner, scope))
            i = k + 1
        pieces = [p for p in pieces if not (isinstance(p, str) and p == "")]
        if len(pieces) == 1:
            return pieces[0]
        out = "".join(_text_of(p) for p in pieces)
        if len(out) > MAX_TEXT:
            raise self.refuse(f"text {text[:60]!r}...", f"it evaluates to more than {MAX_TEXT} characters")
        return out

    def substitution(self, inner: str, scope: _Scope) -> str:
        words = inner.split()
        if not words:
            raise self.refuse("$()")
        command, rest = words[0], words[1:]
        if command == "arg" and len(rest) == 1:
            if rest[0] not in self.args:
                raise self.refuse(f"$(arg {rest[0]})", "no xacro:arg of that name (or no default) before it")
            return self.args[rest[0]]
        if command == "find" and len(rest) == 1:
            if rest[0] not in self.packages:
                raise ArmError(
                    f"{self.where}: xacro names package {rest[0]!r} ($(find {rest[0]})); give its folder "
                    f"with --package {rest[0]}=DIR" + hint(rest[0], self.top.parent)
                )
            return str(self.packages[rest[0]])
        if command == "dirname" and not rest:
            return str(self.files[-1].parent)
        raise self.refuse(f"$({inner})", f"$({command}) is not supported")

    def expression(self, source: str, scope: _Scope):
        if len(source) > MAX_EXPRESSION:  # its nesting with it: Python's parser fails past a few thousand
            raise self.over(f"${{{short(source)}}}", f"longer than {MAX_EXPRESSION} characters")
        try:
            tree = ast.parse(source.strip(), mode="eval")
        except SyntaxError:
            raise self.refuse(f"${{{short(source)}}}", "not an expression") from None
        except (MemoryError, RecursionError):  # the parser's stack: shorter than the bound when deep already
            raise self.refuse(f"${{{short(source)}}}", "nested too deeply") from None
        try:
            return evaluate(tree.body, scope, short(source), self, MAX_TEXT)
        except ArmError:
            raise
        except RecursionError:
            raise self.refuse(f"${{{short(source)}}}", "nested too deeply") from None
        except Undefined as err:
            raise ArmError(f"{self.where}: ${{{short(source)}}}: no property {err.args[0]!r}") from None
        except (ArithmeticError, TypeError, ValueError) as err:
            raise ArmError(f"{self.where}: ${{{short(source)}}}: {err}") from None

    # ---------------------------------------------------------------------- elements --
    def count(self, n: int = 1) -> None:
        self.elements += n
        if self.elements > MAX_ELEMENTS:
            raise self.refuse("document", f"it expands to more than {MAX_ELEMENTS} elements")

    def children(self, parent: ET.Element, scope: _Scope) -> list[ET.Element]:
        """Expand ``parent``'s children in place; return them."""
        out = []
        for child in list(parent):
            out.extend(self.element(child, scope))
        parent[:] = out
        return out

    def element(self, node: ET.Element, scope: _Scope) -> list[ET.Element]:
        if not isinstance(node.tag, str):  # comments, processing instructions
            return []
        if not is_xacro_namespace(node.tag):
            self.count()
            for key, value in list(node.attrib.items()):
                if is_xacro_namespace(key):
                    raise self.refuse(f"attribute {_local(key)}")
                node.set(key, _text_of(self.text(value, scope)))
            if node.text and node.text.strip():
                node.text = _text_of(self.text(node.text, scope))
            self.emit(node)
            self.children(node, scope)
            return [node]
        tag = _local(node.tag)
        handler = getattr(self, f"tag_{tag}", None)
        if handler is not None:
            return handler(node, scope)
        if tag in self.macros:
            return self.call(tag, node, scope)
        if tag in ("element", "attribute", "call", "eval-comments", "load_yaml"):
            raise self.refuse(f"<xacro:{tag}>", "not supported")
        raise self.refuse(f"<xacro:{tag}>", "no macro of that name is defined before it")

    def tag_include(self, node: ET.Element, scope: _Scope) -> list[ET.Element]:
        if set(node.attrib) - {"filename"}:
            raise self.refuse(f"<xacro:include {' '.join(sorted(node.attrib))}>", "only filename is supported")
        name = _text_of(self.text(node.get("filename", ""), scope))
        path = self.resolve_include(name)
        root = self.parse(path)
        self.files.append(path)
        try:
            return self.children(root, scope)
        finally:
            self.files.pop()

    def tag_property(self, node: ET.Element, scope: _Scope) -> list[ET.Element]:
        name = node.get("name", "")
        if not name.isidentifier() or "__" in name:
            raise self.refuse(f'<xacro:property name="{name}">', "a property needs an identifier as its name")
        target = {"parent": scope.parent or scope, "global": scope.root()}.get(node.get("scope", ""), scope)
        if "default" in node.attrib:
            if not target.has(name):
                target.define(name, node.get("default"))
            return []
        if "value" in node.attrib and target is not scope:  # xacro evaluates these where they stand
            target.define(name, _literal(self.text(node.get("value"), scope)), evaluated=True)
        elif "value" in node.attrib:
            target.define(name, node.get("value"))
        else:
            target.define(name, [copy.deepcopy(c) for c in node if isinstance(c.tag, str)], evaluated=True)
        return []

    def tag_arg(self, node: ET.Element, scope: _Scope) -> list[ET.Element]:
        name = node.get("name", "")
        if "default" in node.attrib and name not in self.args:
            self.args[name] = _text_of(self.text(node.get("default"), scope))
        return []

    def tag_macro(self, node: ET.Element, scope: _Scope) -> list[ET.Element]:
        name = node.get("name", "")
        params = []
        words = re.findall(r"""(?:[^\s'"]+|'[^']*'|"[^"]*")+""", node.get("params", ""))  # p:='a b': one
        for word in words:
            param, _, default = word.partition(":=")
            kind = "block" if param.startswith("*") else "value"
            if param.startswith("**"):
                kind = "blocks"
            params.append((param.lstrip("*"), kind, default if ":=" in word else None))
        self.macros[name] = (params, node, _size(node))
        return []

    def _condition(self, node: ET.Element, scope: _Scope, negate: bool) -> list[ET.Element]:
        tag = "unless" if negate else "if"
        value = self.text(node.get("value", ""), scope)
        if _truth(value, self.where, f'<xacro:{tag} value="{node.get("value", "")}">') != negate:
            holder = copy.copy(node)
            return self.children(holder, scope)
        return []

    def tag_if(self, node: ET.Element, scope: _Scope) -> list[ET.Element]:
        return self._condition(node, scope, negate=False)

    def tag_unless(self, node: ET.Element, scope: _Scope) -> list[ET.Element]:
        return self._condition(node, scope, negate=True)

    def tag_insert_block(self, node: ET.Element, scope: _Scope) -> list[ET.Element]:
        name = node.get("name", "")
        try:
            block = scope.get(name, self)
        except Undefined:
            raise self.refuse(f'<xacro:insert_block name="{name}">', "no block of that name") from None
        if not isinstance(block, list):
            raise self.refuse(f'<xacro:insert_block name="{name}">', "it names a property, not a block")
        self.step(f'<xacro:insert_block name="{name}">')
        self.copy(f'<xacro:insert_block name="{name}">', sum(_size(b) for b in block))
        holder = ET.Element("holder")
        holder.extend(copy.deepcopy(block))
        return self.children(holder, scope)

    def call(self, name: str, node: ET.Element, scope: _Scope) -> list[ET.Element]:
        self.calls += 1
        if self.calls > MAX_CALL_DEPTH:
            raise self.refuse(f"<xacro:{name}>", f"more than {MAX_CALL_DEPTH} nested macro calls")
        try:
            params, body, size = self.macros[name]
            self.step(f"<xacro:{name}>")
            self.copy(f"<xacro:{name}>", size)
            inner = _Scope(scope)
            given = dict(node.attrib)
            blocks = [c for c in node if isinstance(c.tag, str)]
            for param, kind, default in params:
                if kind == "block":
                    if not blocks:
                        raise self.refuse(f"<xacro:{name}>", f"block parameter *{param} not given")
                    inner.define(param, [blocks.pop(0)], evaluated=True)
                elif kind == "blocks":
                    inner.define(param, blocks, evaluated=True)
                    blocks = []
                elif param in given:
                    inner.define(param, _literal(self.text(given.pop(param), scope)), evaluated=True)
                elif default is not None and default.startswith("^"):
                    if scope.has(param):
                        inner.define(param, scope.get(param, self), evaluated=True)
                    elif default.startswith("^|"):
                        inner.define(param, _literal(self.text(default[2:], scope)), evaluated=True)
                    else:
                        raise self.refuse(f"<xacro:{name}>", f"parameter {param} not given nor set outside")
                elif default is not None:
                    inner.define(param, _literal(self.text(default, inner)), evaluated=True)
                else:
                    raise self.refuse(f"<xacro:{name}>", f"parameter {param} not given")
            if given:
                raise self.refuse(f"<xacro:{name}>", f"unknown parameter {sorted(given)[0]}")
            holder = copy.deepcopy(body)
            return self.children(holder, inner)
        finally:
            self.calls -= 1


def _size(node: ET.Element, deep: bool = True) -> int:
    """Characters of ``node`` as written, without markup and escapes: tag, attribute names and values,
    text and tail; with its descendants' if ``deep``."""
    total = 0
    for e in node.iter() if deep else (node,):
        total += len(e.tag) if isinstance(e.tag, str) else 0
        total += sum(len(k) + len(v) for k, v in e.attrib.items()) + len(e.text or "") + len(e.tail or "")
    return total


def expand(path: str | Path, packages: dict[str, str | Path] | None = None) -> str:
    """The URDF text of the xacro file ``path``.

    Parameters
    ----------
    path : str or Path
        The top xacro file; includes may read files inside its folder.
    packages : dict of str to path, optional
        ROS package name -> folder: what ``$(find NAME)`` gives; includes may read inside them.

    Raises
    ------
    ArmError
        Naming the file and the construct refused or the expression that failed.
    """
    path = Path(path)
    expander = _Expander(path, {k: Path(v) for k, v in (packages or {}).items()})
    root = expander.parse(path.resolve())
    expander.files.append(path.resolve())
    scope = _Scope()
    if is_xacro_namespace(root.tag):
        raise expander.refuse(f"<xacro:{_local(root.tag)}> as the root")
    try:
        expander.element(root, scope)
    except RecursionError:  # elements or properties nested thousands deep
        raise expander.refuse("document", "elements or properties nested too deeply") from None
    for key in [k for k in root.attrib if is_xacro_namespace(k)]:
        del root.attrib[key]
    text = ET.tostring(root, encoding="unicode")
    if len(text) > MAX_OUTPUT:  # the count above is before escapes (& -> &amp;: one character up to six)
        raise expander.over("document", f"the expanded document holds more than {MAX_OUTPUT} characters")
    return re.sub(r'\s+xmlns:\w+="[^"]*xacro[^"]*"', "", text)
