"""Running the studio: bind 127.0.0.1, print the URL with its token, serve until Ctrl-C.

The socket is bound here, before uvicorn starts, so a port in use is one
clear :class:`~retrokit.errors.PortInUseError` (not a log line and an exit)
and the URL printed is the one the server is really on (``--port 0`` picks a
free port).
"""

from __future__ import annotations

import errno
import socket
import threading
import webbrowser

from retrokit.errors import InvalidArgumentError, PortInUseError, RetrokitError

HOST = "127.0.0.1"
"""The only address the studio listens on: other machines cannot reach it."""


def bind(port: int) -> socket.socket:
    """A TCP socket bound to 127.0.0.1:``port``.

    Raises:
        InvalidArgumentError: ``port`` is not from 0 to 65535.
        PortInUseError: Another program listens on the port.
    """
    if not isinstance(port, int) or isinstance(port, bool) or not 0 <= port <= 65535:
        raise InvalidArgumentError(f"Expected a port from 0 to 65535 (0: any free port), got {port!r}.")
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # a studio just stopped leaves TIME_WAIT, not a listener
    try:
        sock.bind((HOST, port))
        sock.listen(128)
    except OSError as exc:
        sock.close()
        if exc.errno == errno.EADDRINUSE:
            raise PortInUseError(
                f"Expected port {port} on {HOST} to be free; another program (another studio?) listens on it. "
                f"Stop it, or pass another port: retrokit studio --port {port + 1} (or --port 0 for any free one)."
            ) from None
        raise PortInUseError(f"Expected to listen on {HOST}:{port}; the system refused: {exc.strerror or exc}.") from None
    return sock


def serve(game: str, state: str | None, *, port: int, open_browser: bool = True) -> None:
    """Serve the studio on ``game`` until interrupted (Ctrl-C ends it cleanly, closing the emulator).

    Raises:
        PortInUseError: The port is taken.
        RetrokitError: The game, its ROM or the state cannot be opened.
    """
    import uvicorn

    from retrokit.studio.app import create_app
    from retrokit.studio.security import MAX_BODY, new_token
    from retrokit.studio.session import Session

    sock = bind(port)
    try:
        session = Session(game, state)
    except RetrokitError:
        sock.close()
        raise
    actual = sock.getsockname()[1]
    token = new_token()
    app = create_app(session, token=token, port=actual)
    config = uvicorn.Config(app, log_level="warning", ws="websockets-sansio", ws_max_size=MAX_BODY,
                            timeout_graceful_shutdown=2, lifespan="on")
    server = uvicorn.Server(config)
    url = f"http://{HOST}:{actual}/?token={token}"
    print(f"retrokit studio: {url}", flush=True)
    if open_browser:
        threading.Thread(target=webbrowser.open, args=(url,), daemon=True).start()
    try:
        server.run(sockets=[sock])
    except KeyboardInterrupt:  # uvicorn shuts down on SIGINT, then raises it again: it has ended cleanly
        pass
    finally:
        session.close()
        sock.close()
