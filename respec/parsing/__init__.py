"""Parsers for slugs' two specification formats and for LTLSpecification messages.

* ``.structuredslugs``: infix formulas (``parse_structuredslugs``, ``parse_formula(text, 'infix')``),
  with structured slugs' integer variables;
* ``.slugsin``: prefix formulas (``parse_slugsin``, ``parse_formula(text, 'prefix')``), including
  slugs' memory buffers ``$ n f0 ... fn-1`` and recalls ``? i``;
* LTLSpecification messages: ``spec_from_text_sections``.

Every parser returns ``respec.ltl`` trees built with its constructors, so the result of
parsing printed text is the tree that was printed (``parse_formula(to_infix(f)) == f``).
Every error is a ``ParseError`` naming the file (or message section), line, column and the
offending token, e.g. ``spec.structuredslugs:7:12: unknown variable 'foo' near 'foo'``.

Modules, each importing only those above it:

    errors          ParseError, UnknownVariableError
    integers        structured slugs' integer variables, bit-blasted
    scope           proposition names, each section's scope (integer variables too), error positions
    operators       the binary operators: how tightly each binds, the nodes each makes
    infix           the reference reader of infix formulas
    prefix          the reference reader of prefix (slugsin) formulas
    grammar         one formula in either syntax, read by its reference reader (which explains errors)
    quick           quick readers of one file line over plain strings (infix and slugsin)
    shapes          the lines of a section that share a shape, built together
    files           cutting a file into its sections
    specifications  specifications from files and message sections

How large files are read fast, and why the fast paths give the grammar's trees: docs/parsing.md.
"""

from respec.parsing.errors import ParseError, UnknownVariableError
from respec.parsing.grammar import parse_formula
from respec.parsing.integers import IntegerVariable
from respec.parsing.operators import xor
from respec.parsing.specifications import parse_slugsin, parse_structuredslugs, spec_from_text_sections

__all__ = [
    'ParseError', 'UnknownVariableError', 'parse_formula', 'parse_structuredslugs',
    'parse_slugsin', 'spec_from_text_sections', 'IntegerVariable', 'xor',
]
