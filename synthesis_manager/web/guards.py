"""What the GUI refuses before any route sees a request (plain ASGI middleware, ROS-free).

- A ``Host`` header other than the address the server listens on: 421. A web page from
  another site that re-points its own name at 127.0.0.1 (DNS rebinding) still sends its own
  name as Host, so it can no longer read the API. On a loopback address ``localhost`` is
  accepted too.
- A body over ``max_body_bytes`` (default 1 MB): 413, whether announced by Content-Length or
  streamed in chunks; the body is never read further (a 50 MB name once cost 860 MB of RAM).
- A POST (PUT, PATCH) whose Content-Type is not ``application/json``: 415. A page from another
  site can make a browser send a form (urlencoded, multipart or text/plain) without asking,
  but not a JSON request, so no other site can start work here (a simulation costs GBs).
- A JSON body nested deeper than ``MAX_JSON_NESTING`` arrays and objects: 400 TOO_DEEP, found
  by a scan of its brackets before anything parses it. The JSON decoder recurses once per level
  in C, and the process allows deep recursion for formulas (respec.nesting): a 200 KB body
  nested 100,000 deep overflowed the 8 MB stack of the main thread, which serves HTTP.
"""

from __future__ import annotations

import json
import re

from respec.vocabulary.errors import ErrorCode, quoted
from synthesis_manager.limits import MAX_BODY_BYTES

LOOPBACK_ADDRESSES = ('127.0.0.1', '::1')
#: Deepest nesting of arrays and objects in a request body (the API's own requests nest 2 deep).
MAX_JSON_NESTING = 32
# A JSON string, escapes included; an unterminated one runs to the end (so no text is scanned twice).
_JSON_STRING = re.compile(rb'"(?:[^"\\]|\\.)*"?', re.DOTALL)
_NOT_A_BRACKET = bytes(byte for byte in range(256) if byte not in b'[]{}')


def json_nesting_exceeds(body: bytes, limit: int = MAX_JSON_NESTING) -> bool:
    """Whether the JSON text ``body`` nests arrays and objects deeper than ``limit``.

    Brackets inside strings do not count. Linear in the body's size, without recursion, and
    it stops at the first level too deep; malformed JSON is left to the decoder to refuse.
    """
    depth = 0
    for bracket in _JSON_STRING.sub(b'', body).translate(None, _NOT_A_BRACKET):
        if bracket in b'[{':
            depth += 1
            if depth > limit:
                return True
        else:
            depth -= 1
    return False


def accepted_hosts(server_host: str, server_port: int) -> set[str]:
    """Host header values naming ``server_host:server_port``."""
    names = {server_host}
    if server_host in LOOPBACK_ADDRESSES:
        names |= {'localhost', *LOOPBACK_ADDRESSES}
    hosts = set()
    for name in names:
        shown = f'[{name}]' if ':' in name else name
        hosts.add(f'{shown}:{server_port}'.lower())
        if server_port == 80:
            hosts.add(shown.lower())
    return hosts


class RequestGuard:
    """ASGI middleware enforcing the Host check and the body size limit."""

    def __init__(self, app, max_body_bytes: int = MAX_BODY_BYTES):
        self.app = app
        self.max_body_bytes = max_body_bytes

    async def __call__(self, scope, receive, send):
        if scope['type'] != 'http':
            return await self.app(scope, receive, send)
        headers = {name.decode('latin-1').lower(): value.decode('latin-1') for name, value in scope['headers']}
        host = headers.get('host', '').lower()
        server = scope.get('server')
        if server is not None and host not in accepted_hosts(*server[:2]):
            return await _refuse(send, 421, 'BAD_HOST', 'host',
                                 f'this server answers only to {server[0]}:{server[1]}, not to Host '
                                 f'{quoted(host)}')
        declared = headers.get('content-length', '')
        if declared.isdigit() and int(declared) > self.max_body_bytes:
            return await _refuse(send, 413, 'TOO_LARGE', 'body', self._too_large())
        if scope['method'] not in ('POST', 'PUT', 'PATCH'):
            return await self.app(scope, receive, send)
        media_type = headers.get('content-type', '').split(';', 1)[0].strip().lower()
        if media_type != 'application/json':
            return await _refuse(send, 415, 'UNSUPPORTED_MEDIA_TYPE', 'content-type',
                                 f'{scope["method"]} requests must be sent as application/json, not '
                                 f'{quoted(media_type) if media_type else "without a Content-Type"}')
        body = bytearray()
        while True:
            message = await receive()
            if message['type'] != 'http.request':
                return  # the client went away
            body += message.get('body', b'')
            if len(body) > self.max_body_bytes:
                return await _refuse(send, 413, 'TOO_LARGE', 'body', self._too_large())
            if not message.get('more_body', False):
                break
        if json_nesting_exceeds(body):
            return await _refuse(send, 400, 'TOO_DEEP', 'body',
                                 f'the request body nests arrays and objects deeper than {MAX_JSON_NESTING} levels')
        return await self.app(scope, _replay(bytes(body), receive), send)

    def _too_large(self) -> str:
        return f'the request body is larger than {self.max_body_bytes} bytes'


def _replay(body: bytes, receive):
    """A ``receive`` that hands the already read body to the app, then the real channel."""
    sent = False

    async def replayed():
        nonlocal sent
        if not sent:
            sent = True
            return {'type': 'http.request', 'body': body, 'more_body': False}
        return await receive()
    return replayed


async def _refuse(send, status: int, error: str, item: str, message: str):
    """Answer with the GUI's error body ``{"error", "code", "item", "message"}``."""
    payload = json.dumps({'error': error, 'code': ErrorCode.INVALID_REQUEST, 'item': item, 'message': message}).encode()
    await send({'type': 'http.response.start', 'status': status,
                'headers': [(b'content-type', b'application/json'),
                            (b'content-length', str(len(payload)).encode()),
                            (b'connection', b'close')]})
    await send({'type': 'http.response.body', 'body': payload})
