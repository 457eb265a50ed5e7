"""The README's shell commands, and its "Use it from FlexBE" section."""

import re
import shlex


def readme_commands(text: str) -> list[str]:
    """The commands of the README's ``sh`` blocks: continuation lines joined, comments dropped."""
    commands = []
    for block in re.findall(r'^```(?:sh|bash)\n(.*?)^```', text, flags=re.M | re.S):
        pending = ''
        for line in block.replace('\\\n', ' ').splitlines():
            pending = f'{pending}\n{line}' if pending else line
            try:
                words = shlex.split(pending, comments=True)
            except ValueError:  # a quoted argument goes on over the next line
                continue
            if words:
                commands.append(pending.strip())
            pending = ''
        assert not pending, f'unterminated quote in README: {pending}'
    return commands


FLEXBE_SECTION = '## Use it from FlexBE'


def flexbe_section(text: str) -> str:
    """The README's "Use it from FlexBE" section, up to the next ``##`` heading."""
    start = text.index(f'\n{FLEXBE_SECTION}\n')
    end = text.find('\n## ', start + 1)
    return text[start:end if end >= 0 else len(text)]
