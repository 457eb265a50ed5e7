"""The reference readers of one formula, in either of slugs' syntaxes.

* infix: ``parse_formula(text, 'infix')``, as in ``.structuredslugs`` files (respec.parsing.infix);
* prefix: ``parse_formula(text, 'prefix')``, as in ``.slugsin`` files (respec.parsing.prefix).

They return ``respec.ltl`` trees built with its constructors, so the result of parsing printed
text is the tree that was printed (``parse_formula(to_infix(f)) == f``). They keep every token's
position, check each proposition against its section's scope, and explain every error; the
faster readers (respec.parsing.quick, respec.parsing.shapes) leave them any line they do not
expect.
"""

from __future__ import annotations

from respec.vocabulary.errors import quoted
from respec.ltl import Formula
from respec.parsing.errors import ParseError
from respec.parsing.scope import ANY, Scope, Source


def parse_formula(text: str, syntax: str = 'infix') -> Formula:
    """Parse one formula: ``syntax`` is 'infix' (structured slugs) or 'prefix' (slugsin).

    Any variable name is accepted; specification parsers check names against declarations.
    """
    if not isinstance(text, str):
        raise ParseError('formula must be a string', quoted(text))
    return parse_in_scope(text, syntax, ANY, Source())


def parse_in_scope(text: str, syntax: str, scope: Scope, source: Source) -> Formula:
    """Parse one formula whose propositions ``scope`` allows, placing errors by ``source``."""
    # The reference readers load on first use: a well-formed slugsin file is read by the quick
    # readers alone, and a gr1synth run would otherwise pay for compiling the infix tokenizer.
    if syntax == 'infix':
        from respec.parsing.infix import InfixParser
        return InfixParser(text, scope, source).parse()
    if syntax == 'prefix':
        from respec.parsing.prefix import PrefixParser
        return PrefixParser(text, scope, source).parse()
    raise ValueError(f"unknown formula syntax {syntax!r} (expected 'infix' or 'prefix')")
