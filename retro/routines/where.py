"""A routine's domain as a `where` expression over its inputs: parsed once, checked, compiled.

`[cases] where = "aw >= 1 and bw >= 1"` is a Python expression restricted to arithmetic,
comparisons, `and`/`or`/`not`, indexing (tables) and a few pure functions. Its top-level `and`
terms are the domain's conditions, each reported on its own: a condition whose breaking cases the
routine answers wrong is shown to be needed.
"""

from __future__ import annotations

import ast
from collections.abc import Callable
from dataclasses import dataclass

from retro.errors import InputError

FUNCTIONS: dict[str, Callable] = {"abs": abs, "min": min, "max": max, "len": len, "sum": sum, "any": any, "all": all}
_ALLOWED = (ast.Expression, ast.BoolOp, ast.And, ast.Or, ast.UnaryOp, ast.Not, ast.USub, ast.UAdd, ast.Invert,
            ast.BinOp, ast.Add, ast.Sub, ast.Mult, ast.FloorDiv, ast.Mod, ast.BitAnd, ast.BitOr, ast.BitXor,
            ast.LShift, ast.RShift, ast.Compare, ast.Eq, ast.NotEq, ast.Lt, ast.LtE, ast.Gt, ast.GtE, ast.In,
            ast.NotIn, ast.Name, ast.Load, ast.Constant, ast.Subscript, ast.Slice, ast.Tuple, ast.List, ast.Call,
            ast.IfExp)
MAX_LENGTH = 2_000
MAX_CONSTANT = 1 << 32  # inputs are at most 32-bit: larger constants (and shifts) only build huge numbers
MAX_SHIFT = 64


@dataclass(frozen=True)
class Condition:
    text: str  # as the user wrote it: the name the report uses
    test: Callable[..., bool]  # called with the case's values in input order


def parse_where(text: str, names: tuple[str, ...], field: str) -> tuple[Condition, ...]:
    """The conditions of a `where` expression (its top-level `and` terms), each compiled."""
    if not isinstance(text, str) or not text.strip():
        raise InputError(f"{field}: expected an expression over the inputs, e.g. \"aw >= 1 and bw >= 1\"")
    if len(text) > MAX_LENGTH:
        raise InputError(f"{field}: expression longer than {MAX_LENGTH} characters")
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError as exc:
        raise InputError(f"{field}: not an expression: {exc.msg} at column {exc.offset}") from None
    _check(tree, set(names), field)
    body = tree.body
    terms = body.values if isinstance(body, ast.BoolOp) and isinstance(body.op, ast.And) else [body]
    source = text.strip()
    return tuple(Condition(ast.get_source_segment(source, term) or ast.unparse(term), _compile(term, names))
                 for term in terms)


def _check(tree: ast.AST, names: set[str], field: str) -> None:
    for node in ast.walk(tree):
        if not isinstance(node, _ALLOWED):
            raise InputError(f"{field}: {type(node).__name__} is not allowed in a domain expression "
                             "(arithmetic, comparisons, and/or/not, indexing, abs/min/max/len/sum/any/all)")
        if isinstance(node, ast.Name) and node.id not in names and node.id not in FUNCTIONS:
            raise InputError(f"{field}: unknown name {node.id!r} (inputs: {', '.join(sorted(names)) or 'none'})")
        if isinstance(node, ast.Call) and not (isinstance(node.func, ast.Name) and node.func.id in FUNCTIONS):
            raise InputError(f"{field}: only abs, min, max, len, sum, any and all may be called")
        if isinstance(node, ast.Constant) and not isinstance(node.value, (int, bool)):
            raise InputError(f"{field}: only whole numbers are allowed, got {node.value!r}")
        if isinstance(node, ast.Constant) and abs(node.value) > MAX_CONSTANT:
            raise InputError(f"{field}: the number {node.value} is larger than 2^32")
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.LShift) and not (
                isinstance(node.right, ast.Constant) and 0 <= node.right.value <= MAX_SHIFT):
            raise InputError(f"{field}: a left shift must be by a constant of at most {MAX_SHIFT}")


def _compile(term: ast.expr, names: tuple[str, ...]) -> Callable[..., bool]:
    """`lambda <inputs in order>: <term>`: the case's values are passed positionally, no dict per case."""
    arguments = ast.arguments(posonlyargs=[], args=[ast.arg(arg=name) for name in names], kwonlyargs=[],
                              kw_defaults=[], defaults=[])
    expression = ast.Expression(body=ast.Lambda(args=arguments, body=term))
    ast.fix_missing_locations(expression)
    return eval(compile(expression, "<where>", "eval"), {"__builtins__": {}, **FUNCTIONS})
