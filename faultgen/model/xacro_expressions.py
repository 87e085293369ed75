"""The ``${...}`` expressions of a xacro file, evaluated over Python's syntax tree without ``eval``:
numbers, strings, booleans, properties, :data:`CONSTANTS`, arithmetic, comparisons, conditionals
and the calls of :data:`FUNCTIONS`; anything else is refused, naming the expression. Used by the
expander (:mod:`faultgen.model.xacro`), which holds the bounds."""

from __future__ import annotations

import ast
import math
import operator

from faultgen.model.builder import ArmError

#: Functions a ``${...}`` expression may call (``math.NAME`` alike).
FUNCTIONS = {
    **{
        name: getattr(math, name)
        for name in (
            "sin cos tan asin acos atan atan2 sinh cosh tanh sqrt exp log log10 radians degrees "
            "fabs floor ceil hypot copysign"
        ).split()
    },
    "abs": abs,
    "min": min,
    "max": max,
    "round": round,
    "int": int,
    "float": float,
}
CONSTANTS = {"pi": math.pi, "e": math.e, "True": True, "False": False}

BINARY = {
    ast.Add: operator.add,
    ast.Sub: operator.sub,
    ast.Mult: operator.mul,
    ast.Div: operator.truediv,
    ast.FloorDiv: operator.floordiv,
    ast.Mod: operator.mod,
    ast.Pow: operator.pow,
}
COMPARE = {
    ast.Eq: operator.eq,
    ast.NotEq: operator.ne,
    ast.Lt: operator.lt,
    ast.LtE: operator.le,
    ast.Gt: operator.gt,
    ast.GtE: operator.ge,
}


class Undefined(Exception):
    """A ``${...}`` name that is neither a property nor a constant (its name is ``args[0]``)."""


def evaluate(node: ast.AST, scope, source: str, expander, max_text: int):
    """The value of the parsed ``${...}`` expression ``node`` (``source``: its text, for messages):
    numbers, strings, booleans; properties of ``scope`` (``has(name)``, ``get(name, expander)``),
    :data:`CONSTANTS`; arithmetic, comparisons, ``and`` / ``or`` / ``not``, ``a if c else b`` and calls
    of :data:`FUNCTIONS`. Strings of more than ``max_text`` characters, integers past 2**63 (taken as
    floats) and non-finite results are refused.

    Raises
    ------
    faultgen.model.builder.ArmError
        From ``expander.refuse(construct, why)`` for anything else (an attribute, a subscript, a
        name with ``__``, another function), naming the expression; or naming ``expander.where``
        for an out-of-range result.
    Undefined
        For a name that is neither a property nor a constant.
    """
    if isinstance(node, ast.Constant) and isinstance(node.value, (int, float, str, bool)):
        return node.value
    if isinstance(node, ast.Name):
        if "__" in node.id:
            raise expander.refuse(f"${{{source}}}", f"name {node.id!r}")
        if scope.has(node.id):
            return scope.get(node.id, expander)
        if node.id in CONSTANTS:
            return CONSTANTS[node.id]
        raise Undefined(node.id)
    if isinstance(node, ast.BinOp) and type(node.op) in BINARY:
        left = evaluate(node.left, scope, source, expander, max_text)
        right = evaluate(node.right, scope, source, expander, max_text)
        return _arithmetic(node.op, left, right, source, expander, max_text)
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd, ast.Not)):
        operand = evaluate(node.operand, scope, source, expander, max_text)
        if isinstance(node.op, ast.Not):
            return not operand
        if not isinstance(operand, (int, float)):
            raise expander.refuse(f"${{{source}}}", f"sign of {operand!r}")
        return -operand if isinstance(node.op, ast.USub) else +operand
    if isinstance(node, ast.BoolOp):
        result = None
        for operand in node.values:
            result = evaluate(operand, scope, source, expander, max_text)
            if isinstance(node.op, ast.And) != bool(result):
                return result
        return result
    if isinstance(node, ast.Compare) and all(type(op) in COMPARE for op in node.ops):
        left = evaluate(node.left, scope, source, expander, max_text)
        for op, right_node in zip(node.ops, node.comparators):
            right = evaluate(right_node, scope, source, expander, max_text)
            if not COMPARE[type(op)](left, right):
                return False
            left = right
        return True
    if isinstance(node, ast.IfExp):
        test = evaluate(node.test, scope, source, expander, max_text)
        return evaluate(node.body if test else node.orelse, scope, source, expander, max_text)
    if isinstance(node, ast.Call) and not node.keywords:
        name = function_name(node.func)
        if name not in FUNCTIONS:
            what = short(ast.unparse(node.func))
            raise expander.refuse(f"${{{source}}}", f"function {what}() (allowed: {', '.join(sorted(FUNCTIONS))})")
        args = [evaluate(a, scope, source, expander, max_text) for a in node.args]
        if not all(isinstance(a, (int, float)) for a in args):
            raise expander.refuse(f"${{{source}}}", f"{name}() of {args!r}")
        return FUNCTIONS[name](*args)
    if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id == "math":
        if node.attr in ("pi", "e"):
            return CONSTANTS[node.attr]
    kind = {ast.Attribute: "attribute access", ast.Subscript: "subscript", ast.Call: "call"}.get(
        type(node), type(node).__name__
    )
    raise expander.refuse(f"${{{source}}}", f"{kind} {short(ast.unparse(node))!r}")


def _arithmetic(op: ast.operator, left, right, source: str, expander, max_text: int):
    """``left op right`` for an operator of :data:`BINARY` (:func:`evaluate`'s other arguments): on
    numbers, or the concatenation of two strings of at most ``max_text`` characters together; an
    integer past 2**63 is taken as a float, a non-finite result refused."""
    if isinstance(op, ast.Add) and isinstance(left, str) and isinstance(right, str):
        if len(left) + len(right) > max_text:
            raise expander.refuse(f"${{{source}}}", f"a string of more than {max_text} characters")
        return left + right
    if not all(isinstance(v, (int, float)) for v in (left, right)):
        raise expander.refuse(f"${{{source}}}", f"{type(op).__name__} of {left!r} and {right!r}")
    if isinstance(op, ast.Pow):
        left, right = float(left), float(right)  # no integer powers of unbounded size
    result = BINARY[type(op)](left, right)
    # no integers of unbounded size (their arithmetic slows down with their length)
    result = float(result) if isinstance(result, int) and abs(result) > 2**63 else result
    if isinstance(result, float) and not math.isfinite(result):
        raise ArmError(f"{expander.where}: ${{{source}}}: {result} (out of range)")
    return result


def short(text: str, n: int = 60) -> str:
    """``text``, cut to ``n`` characters with "..." when longer (for messages)."""
    return text if len(text) <= n else text[: n - 3] + "..."


def function_name(func: ast.AST) -> str | None:
    """The name a call calls: ``f`` of ``f(x)`` and of ``math.f(x)``; None for anything else."""
    if isinstance(func, ast.Name):
        return func.id
    if isinstance(func, ast.Attribute) and isinstance(func.value, ast.Name) and func.value.id == "math":
        return func.attr
    return None
