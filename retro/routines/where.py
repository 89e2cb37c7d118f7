"""A routine's domain as a `where` expression over its inputs: parsed once, checked, compiled.

`[cases] where = "aw >= 1 and bw >= 1"` is a Python expression restricted to arithmetic,
comparisons, `and`/`or`/`not`, `x if c else y`, indexing (tables) and a few pure functions. Its
top-level `and` terms are the domain's conditions, each reported on its own: a condition whose
breaking cases the routine answers wrong is shown to be needed.

The expression means what it means in Python, case by case, whatever the engine:
- integers never wrap: a term whose values could pass 2^62 (from the inputs' ranges, worked out
  when the spec is read) is evaluated with Python integers, case by case; every other term over
  numpy int64 columns, where it cannot overflow;
- `x // 0`, `x % 0` and a negative shift count are errors naming the term and the case (exit 2),
  as Python raises them; `and`, `or` and `x if c else y` evaluate only what Python evaluates (the
  column form masks the cases a branch does not reach), and `a or b` is a's value when a is true;
- nothing can grow without bound: sequences (tables, lists) take no arithmetic (`[0] * (1 << 28)`
  is refused when the spec is read), a left shift is by a constant of at most MAX_SHIFT, numbers
  are at most MAX_CONSTANT, and terms nest at most MAX_DEPTH deep (one line, not a RecursionError).
"""

from __future__ import annotations

import ast
import operator
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from retro.errors import InputError
from retro.routines.sandbox import shown

FUNCTIONS: dict[str, Callable] = {"abs": abs, "min": min, "max": max, "len": len, "sum": sum, "any": any, "all": all}
_ALLOWED = (ast.Expression, ast.BoolOp, ast.And, ast.Or, ast.UnaryOp, ast.Not, ast.USub, ast.UAdd, ast.Invert,
            ast.BinOp, ast.Add, ast.Sub, ast.Mult, ast.FloorDiv, ast.Mod, ast.BitAnd, ast.BitOr, ast.BitXor,
            ast.LShift, ast.RShift, ast.Compare, ast.Eq, ast.NotEq, ast.Lt, ast.LtE, ast.Gt, ast.GtE, ast.In,
            ast.NotIn, ast.Name, ast.Load, ast.Constant, ast.Subscript, ast.Slice, ast.Tuple, ast.List, ast.Call,
            ast.IfExp)
MAX_LENGTH = 2_000
MAX_CONSTANT = 1 << 32  # inputs are at most 32-bit: larger constants (and shifts) only build huge numbers
MAX_SHIFT = 64
MAX_DEPTH = 100  # nesting of terms; a deeper expression is refused before anything recurses over it
COLUMN_LIMIT = 1 << 62  # a term whose values stay below this in magnitude runs on int64 columns
DEFAULT_BOUND = 1 << 32  # an input whose range is not given: at most 32 bits (retro.routines.spec)
TABLE_LENGTH = 0x10000  # the longest table (retro.routines.spec.MAX_TABLE)
BYTE = 0xFF

NUMBER, SEQUENCE = "number", "sequence"


@dataclass(frozen=True)
class Condition:
    text: str  # as the user wrote it: the name the report uses
    test: Callable[..., object]  # called with the case's values in input order; Python's semantics
    # The same test over numpy columns (one array per input, in input order) -> a bool array; None when
    # the term takes tables, lists or numbers past int64 (then it runs case by case).
    test_columns: Callable[..., np.ndarray] | None = None
    term: ast.expr | None = field(default=None, compare=False)  # the parsed term (what `input_ranges` reads)

    def over(self, columns: list, cases: list[tuple] | None = None) -> np.ndarray:
        """Which of a chunk's cases (given as columns) meet the condition."""
        if self.test_columns is not None:
            return self.test_columns(*columns)
        if cases is None:
            cases = list(zip(*(c.tolist() if c.ndim == 1 else [tuple(row) for row in c.tolist()] for c in columns)))
        return np.fromiter((bool(self.test(*case)) for case in cases), dtype=bool, count=len(cases))


def parse_where(text: str, names: tuple[str, ...], field: str, tables: frozenset[str] = frozenset(),
                bounds: dict[str, tuple[int, int]] | None = None) -> tuple[Condition, ...]:
    """The conditions of a `where` expression (its top-level `and` terms), each compiled. `tables` names
    the inputs that are byte tables; `bounds` gives the other inputs' (lo, hi) (default: 32 bits), which
    decide whether a term can run on int64 columns without overflow."""
    if not isinstance(text, str) or not text.strip():
        raise InputError(f"{field}: expected an expression over the inputs, e.g. \"aw >= 1 and bw >= 1\"")
    if len(text) > MAX_LENGTH:
        raise InputError(f"{field}: expression longer than {MAX_LENGTH} characters")
    source = text.strip()
    try:
        tree = ast.parse(source, mode="eval")
    except SyntaxError as exc:
        raise InputError(f"{field}: not an expression: {exc.msg} at column {exc.offset}") from None
    except (RecursionError, MemoryError):
        raise InputError(f"{field}: the expression nests more deeply than Python's parser allows") from None
    _check_depth(tree, field)
    _check(tree, set(names), field)
    checker = _Kinds(field, source, tables, bounds or {})
    body = tree.body
    terms = body.values if isinstance(body, ast.BoolOp) and isinstance(body.op, ast.And) else [body]
    conditions: list[Condition] = []
    for term in terms:
        term_text = ast.get_source_segment(source, term) or ast.unparse(term)
        _, _, columnar = checker.visit(term)
        earlier = tuple(conditions)
        test = _compile(term, names, f"{field}: {term_text}", earlier)
        columns = _Columns(term, names, f"{field}: {term_text}", source, earlier) if columnar else None
        conditions.append(Condition(term_text, test, columns, term))
    return tuple(conditions)


# ---- ranges the domain allows, for drawing cases inside it ----------------------------------------------

RANGE_ROUNDS = 20  # passes over the comparisons (each narrows what the others allow)


def input_ranges(domain: tuple[Condition, ...], ranges: dict[str, tuple[int, int]]) -> dict[str, tuple[int, int]]:
    """The (lo, hi) of each number input (`ranges`: what its values allow) narrowed by the domain's
    top-level comparisons of sums of inputs and constants (`aw >= 1`, `ax + aw <= 255`,
    `2 <= n < 9`): every case inside the domain lies within them (a necessary condition only: other
    terms, `or`, tables, bit operations narrow nothing). lo > hi: no case lies inside."""
    constraints = []
    for condition in domain:
        term = condition.term
        if not isinstance(term, ast.Compare):
            continue
        operands = [term.left, *term.comparators]
        for op, left, right in zip(term.ops, operands, operands[1:]):
            a, b = _linear(left, ranges), _linear(right, ranges)
            if a is None or b is None:
                continue
            difference = _combine(a, b, -1)  # left - right
            if isinstance(op, (ast.LtE, ast.Eq)):
                constraints.append(difference)
            if isinstance(op, ast.Lt):
                constraints.append((difference[0], difference[1] + 1))
            if isinstance(op, (ast.GtE, ast.Eq)):
                constraints.append(_scaled(difference, -1))
            if isinstance(op, ast.Gt):
                negated = _scaled(difference, -1)
                constraints.append((negated[0], negated[1] + 1))
    bounds = dict(ranges)
    for _ in range(RANGE_ROUNDS):
        changed = False
        for coefficients, constant in constraints:  # sum(c * x) + constant <= 0
            lows = {name: min(c * bounds[name][0], c * bounds[name][1]) for name, c in coefficients.items()}
            total = sum(lows.values())
            for name, c in coefficients.items():
                room = -constant - (total - lows[name])  # c * x <= room
                lo, hi = bounds[name]
                if c > 0:
                    hi = min(hi, room // c)
                else:
                    lo = max(lo, -(room // -c))
                if (lo, hi) != bounds[name]:
                    bounds[name] = (lo, hi)
                    changed = True
                    if lo > hi:
                        return bounds
        if not changed:
            break
    return bounds


def _linear(node: ast.AST, ranges: dict) -> tuple[dict[str, int], int] | None:
    """node as (coefficients by input, constant), when it is a sum of inputs and constants."""
    if isinstance(node, ast.Name):
        return ({node.id: 1}, 0) if node.id in ranges else None
    if isinstance(node, ast.Constant) and isinstance(node.value, int):
        return {}, int(node.value)
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        inner = _linear(node.operand, ranges)
        return None if inner is None else _scaled(inner, -1 if isinstance(node.op, ast.USub) else 1)
    if isinstance(node, ast.BinOp) and isinstance(node.op, (ast.Add, ast.Sub, ast.Mult)):
        a, b = _linear(node.left, ranges), _linear(node.right, ranges)
        if a is None or b is None:
            return None
        if isinstance(node.op, ast.Mult):
            if not a[0]:
                return _scaled(b, a[1])
            return _scaled(a, b[1]) if not b[0] else None
        return _combine(a, b, 1 if isinstance(node.op, ast.Add) else -1)
    return None


def _combine(a: tuple[dict, int], b: tuple[dict, int], sign: int) -> tuple[dict, int]:
    coefficients = dict(a[0])
    for name, c in b[0].items():
        coefficients[name] = coefficients.get(name, 0) + sign * c
    return {k: v for k, v in coefficients.items() if v}, a[1] + sign * b[1]


def _scaled(a: tuple[dict, int], factor: int) -> tuple[dict, int]:
    return {k: v * factor for k, v in a[0].items() if v * factor}, a[1] * factor


def require_inside(field: str, domain: tuple[Condition, ...], cases: int, outside: int,
                   broken: dict[str, int]) -> None:
    """A check whose every case lies outside the domain has checked nothing: that is an error (exit 2:
    the spec's domain and cases do not meet), never an OK."""
    if not domain or not cases or outside < cases:
        return
    worst = max(domain, key=lambda condition: broken.get(condition.text, 0))
    raise InputError(f"{field}: all {cases:,} cases lie outside the domain ({worst.text} excludes "
                     f"{broken.get(worst.text, 0):,} of them): nothing was checked")


def _check_depth(tree: ast.AST, field: str) -> None:
    stack = [(tree, 1)]
    while stack:
        node, depth = stack.pop()
        if depth > MAX_DEPTH:
            raise InputError(f"{field}: the expression nests more than {MAX_DEPTH} deep")
        stack.extend((child, depth + 1) for child in ast.iter_child_nodes(node))


def _check(tree: ast.AST, names: set[str], field: str) -> None:
    for node in ast.walk(tree):
        if not isinstance(node, _ALLOWED):
            raise InputError(f"{field}: {type(node).__name__} is not allowed in a domain expression "
                             "(arithmetic, comparisons, and/or/not, indexing, abs/min/max/len/sum/any/all)")
        if isinstance(node, ast.Name) and node.id not in names and node.id not in FUNCTIONS:
            raise InputError(f"{field}: unknown name {node.id!r} (inputs: {', '.join(sorted(names)) or 'none'})")
        if isinstance(node, ast.Call) and (not (isinstance(node.func, ast.Name) and node.func.id in FUNCTIONS)
                                           or node.keywords):
            raise InputError(f"{field}: only abs, min, max, len, sum, any and all may be called (no keywords)")
        if isinstance(node, ast.Constant) and not isinstance(node.value, (int, bool)):
            raise InputError(f"{field}: only whole numbers are allowed, got {node.value!r:.40}")
        if isinstance(node, ast.Constant) and abs(node.value) > MAX_CONSTANT:
            raise InputError(f"{field}: a number larger than 2^32")
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.LShift) and not (
                isinstance(node.right, ast.Constant) and not isinstance(node.right.value, bool)
                and 0 <= node.right.value <= MAX_SHIFT):
            raise InputError(f"{field}: a left shift must be by a constant of at most {MAX_SHIFT}")


# ---- kinds and sizes, when the spec is read ------------------------------------------------------------

class _Kinds:
    """Each node's kind (a number or a sequence), the largest magnitude its values may take, and
    whether its term can run on int64 columns. Sequences take no arithmetic: that is what keeps
    `[0] * (1 << 28)` from being built."""

    def __init__(self, field: str, source: str, tables: frozenset[str], bounds: dict[str, tuple[int, int]]) -> None:
        self.field, self.source, self.tables, self.bounds = field, source, tables, bounds

    def error(self, node: ast.AST, message: str) -> InputError:
        segment = ast.get_source_segment(self.source, node) or ast.unparse(node)
        return InputError(f"{self.field}: {segment[:60]}: {message}")

    def number(self, node: ast.AST, what: str) -> tuple[int, bool]:
        kind, magnitude, columnar = self.visit(node)
        if kind != NUMBER:
            raise self.error(node, f"{what} takes numbers, not a table or list")
        return magnitude, columnar

    def sequence(self, node: ast.AST, what: str) -> int:
        kind, magnitude, _ = self.visit(node)
        if kind != SEQUENCE:
            raise self.error(node, f"{what} takes a table or a list, not a number")
        return magnitude

    def visit(self, node: ast.AST) -> tuple[str, int, bool]:
        """(kind, magnitude: the largest |value| of a number or of a sequence's items, columnar: the
        node and all below it can run on int64 columns)."""
        kind, magnitude, columnar = self._visit(node)
        return kind, magnitude, columnar and magnitude < COLUMN_LIMIT

    def _visit(self, node: ast.AST) -> tuple[str, int, bool]:
        rule = self._RULES.get(type(node))
        if rule is None:
            raise self.error(node, f"{type(node).__name__} is not allowed")
        return rule(self, node)

    def _name(self, node: ast.Name) -> tuple[str, int, bool]:
        if node.id in FUNCTIONS:
            raise self.error(node, f"{node.id} is a function: call it")
        if node.id in self.tables:
            return SEQUENCE, BYTE, False
        lo, hi = self.bounds.get(node.id, (-DEFAULT_BOUND, DEFAULT_BOUND))
        return NUMBER, max(abs(lo), abs(hi)), True

    def _constant(self, node: ast.Constant) -> tuple[str, int, bool]:
        return NUMBER, abs(int(node.value)), True

    def _literal(self, node: ast.List | ast.Tuple) -> tuple[str, int, bool]:
        return SEQUENCE, max((self.number(e, "a list")[0] for e in node.elts), default=0), False

    def _subscript(self, node: ast.Subscript) -> tuple[str, int, bool]:
        magnitude = self.sequence(node.value, "indexing")
        if isinstance(node.slice, ast.Slice):
            for part in (node.slice.lower, node.slice.upper, node.slice.step):
                if part is not None:
                    self.number(part, "a slice")
            return SEQUENCE, magnitude, False
        self.number(node.slice, "an index")
        return NUMBER, magnitude, False

    def _unary(self, node: ast.UnaryOp) -> tuple[str, int, bool]:
        if isinstance(node.op, ast.Not):
            _, _, columnar = self.visit(node.operand)
            return NUMBER, 1, columnar
        magnitude, columnar = self.number(node.operand, "arithmetic")
        return NUMBER, magnitude + (1 if isinstance(node.op, ast.Invert) else 0), columnar

    def _binary(self, node: ast.BinOp) -> tuple[str, int, bool]:
        (a, left), (b, right) = self.number(node.left, "arithmetic"), self.number(node.right, "arithmetic")
        return NUMBER, _magnitude(node.op, a, b, node.right), left and right

    def _boolean(self, node: ast.BoolOp) -> tuple[str, int, bool]:
        values = [self.number(v, "and/or") for v in node.values]
        return NUMBER, max(m for m, _ in values), all(c for _, c in values)

    def _compare(self, node: ast.Compare) -> tuple[str, int, bool]:
        operands = [node.left, *node.comparators]
        kinds = [self.visit(operand) for operand in operands]  # once each: nested comparisons stay linear
        columnar = all(kind == NUMBER and c for kind, _, c in kinds)
        for k, op in enumerate(node.ops):
            self._comparison(node, op, kinds[k][0], kinds[k + 1][0])
            if isinstance(op, (ast.In, ast.NotIn)):
                columnar = False
        return NUMBER, 1, columnar

    def _comparison(self, node: ast.Compare, op: ast.cmpop, left_kind: str, right_kind: str) -> None:
        """One operator of a comparison between operands of these kinds, or an error."""
        if isinstance(op, (ast.In, ast.NotIn)):
            if left_kind != NUMBER or right_kind != SEQUENCE:
                raise self.error(node, "`in` asks whether a number is in a table or a list")
        elif not isinstance(op, (ast.Eq, ast.NotEq)) and (left_kind, right_kind) != (NUMBER, NUMBER):
            raise self.error(node, "<, <=, >, >= compare numbers, not tables or lists")

    def _if(self, node: ast.IfExp) -> tuple[str, int, bool]:
        _, _, test = self.visit(node.test)
        (kind, a, body), (other, b, orelse) = self.visit(node.body), self.visit(node.orelse)
        if kind != other:
            raise self.error(node, "both branches must be numbers, or both tables or lists")
        return kind, max(a, b), test and body and orelse and kind == NUMBER

    def call(self, node: ast.Call) -> tuple[str, int, bool]:
        name, args = node.func.id, node.args
        if any(isinstance(a, ast.Starred) for a in args):
            raise self.error(node, "no * arguments")
        if name in ("len", "sum", "any", "all"):
            if len(args) != 1:
                raise self.error(node, f"{name} takes one table or list")
            magnitude = self.sequence(args[0], name)
            return NUMBER, {"len": TABLE_LENGTH, "sum": magnitude * TABLE_LENGTH}.get(name, 1), False
        if name == "abs":
            if len(args) != 1:
                raise self.error(node, "abs takes one number")
            magnitude, columnar = self.number(args[0], "abs")
            return NUMBER, magnitude, columnar
        if len(args) == 1:  # min(table), max(table)
            return NUMBER, self.sequence(args[0], f"{name} of one argument"), False
        if not args:
            raise self.error(node, f"{name} takes numbers, or one table")
        values = [self.number(a, name) for a in args]
        return NUMBER, max(m for m, _ in values), all(c for _, c in values)

    # each kind of node the checked AST may hold -> its rule
    _RULES = {ast.Name: _name, ast.Constant: _constant, ast.List: _literal, ast.Tuple: _literal,
              ast.Subscript: _subscript, ast.UnaryOp: _unary, ast.BinOp: _binary, ast.BoolOp: _boolean,
              ast.Compare: _compare, ast.IfExp: _if, ast.Call: call}


def _magnitude(op: ast.operator, a: int, b: int, right: ast.expr) -> int:
    """The largest |result| of `x op y` with |x| <= a and |y| <= b (Python's integers)."""
    if isinstance(op, (ast.Add, ast.Sub)):
        return a + b
    if isinstance(op, ast.Mult):
        return a * b
    if isinstance(op, ast.FloorDiv):
        return a  # |x // y| <= |x| for y != 0
    if isinstance(op, ast.Mod):
        return b  # |x % y| < |y|
    if isinstance(op, ast.LShift):
        return a << right.value  # a constant, checked
    if isinstance(op, ast.RShift):
        return a
    return (1 << (max(a, b).bit_length() + 1)) - 1  # &, |, ^ of numbers of that many bits, signs included


# ---- case by case: Python itself, errors in one line -------------------------------------------------

def _compile(term: ast.expr, names: tuple[str, ...], where: str, earlier: tuple = ()) -> Callable[..., object]:
    """`lambda <inputs in order>: <term>` (the case's values positionally, no dict per case), whose
    errors (x // 0, a negative shift, an index past a table) are one line naming the term and the case.
    Python evaluates `a and b` from the left: a term that fails where an `earlier` term is false is
    never reached there, so it is false, not an error."""
    arguments = ast.arguments(posonlyargs=[], args=[ast.arg(arg=name) for name in names], kwonlyargs=[],
                              kw_defaults=[], defaults=[])
    expression = ast.Expression(body=ast.Lambda(args=arguments, body=term))
    ast.fix_missing_locations(expression)
    raw = eval(compile(expression, "<where>", "eval"), {"__builtins__": {}, **FUNCTIONS})

    def test(*case):
        try:
            return raw(*case)
        except (ArithmeticError, ValueError, TypeError, IndexError) as exc:
            if not all(condition.test(*case) for condition in earlier):
                return False
            raise InputError(f"{where}: {_reason(exc)} at {_describe(names, case)}") from None
    return test


def _reason(exc: Exception) -> str:
    if isinstance(exc, ZeroDivisionError):
        return "division by zero"
    if isinstance(exc, ValueError) and "negative shift count" in str(exc):
        return "negative shift count"
    return f"{type(exc).__name__}: {str(exc)[:100]}"


def _describe(names: tuple[str, ...], case: tuple) -> str:
    return ", ".join(f"{name}={shown(value, 40)}" for name, value in zip(names, case))


# ---- over numpy columns, with Python's meaning --------------------------------------------------------

_ARITHMETIC = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.BitAnd: operator.and_,
               ast.BitOr: operator.or_, ast.BitXor: operator.xor}
_ORDER = {ast.Eq: operator.eq, ast.NotEq: operator.ne, ast.Lt: operator.lt, ast.LtE: operator.le,
          ast.Gt: operator.gt, ast.GtE: operator.ge}


class _Columns:
    """A term evaluated over column blocks by walking its tree once per block. Every node gets the mask
    of the cases Python would evaluate it for (`and`, `or`, `if` and chained comparisons short-circuit);
    an error (x // 0, a negative shift) counts only where the node is evaluated. The kinds check has
    shown every value fits int64, so numpy's arithmetic is Python's here."""

    def __init__(self, term: ast.expr, names: tuple[str, ...], where: str, source: str, earlier: tuple) -> None:
        self.term, self.names, self.where, self.source, self.earlier = term, names, where, source, earlier
        # the nodes under which an error can happen (//, %, >>): only there do masks need computing
        self.fallible = {id(node) for node in ast.walk(term) if any(
            isinstance(inner, ast.BinOp) and isinstance(inner.op, (ast.FloorDiv, ast.Mod, ast.RShift))
            for inner in ast.walk(node))}

    def __call__(self, *columns) -> np.ndarray:
        n = len(columns[0])
        reach = np.ones(n, dtype=bool)
        try:
            with np.errstate(all="ignore"):
                value = self.evaluate(self.term, reach, columns)
        except InputError:
            if not self.earlier:
                raise
            # as Python evaluates `a and b`: the term is reached only where the earlier terms hold
            for condition in self.earlier:
                reach = reach & condition.over(list(columns))
            with np.errstate(all="ignore"):
                value = self.evaluate(self.term, reach, columns)
            return _spread(_truth(value), n) & reach
        return _spread(_truth(value), n)

    def fail(self, node: ast.AST, message: str, bad: np.ndarray, columns: tuple) -> InputError:
        i = int(np.flatnonzero(bad)[0])
        case = tuple(c[i].tolist() for c in columns)
        segment = ast.get_source_segment(self.source, node) or ast.unparse(node)
        return InputError(f"{self.where}: {segment[:60]}: {message} at {_describe(self.names, case)}")

    def evaluate(self, node: ast.AST, active: np.ndarray, columns: tuple):
        """The node's values over the columns; `active`: the cases Python evaluates it for."""
        rule = self._RULES.get(type(node))
        if rule is None:
            raise AssertionError(f"no column form for {type(node).__name__}")  # the kinds check admits none
        return rule(self, node, active, columns)

    def _name(self, node: ast.Name, active: np.ndarray, columns: tuple):
        return columns[self.names.index(node.id)]

    def _constant(self, node: ast.Constant, active: np.ndarray, columns: tuple):
        return np.int64(int(node.value))

    def _unary(self, node: ast.UnaryOp, active: np.ndarray, columns: tuple):
        value = self.evaluate(node.operand, active, columns)
        if isinstance(node.op, ast.Not):
            return ~_truth(value)
        value = _integers(value)
        return -value if isinstance(node.op, ast.USub) else ~value if isinstance(node.op, ast.Invert) else value

    def _boolean(self, node: ast.BoolOp, active: np.ndarray, columns: tuple):
        """`and` / `or`: each value after the first evaluated only where Python goes on to it (both
        sides computed, no masks, when nothing under the node can fail)."""
        fallible = id(node) in self.fallible
        value = self.evaluate(node.values[0], active, columns)
        for following in node.values[1:]:
            go_on = _truth(value) if isinstance(node.op, ast.And) else ~_truth(value)
            if not fallible:
                value = np.where(go_on, self.evaluate(following, active, columns), value)
                continue
            reach = active & go_on
            value = np.where(go_on, self.evaluate(following, reach, columns), value) if reach.any() else value
        return value

    def _compare(self, node: ast.Compare, active: np.ndarray, columns: tuple):
        """A chained comparison: each comparator evaluated only where the chain still holds (every
        operand once, no masks, when nothing under the node can fail)."""
        if id(node) not in self.fallible:
            operands = [self.evaluate(o, active, columns) for o in (node.left, *node.comparators)]
            result = _ORDER[type(node.ops[0])](operands[0], operands[1])
            for k, op in enumerate(node.ops[1:], 1):
                result = result & _ORDER[type(op)](operands[k], operands[k + 1])
            return result
        result = np.ones(len(active), dtype=bool)
        left = self.evaluate(node.left, active, columns)
        for op, comparator in zip(node.ops, node.comparators):
            reach = active & result
            right = self.evaluate(comparator, reach, columns)
            result = result & _ORDER[type(op)](left, right)
            left = right
        return result

    def _if(self, node: ast.IfExp, active: np.ndarray, columns: tuple):
        """`x if test else y`: each branch evaluated only where it is taken (both, no masks, when
        nothing under the node can fail)."""
        test = _truth(self.evaluate(node.test, active, columns))
        if id(node) not in self.fallible:
            return np.where(test, self.evaluate(node.body, active, columns), self.evaluate(node.orelse, active, columns))
        body = self.evaluate(node.body, active & test, columns) if (active & test).any() else np.int64(0)
        orelse = self.evaluate(node.orelse, active & ~test, columns) if (active & ~test).any() else np.int64(0)
        return np.where(test, body, orelse)

    def _call(self, node: ast.Call, active: np.ndarray, columns: tuple):
        values = [_integers(self.evaluate(a, active, columns)) for a in node.args]
        if node.func.id == "abs":
            return np.abs(values[0])
        return (np.minimum if node.func.id == "min" else np.maximum).reduce(np.broadcast_arrays(*values))

    def binary(self, node: ast.BinOp, active: np.ndarray, columns: tuple):
        left = _integers(self.evaluate(node.left, active, columns))
        right = _integers(self.evaluate(node.right, active, columns))
        op = type(node.op)
        if op in _ARITHMETIC:
            return _ARITHMETIC[op](left, right)
        if op in (ast.FloorDiv, ast.Mod):
            zero = (right == 0) & active
            if zero.any():
                raise self.fail(node, "division by zero", zero, columns)
            right = np.where(right == 0, 1, right)
            return np.floor_divide(left, right) if op is ast.FloorDiv else np.mod(left, right)
        if op is ast.RShift:
            negative = (right < 0) & active
            if negative.any():
                raise self.fail(node, "negative shift count", negative, columns)
            return left >> np.clip(right, 0, 63)  # Python: x >> 63 and beyond is 0 or -1 for int64 x
        return left << right  # a constant of at most MAX_SHIFT, the result within int64 (the kinds check)

    # each kind of node a columnar term may hold -> how it is evaluated
    _RULES = {ast.Name: _name, ast.Constant: _constant, ast.UnaryOp: _unary, ast.BinOp: binary, ast.BoolOp: _boolean,
              ast.Compare: _compare, ast.IfExp: _if, ast.Call: _call}


def _spread(truth: np.ndarray, n: int) -> np.ndarray:
    """A term's truth over the n cases (a term of constants only: one value for all)."""
    return truth if truth.shape == (n,) else np.broadcast_to(truth, (n,))


def _truth(value) -> np.ndarray:
    return value if isinstance(value, np.ndarray) and value.dtype == bool else np.asarray(value) != 0


def _integers(value):
    """Booleans as the integers Python makes of them in arithmetic (True + 1 == 2, ~True == -2)."""
    return value.astype(np.int64) if isinstance(value, np.ndarray) and value.dtype == bool else (
        np.int64(value) if isinstance(value, (bool, np.bool_)) else value)
