"""The studio's guards: the token every request shows, the Origin a WebSocket comes from, and the one path resolver.

The server listens on 127.0.0.1 only, but any web page the user opens can
send requests to it; so, as Jupyter does, every HTTP request and WebSocket
must carry a random token that only the printed URL holds: in the query
(``?token=``), in the ``X-Retrokit-Token`` header (what the page's scripts
send), or in the cookie the server sets when the URL's token is first seen
(so the page's ``<script>`` and ``<img>`` requests carry it; ``SameSite=Strict``
keeps other sites' pages from sending it). WebSockets must also come from
the studio's own origin, and the ``Host`` header must name 127.0.0.1 or
localhost, which stops DNS rebinding.

:func:`resolve_path` is the one function through which a request may name a
file: it refuses whatever would leave the game's folders and the data folder.
The request helpers (:func:`json_body`, :func:`expect`) cap bodies and check
types, so hostile input ends in a 4xx JSON error, never a 500; :func:`session_of`
gives every route its session (here, below the app and its routes, so no
route imports the app that mounts it).
"""

from __future__ import annotations

import asyncio
import json
import os
import secrets
from collections.abc import Iterable, Sequence
from http.cookies import SimpleCookie
from pathlib import Path
from typing import TYPE_CHECKING, Any
from urllib.parse import parse_qs, unquote

from starlette.requests import Request
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from retrokit.errors import AccessDeniedError, InvalidArgumentError, RequestTooLargeError, shown
from retrokit.paths import data_dir

if TYPE_CHECKING:
    from starlette.websockets import WebSocket

    from retrokit.data.games import Game
    from retrokit.studio.session import Session

TOKEN_HEADER = "x-retrokit-token"
MAX_BODY = 1 << 20
"""The largest request body, in bytes: a scenario or a game.yaml is far smaller."""
_HOSTS = ("127.0.0.1", "localhost")
NAME_MAX = 250
"""The longest file name a request may give, in bytes: file systems hold 255, and the studio adds a suffix."""


def new_token() -> str:
    """A fresh random token (URL-safe)."""
    return secrets.token_urlsafe(24)


def cookie_name(port: int) -> str:
    """The token cookie's name: one per port, as browsers share cookies between a host's ports."""
    return f"retrokit-studio-{port}"


def allowed_origins(port: int) -> tuple[str, ...]:
    """The origins a WebSocket may come from: the studio's own page."""
    return tuple(f"http://{host}:{port}" for host in _HOSTS)


class Guard:
    """ASGI middleware that refuses a request without the token, from another origin, or with a body too large.

    Args:
        app: The application it guards.
        token: The token the printed URL holds.
        port: The port the server listens on (for the Origin and Host checks, and the cookie's name).
    """

    def __init__(self, app: ASGIApp, token: str, port: int) -> None:
        self.app = app
        self.token = token
        self.port = port

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] not in ("http", "websocket"):
            await self.app(scope, receive, send)
            return
        headers = {k.decode("latin-1").lower(): v.decode("latin-1") for k, v in scope.get("headers", [])}
        problem = self._problem(scope, headers)
        if problem:
            sending = send if scope["type"] == "websocket" else self._with_headers(send, cookie=False)
            await _refuse(scope, receive, sending, 403, problem, "AccessDeniedError")
            return
        if scope["type"] == "websocket":
            await self.app(scope, receive, send)
            return
        send = self._with_headers(send, cookie=_query_token(scope) is not None)
        problem = _forged(scope["method"], headers, self.port)
        if problem:
            await _refuse(scope, receive, send, 403, problem, "AccessDeniedError")
            return
        length = headers.get("content-length", "0")
        if not length.isdigit() or int(length) > MAX_BODY:
            await _refuse(scope, receive, send, 413, _too_large(length), "RequestTooLargeError")
            return
        try:
            await self.app(scope, _capped(receive), send)
        except asyncio.CancelledError:  # Ctrl-C cancels what still runs: a stop, not an error to print
            if scope["type"] == "http":
                return
            raise

    def _problem(self, scope: Scope, headers: dict[str, str]) -> str:
        host = headers.get("host", "")
        if host.rpartition(":")[0] not in _HOSTS and host not in _HOSTS:
            return f"Expected a request to 127.0.0.1 or localhost; found Host {shown(host)}. Open the URL the studio printed."
        given = _query_token(scope) or headers.get(TOKEN_HEADER) or _cookie_token(headers, cookie_name(self.port))
        if not given or not secrets.compare_digest(given.encode(), self.token.encode()):
            what = "a wrong token" if given else "no token"
            return (
                f"Expected the studio's token (?token= in the URL it printed, or the {TOKEN_HEADER} header); "
                f"found {what}. Open the URL that `retrokit studio` printed."
            )
        origin = headers.get("origin")
        if scope["type"] == "websocket" and origin is not None and origin not in allowed_origins(self.port):
            return (
                f"Expected a WebSocket from the studio's page ({' or '.join(allowed_origins(self.port))}); "
                f"found Origin {shown(origin)}."
            )
        return ""

    def _with_headers(self, send: Send, *, cookie: bool) -> Send:
        """``send`` adding the security headers to every response, and the token cookie if ``cookie``."""
        added = [(name.encode(), value.encode()) for name, value in security_headers(self.port).items()]
        if cookie:
            added.append((b"set-cookie", f"{cookie_name(self.port)}={self.token}; Path=/; HttpOnly; SameSite=Strict".encode()))

        async def sending(message: Message) -> None:
            if message["type"] == "http.response.start":
                message = {**message, "headers": [*message.get("headers", []), *added]}
            await send(message)

        return sending


def security_headers(port: int) -> dict[str, str]:
    """The headers on every HTTP response: no framing, no sniffing, no referrer, no cache; scripts only from the studio."""
    sockets = " ".join(f"ws://{host}:{port}" for host in _HOSTS)
    return {
        "Content-Security-Policy": (
            "default-src 'self'; script-src 'self'; style-src 'self' 'unsafe-inline'; img-src 'self' data: blob:; "
            f"connect-src 'self' {sockets}; object-src 'none'; base-uri 'none'; form-action 'self'; "
            "frame-ancestors 'none'"
        ),
        "X-Content-Type-Options": "nosniff",
        "Referrer-Policy": "no-referrer",
        "Cache-Control": "no-store",
        "X-Frame-Options": "DENY",  # frame-ancestors' older twin, for browsers without CSP level 2
    }


SAFE_METHODS = ("GET", "HEAD")
"""Methods that change nothing: every other request must show it comes from the studio's own page."""


def _forged(method: str, headers: dict[str, str], port: int) -> str:
    """Why a state-changing request may come from another page (a forged one), or ``""``.

    Another page on 127.0.0.1 (another port: the same *site*, so the browser
    sends the token cookie) can post a form or a no-cors ``fetch``. Such a
    request says where it comes from (``Sec-Fetch-Site``, ``Origin``), and it
    can carry neither a custom header nor ``Content-Type: application/json``
    without a CORS preflight, which the studio never grants. The page's
    scripts send both.
    """
    if method in SAFE_METHODS:
        return ""
    site = headers.get("sec-fetch-site")
    if site is not None and site not in ("same-origin", "none"):
        return (
            f"Expected a request from the studio's own page; found one from another page (Sec-Fetch-Site {shown(site)}). "
            "Use the studio's page, or send the request without a browser."
        )
    origin = headers.get("origin")
    if origin is not None and origin not in allowed_origins(port):
        return (
            f"Expected a request from the studio's page ({' or '.join(allowed_origins(port))}); found Origin "
            f"{shown(origin)}. Use the studio's page."
        )
    content_type = headers.get("content-type", "").split(";")[0].strip().lower()
    if not headers.get(TOKEN_HEADER) and content_type != "application/json":
        return (
            f"Expected a JSON request (Content-Type: application/json) or the {TOKEN_HEADER} header; found "
            f"{'Content-Type ' + shown(content_type) if content_type else 'no Content-Type'}. "
            "Send JSON, as the studio's page does."
        )
    return ""


def _query_token(scope: Scope) -> str | None:
    values = parse_qs(scope.get("query_string", b"").decode("latin-1")).get("token")
    return values[0] if values else None


def _cookie_token(headers: dict[str, str], name: str) -> str | None:
    cookie = SimpleCookie()
    try:
        cookie.load(headers.get("cookie", ""))
    except Exception:  # a malformed Cookie header is no token  # noqa: BLE001
        return None
    return cookie[name].value if name in cookie else None


def _too_large(length: str) -> str:
    return (
        f"Expected a request body of at most {MAX_BODY:,} bytes with a Content-Length; found {shown(length)}. "
        "Send less."
    )


def _capped(receive: Receive) -> Receive:
    """``receive`` that refuses a body growing past :data:`MAX_BODY` (a chunked one has no Content-Length)."""
    seen = 0

    async def receiving() -> Message:
        nonlocal seen
        message = await receive()
        if message["type"] == "http.request":
            seen += len(message.get("body", b""))
            if seen > MAX_BODY:
                raise RequestTooLargeError(_too_large(f"{seen:,} bytes and more"))
        return message

    return receiving


async def _refuse(scope: Scope, receive: Receive, send: Send, status: int, error: str, kind: str) -> None:
    if scope["type"] == "websocket":
        await receive()  # websocket.connect
        await send({"type": "websocket.close", "code": 1008, "reason": error[:120]})
        return
    body = json.dumps({"error": error, "kind": kind}).encode()
    await send({"type": "http.response.start", "status": status,
                "headers": [(b"content-type", b"application/json"), (b"content-length", str(len(body)).encode())]})
    await send({"type": "http.response.body", "body": body})


# --- requests ---------------------------------------------------------------------------------------


def session_of(request: Request | WebSocket) -> Session:
    """The session a request is for."""
    return request.app.state.session



async def json_body(request: Request) -> dict[str, Any]:
    """The request's JSON object (an empty body is ``{}``).

    Raises:
        InvalidArgumentError: The body is not JSON, or not an object.
        RequestTooLargeError: It is larger than :data:`MAX_BODY`.
    """
    raw = await request.body()
    if not raw.strip():
        return {}
    try:
        body = json.loads(raw)
    except (ValueError, RecursionError) as exc:
        raise InvalidArgumentError(
            f"Expected a JSON object as the request body; found text that is not JSON ({exc}). Send JSON."
        ) from None
    if not isinstance(body, dict):
        raise InvalidArgumentError(f"Expected a JSON object as the request body; found a {type(body).__name__}.")
    return body


def expect(body: dict[str, Any], key: str, kind: type | tuple[type, ...], default: Any = ...) -> Any:
    """``body[key]``, checked to be of ``kind`` (a bool is not an int); ``default`` if it is missing or null.

    Raises:
        InvalidArgumentError: It is missing (and has no default) or of another type.
    """
    value = body.get(key)
    if value is None:
        if default is ...:
            raise InvalidArgumentError(f"Expected {key!r} in the request's JSON object; found none.")
        return default
    kinds = kind if isinstance(kind, tuple) else (kind,)
    if isinstance(value, bool) and bool not in kinds or not isinstance(value, kinds):
        names = " or ".join(_JSON_NAMES.get(k, k.__name__) for k in kinds)
        raise InvalidArgumentError(f"Expected {key!r} to be {names}; got {shown(value)}.")
    return value


_JSON_NAMES = {str: "a string", int: "a whole number", float: "a number", bool: "true or false", list: "a list"}


# --- paths ---------------------------------------------------------------------------------------------


def resolve_path(name: str, base: Path, roots: Iterable[Path], *, what: str = "file") -> Path:
    """The file a request names, relative to ``base``, if it stays inside one of ``roots``: the one check of them all.

    The name is percent-decoded until it no longer changes (``%2e%2e``, ``%252e%252e``), then
    refused if it holds a NUL or a control character, is absolute, or climbs with ``..``; the
    path is then resolved, symlinks followed, and must still lie inside a root (a symlink out of
    the folder is refused too).

    Args:
        name: The relative path the request gave.
        base: The folder it is relative to (inside a root).
        roots: The folders a request may reach: the game's folders and the data folder.
        what: What the file is, for the message.

    Raises:
        AccessDeniedError: The path leaves every root, however it is written.
        InvalidArgumentError: ``name`` is not a non-empty string.
    """
    if not isinstance(name, str) or not name:
        raise InvalidArgumentError(f"Expected a {what} name as a non-empty string, got {shown(name)}.")
    decoded = name
    try:
        for _ in range(8):  # %25 nests: decode until the text is stable
            step = unquote(decoded, errors="strict") if "%" in decoded else decoded
            if step == decoded:
                break
            decoded = step
    except UnicodeDecodeError:
        raise InvalidArgumentError(
            f"Expected a {what} name in UTF-8; got {shown(name)}, whose percent-escapes are other bytes. "
            "Name a file by its plain name."
        ) from None
    longest = max(len(part.encode("utf-8", "surrogatepass")) for part in decoded.replace("\\", "/").split("/"))
    if longest > NAME_MAX:
        raise InvalidArgumentError(
            f"Expected a {what} name of at most {NAME_MAX} bytes (what a file system holds); got {shown(name)}, "
            f"of {longest} bytes. Pick a shorter name."
        )
    problem = _path_problem(decoded)
    allowed = [Path(os.path.realpath(r)) for r in roots]
    if not problem:
        target = Path(os.path.realpath(base / decoded))
        if not any(target.is_relative_to(root) for root in allowed):
            problem = "leads outside the game's folders and the data folder (through a symlink)"
    if problem:
        raise AccessDeniedError(
            f"Expected a {what} inside the game's folders or the data folder; got {shown(name)}, which {problem}. "
            "Name a file by its plain name."
        )
    return target


def _path_problem(text: str) -> str:
    if "%" in text:
        return "is still percent-encoded after 8 rounds of decoding"
    if any(ord(c) < 32 or ord(c) == 127 for c in text):
        return "holds a NUL or a control character"
    if any("\ud800" <= c <= "\udfff" for c in text):  # JSON's lone surrogates: no file name holds one
        return "holds a character that is not UTF-8"
    if text.startswith(("/", "\\", "~")) or (len(text) > 1 and text[1] == ":"):
        return "is an absolute path"
    if any(part == ".." for part in text.replace("\\", "/").split("/")):
        return "climbs out of its folder with '..'"
    return ""


def game_roots(game: Game) -> list[Path]:
    """The folders a request about ``game`` may reach: its folders, where its made states go, the data folder."""
    from retrokit.data.integrate import target_folder

    return [*game.folders, target_folder(game), data_dir()]


def check_inside(path: Path, roots: Sequence[Path], *, what: str = "file") -> Path:
    """Return ``path`` if, symlinks followed, it lies inside one of ``roots``.

    Raises:
        AccessDeniedError: It leads elsewhere (a symlink out of the game's folder).
    """
    real = Path(os.path.realpath(path))
    if not any(real.is_relative_to(Path(os.path.realpath(root))) for root in roots):
        raise AccessDeniedError(
            f"Expected a {what} inside the game's folders or the data folder; found {path}, a symlink to {real}. "
            "Copy the file into the game's folder instead of linking to it."
        )
    return path
