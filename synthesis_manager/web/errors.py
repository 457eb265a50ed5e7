"""The GUI's request errors: each answers with an HTTP status and ``{"error", "item", "message"}``."""

from __future__ import annotations


class GuiRequestError(Exception):
    """A request the GUI cannot serve; ``item`` names what was wrong."""

    status = 400
    code = 'BAD_REQUEST'

    def __init__(self, message: str, item: str):
        super().__init__(message)
        self.item = item

    def to_dict(self) -> dict:
        return {'error': self.code, 'item': self.item, 'message': str(self)}


class NotFoundError(GuiRequestError):
    """An unknown system, job or artifact name."""

    status = 404
    code = 'NOT_FOUND'


class InvalidJobRequestError(GuiRequestError):
    """A job request with a missing, mistyped or malformed field."""

    status = 422
    code = 'INVALID_REQUEST'


class NotAvailableError(GuiRequestError):
    """The item exists but not in this state (e.g. no state machine to download yet)."""

    status = 409
    code = 'NOT_AVAILABLE'


class ArtifactFailedError(GuiRequestError):
    """Building a download failed (e.g. Graphviz is not installed)."""

    status = 500
    code = 'ARTIFACT_FAILED'
