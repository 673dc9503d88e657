"""Parse scenario expressions with lark into :mod:`retrokit.dsl.nodes` trees.

The grammar is ``grammar.lark`` next to this file, parsed with LALR(1). Its
aliased alternatives map one-to-one onto the methods of :class:`ToAst`. Syntax
errors become :class:`~retrokit.errors.ScenarioSyntaxError` pointing at the
offending character, with what was expected; errors raised while building the
tree (lark wraps them in ``VisitError``) are unwrapped.

Every later pass walks the tree recursively, and the generated Python nests as
the expression does, so an expression may nest at most :data:`MAX_DEPTH`
operations deep; deeper ones are refused before the tree is built. Number
literals must be finite and fit in 64 bits: the console's values do.
"""

from __future__ import annotations

import functools
import math
from pathlib import Path

from lark import Lark, Token, Transformer, Tree, v_args
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, UnexpectedToken, VisitError

from retrokit.dsl import nodes as n
from retrokit.dsl.source import Snippet
from retrokit.errors import ScenarioError, ScenarioSyntaxError

_GRAMMAR = Path(__file__).with_name("grammar.lark")

#: How many operations (operators, calls, lookups) may enclose one another in an
#: expression: a sum of 101 terms, or 101 nested calls, is refused. Longer
#: formulas are split into definitions (``define:``), which have no such limit.
MAX_DEPTH = 100

#: How deep brackets may nest, redundant ones included: far more than :data:`MAX_DEPTH`
#: operations use, few enough that the parser stays fast on hostile text.
MAX_BRACKETS = 10 * MAX_DEPTH

#: The largest integer literal: the console's values are at most 64 bits wide.
MAX_INT = 2**64 - 1

#: Trees of expressions parsed before, by their text. Games share expressions (stable-retro's ~1,000
#: scenarios use ~350 different ones: `retrokit games` parsed "lives == 0" 428 times), and a tree is
#: immutable and holds no trace of its source, so one tree serves every snippet with the same text. Only
#: successful parses are kept (an error must point into its own snippet); bounded in count and text length.
_PARSED: dict[str, n.Node] = {}
_PARSED_MAX = 4096
_PARSED_TEXT_MAX = 1000

#: How lark's terminal names read in a message.
_TERMINALS = {
    "LPAR": "'('", "RPAR": "')'", "LSQB": "'['", "RSQB": "']'", "COMMA": "','",
    "NAME": "a name", "QUOTED_NAME": "a name", "INT": "a number", "HEX": "a number",
    "FLOAT": "a number", "TRUE": "'true'", "FALSE": "'false'", "NOT": "'not'",
    "IF": "'if'", "ELSE": "'else'", "AND": "'and'", "OR": "'or'",
    "COMP_OP": "a comparison", "ADD_OP": "'+' or '-'", "MUL_OP": "'*', '/', '//' or '%'",
    "UNARY_OP": "'-'", "SHIFT_OP": "'<<' or '>>'", "BIT_OR": "'|'", "BIT_XOR": "'^'",
    "BIT_AND": "'&'", "$END": "the end of the expression",
}

#: Terminals summed up as "an operator" in messages.
_OPERATORS = {"COMP_OP", "ADD_OP", "MUL_OP", "SHIFT_OP", "BIT_OR", "BIT_XOR", "BIT_AND", "AND", "OR", "IF"}

#: Hints for characters people bring from other languages.
_HINTS = {
    "=": "to compare, write '=='",
    "!": "write 'not', or '!=' to compare",
    "&&": "write 'and'",
    "||": "write 'or'",
    "?": "write 'a if condition else b'",
    "'": "names with odd characters are written in backquotes: `my field`",
    '"': "names with odd characters are written in backquotes: `my field`",
}


@functools.cache
def _lark() -> Lark:
    return Lark(_GRAMMAR.read_text(), parser="lalr", propagate_positions=True, maybe_placeholders=True)


def warm() -> None:
    """Build the grammar's parser now, once for every process forked from this one (an evaluation's fork server)."""
    _lark()


def _literal(token: Token) -> str:
    """The digits of a number token, without ``_`` separators."""
    return str(token).replace("_", "")


@v_args(meta=True)
class ToAst(Transformer):
    """Turn lark's parse tree into :mod:`retrokit.dsl.nodes` nodes."""

    def __init__(self, snippet: Snippet) -> None:
        super().__init__()
        self._snippet = snippet

    def int_literal(self, meta, children):
        text = _literal(children[0])
        # Checked by length first: int() refuses over 4300 digits, and 64 bits need at most 20.
        digits = text[2:] if text[1:2] in "xX" else text
        if len(digits.lstrip("0")) > 20 or int(text, 16 if digits is not text else 10) > MAX_INT:
            shown = text if len(text) <= 24 else f"{text[:10]}...{text[-4:]} ({len(text)} digits)"
            raise self._snippet.error(
                ScenarioSyntaxError, meta.start_pos, meta.end_pos,
                f"expected an integer of at most 64 bits (up to {MAX_INT}), got {shown}; use a smaller number",
            )
        if len(text) > 1 and text[0] == "0" and text[1] not in "xX":
            raise self._snippet.error(
                ScenarioSyntaxError, meta.start_pos, meta.end_pos,
                f"the number {text} has a leading zero; write {int(text)} (decimal) or 0x{text.lstrip('0') or '0'} (hex)",
            )
        return n.Number(start=meta.start_pos, end=meta.end_pos, value=int(text, 0))

    def float_literal(self, meta, children):
        value = float(_literal(children[0]))
        if not math.isfinite(value):  # e.g. 1e999: the generated code could not even name it
            raise self._snippet.error(
                ScenarioSyntaxError, meta.start_pos, meta.end_pos,
                f"expected a finite decimal number (at most about 1.8e308), got {children[0]!s}; use a smaller number",
            )
        return n.Number(start=meta.start_pos, end=meta.end_pos, value=value)

    def true(self, meta, children):
        return n.Bool(start=meta.start_pos, end=meta.end_pos, value=True)

    def false(self, meta, children):
        return n.Bool(start=meta.start_pos, end=meta.end_pos, value=False)

    def name(self, meta, children):
        text = str(children[0])
        quoted = text.startswith("`")
        return n.Name(start=meta.start_pos, end=meta.end_pos, id=text[1:-1] if quoted else text, quoted=quoted)

    def arguments(self, meta, children):
        return tuple(children)

    def call(self, meta, children):
        func, args = children
        return n.Call(start=meta.start_pos, end=meta.end_pos, func=str(func), name_end=func.end_pos, args=args or ())

    def lookup(self, meta, children):
        table, keys = children
        return n.Lookup(start=meta.start_pos, end=meta.end_pos, table=str(table), name_end=table.end_pos, keys=keys)

    def unary(self, meta, children):
        op, operand = children
        return n.Unary(start=meta.start_pos, end=meta.end_pos, op=str(op), operand=operand)

    def binary(self, meta, children):
        left, op, right = children
        return n.Binary(start=meta.start_pos, end=meta.end_pos, op=str(op), op_start=op.start_pos, left=left, right=right)

    def compare(self, meta, children):
        return n.Compare(
            start=meta.start_pos, end=meta.end_pos,
            ops=tuple(str(op) for op in children[1::2]), operands=tuple(children[0::2]),
        )

    def and_(self, meta, children):
        return n.Logic(start=meta.start_pos, end=meta.end_pos, op="and", left=children[0], right=children[1])

    def or_(self, meta, children):
        return n.Logic(start=meta.start_pos, end=meta.end_pos, op="or", left=children[0], right=children[1])

    def not_(self, meta, children):
        return n.Not(start=meta.start_pos, end=meta.end_pos, operand=children[1])

    def ifelse(self, meta, children):
        then, cond, other = children
        return n.IfElse(start=meta.start_pos, end=meta.end_pos, cond=cond, then=then, other=other)


def parse(snippet: Snippet) -> n.Node:
    """Parse one expression.

    Args:
        snippet: The expression and where it comes from.

    Returns:
        The root of its syntax tree.

    Raises:
        ScenarioSyntaxError: The text is not an expression.
    """
    cached = _PARSED.get(snippet.text)
    if cached is not None:
        return cached
    if not snippet.text.strip():
        raise snippet.error(ScenarioSyntaxError, 0, len(snippet.text), "the expression is empty")
    _check_brackets(snippet)
    try:
        tree = _lark().parse(snippet.text)
    except UnexpectedInput as exc:
        raise _syntax_error(snippet, exc) from None
    _check_depth(snippet, tree)
    try:
        root = ToAst(snippet).transform(tree)
    except VisitError as exc:
        if isinstance(exc.orig_exc, ScenarioError):
            raise exc.orig_exc from None
        raise
    if len(snippet.text) <= _PARSED_TEXT_MAX and len(_PARSED) < _PARSED_MAX:
        _PARSED[snippet.text] = root
    return root


def _check_brackets(snippet: Snippet) -> None:
    """Refuse brackets nested more than :data:`MAX_BRACKETS` deep, before lark parses them.

    Redundant brackets are no operation, so :func:`_check_depth` does not count them, but lark's
    parser slows down faster than their number grows: 32,000 nested ``(`` took it seconds.
    """
    depth = 0
    for index, char in enumerate(snippet.text):
        if char in "([":
            depth += 1
            if depth > MAX_BRACKETS:
                raise snippet.error(
                    ScenarioSyntaxError, index, index + 1,
                    f"expected an expression nesting at most {MAX_DEPTH} operations, and brackets at most "
                    f"{MAX_BRACKETS} deep; got deeper brackets; split it into definitions under 'define:'",
                )
        elif char in ")]":
            depth -= 1


def _check_depth(snippet: Snippet, tree: Tree) -> None:
    """Refuse a tree nesting more than MAX_DEPTH operations, walking it without recursion.

    Lark's ``arguments`` node is no operation of its own: a call and its
    arguments count as one level.
    """
    stack: list[tuple[Tree, int]] = [(tree, 1)]
    while stack:
        node, depth = stack.pop()
        if depth > MAX_DEPTH:
            meta = node.meta
            raise snippet.error(
                ScenarioSyntaxError, meta.start_pos, meta.end_pos,
                f"expected an expression nesting at most {MAX_DEPTH} operations (operators, calls, lookups), "
                f"got more; split it into definitions under 'define:' (a long sum: add parts defined separately)",
            )
        for child in node.children:
            if isinstance(child, Tree):
                stack.append((child, depth if child.data == "arguments" else depth + 1))


def _syntax_error(snippet: Snippet, exc: UnexpectedInput) -> ScenarioSyntaxError:
    """Turn a lark error into a message saying what was found and what was expected."""
    text = snippet.text
    if isinstance(exc, UnexpectedCharacters):
        pos = exc.pos_in_stream
        found = text[pos]
        expected = exc.allowed
        width = 1
    elif isinstance(exc, UnexpectedToken) and exc.token.type != "$END":
        pos = exc.token.start_pos
        found = str(exc.token)
        expected = exc.expected
        width = max(1, len(found))
    else:  # the text stopped too early
        pos = len(text.rstrip())
        found = ""
        expected = exc.expected if isinstance(exc, (UnexpectedToken, UnexpectedEOF)) else set()
        width = 1
    expected = set(getattr(exc, "accepts", None) or expected)
    wanted = sorted({_TERMINALS.get(name, name) for name in expected - _OPERATORS})
    if expected & _OPERATORS:
        wanted.insert(0, "an operator")
    what = f"unexpected {found!r}" if found else "the expression ends too early"
    message = what + (f"; expected {', '.join(wanted)}" if wanted else "")
    hint = _HINTS.get(text[pos : pos + 2]) or _HINTS.get(found[:1])
    if hint:
        message += f" ({hint})"
    return snippet.error(ScenarioSyntaxError, pos, pos + width, message)
