"""``render_mode="human"``: SIGTERM ends a program showing the window, and its close button works.

SDL turns SIGTERM into a quit event in its queue (and the window's close button into another), which the window
never read: ``timeout``, ``kill`` and process managers could not stop a playing env, nor could its close button.
One child, with SDL's dummy video driver (a real SDL window, no screen needed), shows both.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap

import pytest

pytest.importorskip("pygame")

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEADLINE = 120  # seconds: only a child that ignores SIGTERM, or hangs, gets near it

CHILD = textwrap.dedent(
    """
    import pygame
    import retrokit

    env = retrokit.make("Dasher-Genesis", render_mode="human")
    env.reset(seed=0)
    env.step(env.action_space.sample())
    assert pygame.display.get_surface() is not None
    pygame.event.post(pygame.event.Event(pygame.QUIT))  # what the window's close button sends
    try:
        env.step(env.action_space.sample())
    except KeyboardInterrupt as exc:
        print("interrupted:", exc, flush=True)
    assert pygame.display.get_surface() is None, "the window stayed open"
    env.step(env.action_space.sample())  # another frame shown opens it again
    assert pygame.display.get_surface() is not None
    print("ready", flush=True)
    while True:
        env.step(env.action_space.sample())
    """
)


def test_sigterm_ends_a_human_env_and_its_close_button_closes_it() -> None:
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "SDL_AUDIODRIVER": "dummy", "PYTHONPATH": REPO}
    env.pop("SDL_NO_SIGNAL_HANDLERS", None)
    child = subprocess.Popen([sys.executable, "-c", CHILD], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                             env=env, cwd=REPO, stdin=subprocess.DEVNULL)  # fmt: skip
    try:
        lines = []
        for line in child.stdout:  # the child prints "ready" once it plays in its window again
            lines.append(line.strip())
            if line.strip() == "ready":
                break
        assert lines == ["interrupted: the Dasher-Genesis window was closed", "ready"], (lines, child.stderr.read())
        child.send_signal(signal.SIGTERM)
        try:
            child.wait(DEADLINE)
        except subprocess.TimeoutExpired:
            pytest.fail("the child went on playing after SIGTERM")
        assert child.returncode == -signal.SIGTERM, child.stderr.read()
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()
