"""The GUI's request errors: each answers with an HTTP status and
``{"error", "code", "item", "message"}``.

``error`` names the kind of HTTP failure (``NOT_FOUND``, ...); ``code`` is the
SynthesisErrorCodes name, as for every user-facing error. A :class:`BusyError` (too much work in
progress) is 503, or 429 with Retry-After when it says when to come back.
"""

from __future__ import annotations

from respec.vocabulary.errors import CodedError, ErrorCode, quoted
from synthesis_manager.limits import BusyError


def http_answer(error: GuiRequestError | BusyError) -> tuple[int, dict, dict | None]:
    """Status, JSON body and headers answering ``error`` (a GuiRequestError or BusyError)."""
    if isinstance(error, BusyError):
        headers = {'Retry-After': str(error.retry_after)} if error.retry_after else None
        return (429 if error.retry_after else 503), _body('BUSY', error), headers
    return error.status, _body(error.kind, error), None


def _body(kind: str, error: CodedError) -> dict:
    item = error.item if isinstance(error.item, str) else quoted(error.item)
    return {'error': kind, 'code': error.code, 'item': _encodable(item), 'message': _encodable(str(error))}


def _encodable(text: str) -> str:
    """``text`` with any lone surrogate written as its escape: the answer must encode as UTF-8."""
    return text.encode('utf-8', 'backslashreplace').decode('utf-8')


class GuiRequestError(CodedError):
    """A request the GUI cannot serve; ``item`` names what was wrong."""

    status = 400
    kind = 'BAD_REQUEST'
    code = ErrorCode.INVALID_REQUEST

    def to_dict(self) -> dict:
        return _body(self.kind, self)


class NotFoundError(GuiRequestError):
    """An unknown system, job or artifact name."""

    status = 404
    kind = 'NOT_FOUND'


class InvalidJobRequestError(GuiRequestError):
    """A job request with a missing, mistyped or malformed field."""

    status = 422
    kind = 'INVALID_REQUEST'


class InvalidCharacterError(InvalidJobRequestError):
    """A request string holding a control character (NUL included) or a lone surrogate."""

    kind = 'INVALID_CHARACTER'


class NotAvailableError(GuiRequestError):
    """The item exists but not in this state (e.g. no state machine to download yet)."""

    status = 409
    kind = 'NOT_AVAILABLE'


class ArtifactFailedError(GuiRequestError):
    """Building a download failed (e.g. Graphviz is not installed)."""

    status = 500
    kind = 'ARTIFACT_FAILED'
    code = ErrorCode.FAILURE
