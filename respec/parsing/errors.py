"""The parsers' errors: a malformed formula or file, and a formula naming an undeclared proposition.

Each names the file (or message section), line, column and the offending token, e.g.
``spec.structuredslugs:7:12: unknown variable 'foo' near 'foo'``.
"""

from __future__ import annotations

from respec.vocabulary.errors import CodedError, ErrorCode, quoted


class ParseError(CodedError):
    """A syntax or naming error at ``filename:line:column``; ``item`` is the offending token."""

    code = ErrorCode.INVALID_FORMULA

    def __init__(self, problem: str, token: str, filename: str = '<string>', line: int = 1,
                 column: int = 1):
        self.problem = problem
        self.filename = filename
        self.line = line
        self.column = column
        self.token = token
        super().__init__(f'{filename}:{line}:{column}: {problem} near {quoted(token)}', item=token)


class UnknownVariableError(ParseError):
    """A formula mentions a proposition that no [INPUT] / [OUTPUT] section declares."""

    code = ErrorCode.UNKNOWN_PROPOSITION
