"""The GUI's request errors: each answers with an HTTP status and
``{"error", "code", "item", "message"}``.

``error`` names the kind of HTTP failure (``NOT_FOUND``, ...); ``code`` is the
SynthesisErrorCodes name, as for every user-facing error.
"""

from __future__ import annotations

from respec.errors import CodedError, quoted


class GuiRequestError(CodedError):
    """A request the GUI cannot serve; ``item`` names what was wrong."""

    status = 400
    kind = 'BAD_REQUEST'
    code = 'INVALID_REQUEST'

    def to_dict(self) -> dict:
        item = self.item if isinstance(self.item, str) else quoted(self.item)
        return {'error': self.kind, 'code': self.code, 'item': item, 'message': str(self)}


class NotFoundError(GuiRequestError):
    """An unknown system, job or artifact name."""

    status = 404
    kind = 'NOT_FOUND'


class InvalidJobRequestError(GuiRequestError):
    """A job request with a missing, mistyped or malformed field."""

    status = 422
    kind = 'INVALID_REQUEST'


class NotAvailableError(GuiRequestError):
    """The item exists but not in this state (e.g. no state machine to download yet)."""

    status = 409
    kind = 'NOT_AVAILABLE'


class ArtifactFailedError(GuiRequestError):
    """Building a download failed (e.g. Graphviz is not installed)."""

    status = 500
    kind = 'ARTIFACT_FAILED'
    code = 'FAILURE'


class BusyError(GuiRequestError):
    """Too many jobs are unfinished: the request is refused, try again later."""

    status = 503
    kind = 'BUSY'
    code = 'BUSY'


class TooManyRequestsError(GuiRequestError):
    """Too much of one kind of work is running: try again after ``retry_after`` seconds
    (sent as the Retry-After header)."""

    status = 429
    kind = 'BUSY'
    code = 'BUSY'

    def __init__(self, message: str, item='', retry_after: int = 10):
        super().__init__(message, item)
        self.retry_after = retry_after
