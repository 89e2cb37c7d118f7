"""A routine's domain as a `where` expression over its inputs: parsed once, checked, compiled.

`[cases] where = "aw >= 1 and bw >= 1"` is a Python expression restricted to arithmetic,
comparisons, `and`/`or`/`not`, indexing (tables) and a few pure functions. Its top-level `and`
terms are the domain's conditions, each reported on its own: a condition whose breaking cases the
routine answers wrong is shown to be needed.
"""

from __future__ import annotations

import ast
import copy
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

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
    # The same test over numpy columns (one array per input, in input order) -> a bool array; None when
    # the term indexes tables or calls len/sum/any/all (then it runs case by case).
    test_columns: Callable[..., np.ndarray] | None = None

    def over(self, columns: list, cases: list[tuple] | None = None) -> np.ndarray:
        """Which of a chunk's cases (given as columns) meet the condition."""
        if self.test_columns is not None:
            with np.errstate(all="ignore"):
                result = self.test_columns(*columns)
            return np.broadcast_to(np.asarray(result, dtype=bool), (len(columns[0]),))
        if cases is None:
            cases = list(zip(*(c.tolist() if c.ndim == 1 else [tuple(row) for row in c.tolist()] for c in columns)))
        return np.fromiter((bool(self.test(*case)) for case in cases), dtype=bool, count=len(cases))


def parse_where(text: str, names: tuple[str, ...], field: str, tables: frozenset[str] = frozenset()) -> tuple[Condition, ...]:
    """The conditions of a `where` expression (its top-level `and` terms), each compiled. `tables` names
    the inputs that are byte tables (their terms are tested case by case)."""
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
    return tuple(Condition(ast.get_source_segment(source, term) or ast.unparse(term), _compile(term, names),
                           _compile_columns(term, names, tables))
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


# ---- the same terms over numpy columns ---------------------------------------------------------------
# and/or/not become element-wise logic, a chained comparison the AND of its links, `x if c else y`
# np.where, abs/min/max their numpy forms. Terms over tables (indexing, len, sum, any, all, `in`) and
# left shifts (which could pass 64 bits) keep the case-by-case test.

_COLUMN_FUNCTIONS = {"_and": lambda *v: np.logical_and.reduce(v), "_or": lambda *v: np.logical_or.reduce(v),
                     "_not": np.logical_not, "_where": np.where, "abs": np.abs,
                     "min": lambda *v: np.minimum.reduce(v), "max": lambda *v: np.maximum.reduce(v)}
_CASE_BY_CASE = (ast.Subscript, ast.Slice, ast.Tuple, ast.List, ast.In, ast.NotIn, ast.LShift)


class _ToColumns(ast.NodeTransformer):
    def visit_BoolOp(self, node: ast.BoolOp) -> ast.AST:
        self.generic_visit(node)
        return _call("_and" if isinstance(node.op, ast.And) else "_or", node.values)

    def visit_UnaryOp(self, node: ast.UnaryOp) -> ast.AST:
        self.generic_visit(node)
        return _call("_not", [node.operand]) if isinstance(node.op, ast.Not) else node

    def visit_Compare(self, node: ast.Compare) -> ast.AST:
        self.generic_visit(node)
        if len(node.ops) == 1:
            return node
        left, links = node.left, []
        for op, right in zip(node.ops, node.comparators):
            links.append(ast.Compare(left=left, ops=[op], comparators=[right]))
            left = right
        return _call("_and", links)

    def visit_IfExp(self, node: ast.IfExp) -> ast.AST:
        self.generic_visit(node)
        return _call("_where", [node.test, node.body, node.orelse])


def _call(name: str, arguments: list) -> ast.Call:
    return ast.Call(func=ast.Name(id=name, ctx=ast.Load()), args=list(arguments), keywords=[])


def _compile_columns(term: ast.expr, names: tuple[str, ...], tables: frozenset[str]) -> Callable[..., np.ndarray] | None:
    for node in ast.walk(term):
        if isinstance(node, ast.Name) and node.id in tables:
            return None
        if isinstance(node, _CASE_BY_CASE) or (isinstance(node, ast.Call) and node.func.id not in ("abs", "min", "max")):
            return None
        if isinstance(node, ast.Call) and node.func.id in ("min", "max") and len(node.args) < 2:
            return None
    body = _ToColumns().visit(copy.deepcopy(term))
    arguments = ast.arguments(posonlyargs=[], args=[ast.arg(arg=name) for name in names], kwonlyargs=[],
                              kw_defaults=[], defaults=[])
    expression = ast.Expression(body=ast.Lambda(args=arguments, body=body))
    ast.fix_missing_locations(expression)
    return eval(compile(expression, "<where>", "eval"), {"__builtins__": {}, **_COLUMN_FUNCTIONS})
