"""The GUI's request errors: each answers with an HTTP status and ``{"error", "item", "message"}``.

``error`` is the SynthesisErrorCodes name (``code``) like everywhere else; the HTTP status
tells the kinds of bad request apart.
"""

from __future__ import annotations

from respec.errors import CodedError


class GuiRequestError(CodedError):
    """A request the GUI cannot serve; ``item`` names what was wrong."""

    status = 400
    code = 'INVALID_REQUEST'

    def to_dict(self) -> dict:
        return {'error': self.code, 'item': self.item, 'message': str(self)}


class NotFoundError(GuiRequestError):
    """An unknown system, job or artifact name."""

    status = 404


class InvalidJobRequestError(GuiRequestError):
    """A job request with a missing, mistyped or malformed field."""

    status = 422


class NotAvailableError(GuiRequestError):
    """The item exists but not in this state (e.g. no state machine to download yet)."""

    status = 409


class ArtifactFailedError(GuiRequestError):
    """Building a download failed (e.g. Graphviz is not installed)."""

    status = 500
    code = 'FAILURE'
