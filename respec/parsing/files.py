"""Cutting a specification file into its sections ([INPUT], [OUTPUT], [ENV_INIT], ...).

The file is cut at its header lines, not walked line by line; each section keeps its non-blank
lines (comments removed) and finds where one of them is in the file only when it is asked to
(for an error's position).
"""

from __future__ import annotations

import itertools
from bisect import bisect_right
from typing import Iterator

from respec.parsing.errors import ParseError
from respec.parsing.scope import Source
from respec.spec import FORMULA_SECTIONS, PROPOSITION_SECTIONS, SLUGS_HEADERS

_SECTION_OF_HEADER = {header: section for section, header in SLUGS_HEADERS.items()}


class SectionText:
    """A section's non-blank lines (comments and surrounding blanks removed), and where each
    one is in the file (worked out only for the lines that need a position: errors)."""

    def __init__(self) -> None:
        self.lines: list[str] = []
        self._parts: list[tuple[int, int, list[str], list[int] | None]] = []

    def add(self, first_line: int, contents: list[str]) -> None:
        """The lines after one header; ``first_line``: the file line of ``contents[0]``."""
        stripped = list(map(str.strip, contents))
        while stripped and not stripped[-1]:  # the blank lines before the next header
            stripped.pop()
        kept = [index for index, line in enumerate(stripped) if line] if '' in stripped else None
        self._parts.append((len(self.lines), first_line, contents, kept))
        self.lines.extend(stripped if kept is None else [stripped[index] for index in kept])

    def first_lines(self) -> list[int]:
        """The file line where each part of the section (the text after each of its headers) starts."""
        return [part[1] for part in self._parts]

    def source(self, index: int, filename: str) -> Source:
        """Where the section's line ``index`` is in the file."""
        # The last part starting at or before the line (1 << 62: beyond any file line).
        start, first_line, contents, kept = self._parts[bisect_right(self._parts, (index, 1 << 62)) - 1]
        position = index - start if kept is None else kept[index - start]
        return Source(filename, first_line + position, _column(contents[position]))


# Line breaks other than '\n' that str.splitlines() also honours.
_OTHER_LINE_BREAKS = '\r\x0b\x0c\x1c\x1d\x1e\x85\u2028\u2029'


def sections_of(text: str, filename: str) -> dict[str, SectionText]:
    """Each section's lines: the file is cut at its header lines, not walked line by line."""
    if any(mark in text for mark in _OTHER_LINE_BREAKS):
        text = '\n'.join(text.splitlines())
    sections = {section: SectionText() for section in PROPOSITION_SECTIONS + FORMULA_SECTIONS}
    section, line, position = None, 1, 0
    for header in itertools.chain(_header_lines(text), [None]):
        chunk = text[position:header[0] if header else len(text)]
        body = chunk.split('\n')
        if not body[-1]:
            body.pop()  # what follows the chunk's last line break
        if '#' in chunk:
            body = [raw.partition('#')[0] for raw in body]
        if section is not None:
            sections[section].add(line, body)
        else:
            for offset, content in enumerate(body):
                if content.strip():
                    raise ParseError('text before the first section header', content.strip(), filename,
                                     line + offset, _column(content))
        if header is None:
            break
        line += chunk.count('\n')
        content = text[header[0]:header[1]].partition('#')[0]
        stripped = content.strip()
        name = stripped[1:-1] if stripped.endswith(']') else None
        if name not in _SECTION_OF_HEADER:
            raise ParseError('unknown section header (expected one of '
                             + ', '.join(f'[{h}]' for h in SLUGS_HEADERS.values()) + ')',
                             stripped, filename, line, _column(content))
        section, line, position = _SECTION_OF_HEADER[name], line + 1, header[1] + 1
    return sections


def _header_lines(text: str) -> Iterator[tuple[int, int]]:
    """(start, end) of each line whose first non-blank character is '[' (formulas have no '[')."""
    at = text.find('[')
    while at != -1:
        start = text.rfind('\n', 0, at) + 1
        if text[start:at].isspace() or start == at:
            end = text.find('\n', at)
            end = len(text) if end == -1 else end
            yield start, end
            at = text.find('[', end)
        else:
            at = text.find('[', at + 1)


def _column(content: str) -> int:
    """The column of a line's first non-blank character."""
    return len(content) - len(content.lstrip()) + 1
