#!/usr/bin/env python3
"""Benchmark the studio's server: screens served per second, input-to-screen latency, and its CPU share.

Starts ``retrokit studio GAME --no-browser`` on a free port and talks to it as
the page does, through the ``/ws`` socket (a scripted client: no browser is
needed, and a browser's own drawing time is not the server's):

- **Frames served per second** at 1x and at the top speed (8x): the screens
  the socket delivered per second of wall time, and the frames the emulator
  ran per second (from the screens' frame numbers). At 8x the server sends the
  newest screen, never a backlog, so it serves fewer screens than it emulates.
- **Input-to-screen latency**: from the moment the client sends
  ``{"type": "buttons", "buttons": ["RIGHT"]}`` to the arrival of the first
  screen that differs from the same frame without the button. The reference
  screens are emulated in this process from the same state (the emulator is
  deterministic), so "differs" is exact, not a guess about which pixels move.
  The time includes the game's own reaction (Dasher reads the pad once per
  frame and draws the frame after), as a player would feel it.
- **CPU share** of the server process (user + system time over wall time,
  100% = one core), idle (paused, a page connected) and while playing at 1x.

Targets (issue 22): a steady 60 fps at 1x (the Genesis runs at 59.92), and a
latency under 50 ms, on a 2-core machine with both cores otherwise free: the
load average is printed, since a loaded machine misses them for reasons that
are not the studio's.

Usage: PYTHONPATH=. python tools/bench_studio.py [--seconds 5] [--trials 5] [--game Dasher-Genesis]
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import statistics
import struct
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from websockets.sync.client import ClientConnection, connect

from retrokit.ramsearch import RamSearch

HEADER = struct.Struct("<4sHHIB3x")  # retrokit/studio/app.py SCREEN_HEADER
TARGET_FPS = 60.0
CONSOLE_FPS = 59.92  # the Genesis' NTSC rate (retrokit/host/systems.yaml)
TARGET_LATENCY_MS = 50.0
REFERENCE_FRAMES = 150


class Studio:
    """A studio server in a child process, and its API."""

    def __init__(self, game: str, state: str) -> None:
        self.process = subprocess.Popen(
            [sys.executable, "-m", "retrokit", "studio", game, "--state", state, "--port", "0", "--no-browser"],
            stdout=subprocess.PIPE, text=True, cwd=REPO,
        )  # fmt: skip
        line = self.process.stdout.readline()
        if "http://" not in line:
            self.process.kill()
            raise SystemExit(f"bench_studio: the studio did not start: {line!r}")
        url = line.split(": ", 1)[1].strip()
        self.base, self.token = url.split("/?token=")

    def api(self, route: str, body: dict | None = None) -> dict:
        request = urllib.request.Request(
            self.base + route, data=None if body is None else json.dumps(body).encode(),
            headers={"X-Retrokit-Token": self.token, "Content-Type": "application/json"},
        )  # fmt: skip
        with urllib.request.urlopen(request, timeout=60) as answer:
            return json.load(answer)

    def socket(self) -> ClientConnection:
        ws = self.base.replace("http://", "ws://") + "/ws?token=" + self.token
        return connect(ws, origin=self.base, max_size=None, compression=None)

    def cpu_seconds(self) -> float:
        """User + system CPU time of the server so far (Linux /proc)."""
        fields = Path(f"/proc/{self.process.pid}/stat").read_text().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")

    def stop(self) -> None:
        self.process.send_signal(signal.SIGINT)
        try:
            self.process.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.process.kill()


def screens_for(socket: ClientConnection, seconds: float) -> list[tuple[float, int, bytes]]:
    """Every screen received for ``seconds``: (arrival time, frame number, pixels)."""
    got = []
    end = time.perf_counter() + seconds
    while (left := end - time.perf_counter()) > 0:
        try:
            message = socket.recv(timeout=left)
        except TimeoutError:
            break
        if isinstance(message, bytes):
            _, _, _, frame, _ = HEADER.unpack_from(message)
            got.append((time.perf_counter(), frame, message[HEADER.size :]))
    return got


def drain(socket: ClientConnection) -> None:
    """Drop what the socket has queued (screens of before the command just sent)."""
    while True:
        try:
            socket.recv(timeout=0.05)
        except TimeoutError:
            return


def rate(studio: Studio, socket: ClientConnection, speed: float, seconds: float) -> tuple[float, float, float]:
    """(screens served per second, frames emulated per second, CPU share) while running at ``speed``."""
    studio.api("/api/play/speed", {"value": speed})
    studio.api("/api/play/resume", {})
    screens_for(socket, 1.0)  # settle: the frame loop paces itself from here
    cpu0, wall0 = studio.cpu_seconds(), time.perf_counter()
    got = screens_for(socket, seconds)
    cpu = (studio.cpu_seconds() - cpu0) / (time.perf_counter() - wall0)
    studio.api("/api/play/pause", {})
    if len(got) < 2:
        return 0.0, 0.0, cpu
    span = got[-1][0] - got[0][0]
    return (len(got) - 1) / span, (got[-1][1] - got[0][1]) / span, cpu


def reference(game: str, state: str) -> list[bytes]:
    """The screens of the first frames after ``state`` with no button held, emulated here."""
    with RamSearch(game, state) as search:
        shots = []
        for _ in range(REFERENCE_FRAMES):
            search.step([], 1)
            shots.append(search.screen().tobytes())
        return shots


def latency(studio: Studio, socket: ClientConnection, state: str, still: list[bytes]) -> float | None:
    """Milliseconds from sending RIGHT to the first screen that differs from the same frame without it."""
    studio.api("/api/play/pause", {})
    studio.api("/api/play/buttons", {"buttons": []})
    start = studio.api("/api/play/reset", {"state": state})["frame"]  # the screens count frames from here
    studio.api("/api/play/speed", {"value": 1})
    drain(socket)
    studio.api("/api/play/resume", {})
    screens_for(socket, 0.5)  # running steadily, nothing held
    sent = time.perf_counter()
    socket.send(json.dumps({"type": "buttons", "buttons": ["RIGHT"]}))
    end = sent + 2.0
    found = None
    while found is None and time.perf_counter() < end:
        for arrived, frame, pixels in screens_for(socket, 0.05):
            index = frame - start - 1
            if 0 <= index < len(still) and pixels != still[index]:
                found = arrived
                break
    socket.send(json.dumps({"type": "buttons", "buttons": []}))
    studio.api("/api/play/pause", {})
    return None if found is None else (found - sent) * 1000


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.partition("\n")[0])
    parser.add_argument("--game", default="Dasher-Genesis")
    parser.add_argument("--state", default="Zone1.Act1")
    parser.add_argument("--seconds", type=float, default=5.0, help="seconds of each measure (default 5)")
    parser.add_argument("--trials", type=int, default=5, help="latency trials (default 5)")
    args = parser.parse_args()

    print(f"bench_studio: {args.game} from {args.state}; load average {os.getloadavg()[0]:.2f} "
          f"on {os.cpu_count()} cores (the targets assume both cores free)")  # fmt: skip
    still = reference(args.game, args.state)
    studio = Studio(args.game, args.state)
    try:
        with studio.socket() as socket:
            studio.api("/api/play/pause", {})
            screens_for(socket, 0.5)
            cpu0, wall0 = studio.cpu_seconds(), time.perf_counter()
            screens_for(socket, args.seconds)
            idle = (studio.cpu_seconds() - cpu0) / (time.perf_counter() - wall0)

            served1, emulated1, playing = rate(studio, socket, 1.0, args.seconds)
            top = studio.api("/api/info")["speeds"][1]
            served8, emulated8, _ = rate(studio, socket, top, args.seconds)
            delays = [d for d in (latency(studio, socket, args.state, still) for _ in range(args.trials)) if d is not None]
    finally:
        studio.stop()


    def mark(ok: bool) -> str:
        return "ok" if ok else "MISSED"

    print(f"frames served at 1x:    {served1:6.1f} screens/s, {emulated1:6.1f} frames emulated/s "
          f"(target: a steady {TARGET_FPS:.0f}; the console's rate is {CONSOLE_FPS}) "
          f"{mark(served1 >= 0.97 * CONSOLE_FPS)}")  # fmt: skip
    print(f"frames served at {top:g}x:   {served8:6.1f} screens/s, {emulated8:6.1f} frames emulated/s "
          f"(ideal: {top * CONSOLE_FPS:.0f} emulated)")  # fmt: skip
    if delays:
        print(f"input-to-screen latency: median {statistics.median(delays):5.1f} ms, worst {max(delays):5.1f} ms "
              f"over {len(delays)} trials (target: under {TARGET_LATENCY_MS:.0f} ms) "
              f"{mark(statistics.median(delays) < TARGET_LATENCY_MS)}")  # fmt: skip
    else:
        print("input-to-screen latency: no trial saw the screen change within 2 s: MISSED")
    print(f"server CPU share:       idle {idle:6.1%} of a core, playing at 1x {playing:6.1%} of a core")
    print(f"load average now {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
