"""A real ``retrokit studio`` server in a child process, driven over HTTP as its page drives it.

For the tests that need a studio as a user runs it (two at once on one game,
another local page beside it) rather than the in-process test client.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import urllib.error
import urllib.request
from pathlib import Path
from typing import Any
from urllib.parse import parse_qs, urlsplit

TOKEN_HEADER = "X-Retrokit-Token"


class StudioProcess:
    """``retrokit studio GAME --port 0 --no-browser`` with ``RETROKIT_DATA=data``, started in ``cwd``.

    Args:
        game: The game, by name or folder.
        data: The data folder.
        cwd: The folder it runs in.
        env: More environment variables.
        launcher: A script run instead of ``python -m retrokit`` (it is given the command line's arguments).
    """

    def __init__(
        self, game: str | Path, data: Path, cwd: Path, env: dict[str, str] | None = None, launcher: Path | None = None
    ) -> None:
        environ = {**os.environ, "RETROKIT_DATA": str(data), **(env or {})}
        program = [str(launcher)] if launcher is not None else ["-m", "retrokit"]
        self.process = subprocess.Popen(
            [sys.executable, *program, "studio", str(game), "--port", "0", "--no-browser"],
            cwd=cwd, env=environ, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        )  # fmt: skip
        line = self.process.stdout.readline()
        if not line.startswith("retrokit studio: http://127.0.0.1:"):
            self.process.kill()
            raise AssertionError(f"the studio printed {line!r}; stderr: {self.process.stderr.read()}")
        self.url = line.split(": ", 1)[1].strip()
        parts = urlsplit(self.url)
        self.origin = f"{parts.scheme}://{parts.netloc}"
        self.token = parse_qs(parts.query)["token"][0]

    def request(
        self, method: str, route: str, body: Any = None, headers: dict[str, str] | None = None
    ) -> tuple[int, Any, dict[str, str]]:
        """Send a request as the page's scripts do (the token header, a JSON body); return status, JSON, headers.

        ``headers`` are added to those, or replace them (a value of ``None`` leaves that header out).
        """
        data = None if body is None else json.dumps(body).encode()
        sent = {TOKEN_HEADER: self.token, **({"Content-Type": "application/json"} if data is not None else {})}
        sent.update(headers or {})
        sent = {name: value for name, value in sent.items() if value is not None}  # None: leave that header out
        req = urllib.request.Request(self.origin + route, data=data, method=method, headers=sent)
        try:
            with urllib.request.urlopen(req, timeout=120) as answer:
                status, raw, got = answer.status, answer.read(), dict(answer.headers)
        except urllib.error.HTTPError as error:
            status, raw, got = error.code, error.read(), dict(error.headers)
        try:
            parsed = json.loads(raw) if raw else None
        except ValueError:
            parsed = raw
        return status, parsed, {k.lower(): v for k, v in got.items()}

    def stop(self, timeout: float = 30) -> str:
        """Ctrl-C, as a user stops it; return what it printed on stderr."""
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGINT)
        try:
            _, err = self.process.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.process.kill()
            _, err = self.process.communicate()
            raise AssertionError(f"the studio did not stop on Ctrl-C: {err}") from None
        return err
