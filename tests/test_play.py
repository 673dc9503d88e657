"""``retrokit play`` under a real SDL window (the dummy video driver): keys save states and movies."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

pygame = pytest.importorskip("pygame")

from retrokit.data.games import find_game
from retrokit.data.statecheck import load_state
from retrokit.envs.play import PlaySession
from retrokit.host.emulator import Emulator
from retrokit.movie import play, read_bk2


@pytest.fixture(autouse=True)
def dummy_video(monkeypatch: pytest.MonkeyPatch):
    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")
    monkeypatch.setenv("SDL_AUDIODRIVER", "dummy")
    yield
    pygame.display.quit()


def key(kind: int, name: str) -> None:
    pygame.event.post(pygame.event.Event(kind, key=pygame.key.key_code(name), mod=0, unicode="", scancode=0))


def test_keys_save_a_state_and_record_a_movie_that_replays_to_it(tmp_path: Path) -> None:
    game = find_game("Dasher-Genesis")
    session = PlaySession(game, "Zone1.Act1", tmp_path, name="Mine")
    try:
        session.run(5, fps=0)
        assert session.window_size == (640, 448)  # a real SDL window, on the dummy driver
        key(pygame.KEYDOWN, "f9")  # start a movie here
        key(pygame.KEYDOWN, "right")
        session.run(90, fps=0)
        key(pygame.KEYDOWN, "x")  # jump (B) while running
        session.run(20, fps=0)
        key(pygame.KEYUP, "x")
        key(pygame.KEYDOWN, "f5")  # save a state
        session.run(1, fps=0)
        key(pygame.KEYDOWN, "f5")  # a second one gets the next name
        key(pygame.KEYDOWN, "f9")  # stop the movie
        key(pygame.KEYDOWN, "escape")
        session.run(fps=0)
    finally:
        session.close()
    assert [p.name for p in session.saved] == ["Mine.state", "Mine.2.state"]
    assert len(session.movies) == 1 and session.movies[0].parent == tmp_path / "movies"
    movie = read_bk2(session.movies[0])
    assert len(movie.frames) == 111 and movie.game == "Dasher-Genesis"
    assert any(f[0] & (1 << 7) for f in movie.frames) and any(f[0] & 1 for f in movie.frames)  # RIGHT, B
    with Emulator("Genesis", game.require_rom()) as emu:
        for _ in play(movie, emulator=emu):
            pass
        replayed = bytes(np.asarray(emu.ram))
        emu.set_state(load_state(game, session.saved[0]))
        assert emu.peek(0xFF0020, ">i2") > 48 + 150  # player 1 ran right
    with Emulator("Genesis", game.require_rom()) as emu:
        emu.set_state(load_state(game, session.saved[1]))
        assert bytes(np.asarray(emu.ram)) == replayed  # the movie ends where the second state was saved


def test_play_command_quits_on_escape(tmp_path: Path, capsys) -> None:
    from retrokit.cli import main

    pygame.display.init()  # the command's session finds it open, with these keys waiting
    key(pygame.KEYDOWN, "f5")
    key(pygame.KEYDOWN, "escape")
    assert os.environ["SDL_VIDEODRIVER"] == "dummy"
    assert main(["play", "Dasher-Genesis", "--state", "Zone2.Act1", "--out", str(tmp_path)]) == 0
    assert "1 state(s) and 0 movie(s) saved" in capsys.readouterr().out
    assert (tmp_path / "Play.state").is_file()
