"""RAM searches on the real emulator: Dasher's documented fields and Airstriker's data.json, found by play.

The searches never read the game's fields: they only play and filter. The
fields are read afterwards, to check the candidates hold them.
"""

from __future__ import annotations

import numpy as np
import pytest

from retrokit.data.games import find_game
from retrokit.data.states import read_state
from retrokit.errors import FileConflictError, InvalidArgumentError, MovieError
from retrokit.host.systems import get_system
from retrokit.movie import Movie, write_bk2
from retrokit.ramsearch import RamSearch, group_candidates


def dasher_lives(search: RamSearch) -> None:
    """The HUD shows 3 lives; run right into the first pit, twice."""
    search.filter("equal", 3)
    search.run(["RIGHT"], 150)  # fell into the pit
    search.filter("decreased")
    search.run([], 130)  # the death animation, then the respawn
    search.filter("unchanged")
    search.run(["RIGHT"], 200)  # the pit again
    search.filter("decreased")


def dasher_rings(search: RamSearch) -> None:
    """The HUD counts the rings at the start of zone 1 as they are picked up."""
    search.filter("equal", 0)
    for frames, rings in ((50, 1), (3, 2), (4, 3), (4, 4)):
        search.run(["RIGHT"], frames)
        search.filter("equal", rings)


def dasher_score(search: RamSearch) -> None:
    """Each ring is worth 10 points."""
    search.filter("equal", 0)
    search.run(["RIGHT"], 50)
    search.filter("equal", 10)
    search.run(["RIGHT"], 3)
    search.filter("changed-by", 10)
    search.run(["RIGHT"], 4)
    search.filter("increased")
    search.run(["RIGHT"], 4)
    search.filter("equal", 40)


def dasher_x(search: RamSearch) -> None:
    """x grows while RIGHT is held (again and again, so the pad byte drops out) and stays put when idle.

    The run passes x = 256, so the low byte alone wraps and drops out, and
    brakes with LEFT before the first pit.
    """
    search.run([], 30)
    search.filter("unchanged")
    for hold in (20, 20, 30, 34):
        search.run(["RIGHT"], hold)
        search.filter("increased")
    search.run(["LEFT"], 8)  # braking: still moving right
    search.filter("increased")
    search.run([], 30)
    search.filter("unchanged")


def dasher_zone(search: RamSearch) -> None:
    """The HUD shows ZONE 1-1, 2-1, 3-1, 1-2, then 2-2."""
    search.filter("equal", 1)
    for state, zone in (("Zone2.Act1", 2), ("Zone3.Act1", 3), ("Zone1.Act2", 1), ("Zone2.Act2", 2)):
        search.run(state=state)
        search.filter("equal", zone)


@pytest.mark.parametrize(
    ("field", "play", "most_groups"),
    [
        ("p1_lives", dasher_lives, 1),
        ("p1_rings", dasher_rings, 3),
        ("p1_score", dasher_score, 4),
        ("p1_x", dasher_x, 6),  # x read as 2 and 4 bytes: its high bytes never changed
        ("zone", dasher_zone, 1),
    ],
    ids=["lives", "rings", "score", "x", "zone"],
)
def test_dasher_fields_are_found_by_play(field, play, most_groups):
    with RamSearch("Dasher-Genesis", "Zone1.Act1") as search:
        play(search)
        candidates = search.candidates()
        groups = group_candidates(candidates)
    spec = find_game("Dasher-Genesis").fields[field]  # only now: what game.yaml documents
    assert (spec.address, spec.type) in {(c.address, c.type) for c in candidates}
    assert 1 <= len(groups) <= most_groups, [(hex(g[0].address), g[0].type) for g in groups]
    if field in ("p1_lives", "p1_x", "zone"):  # every group reads the field's bytes
        for group in groups:
            low, high = group[0].address, group[0].address + int(group[0].type[-1])
            assert low < spec.address + spec.field_type.width and spec.address < high, group[0]


def fire(search: RamSearch, frames: int) -> int:
    """Tap B (fire) for some frames, then take a snapshot."""
    for _ in range(frames // 8):
        search.step(["B"], 4)
        search.step([], 4)
    return search.snapshot(f"fired for {frames} frames")


def test_buttons_by_name_and_port():
    with RamSearch("Dasher-Genesis", "Zone1.Act1") as search:
        assert search.buttons(["RIGHT", "B", "2:START"]) == [(1 << 7) | 1, 1 << 3]
        with pytest.raises(InvalidArgumentError, match="port of 1 to 2"):
            search.buttons(["3:START"])
        with pytest.raises(InvalidArgumentError, match="frames from 0 to 1,000,000"):
            search.run(["RIGHT"], -1)
        with pytest.raises(InvalidArgumentError, match="frames from 0 to 1,000,000"):
            search.run(["RIGHT"], 10**9)  # hours of emulation: refused, not run
        assert len(search.labels) == 1  # nothing was run


def test_airstriker_lives_and_score_match_data_json(airstriker_fields):
    with RamSearch("Airstriker-Genesis") as lives:
        lives.filter("equal", 3)
        fire(lives, 440)  # shot down once
        lives.filter("decreased")
        lives.filter("equal", 2)
        fire(lives, 440)
        lives.filter("equal", 1)
        found_lives = lives.candidates()
    with RamSearch("Airstriker-Genesis") as score:
        score.filter("equal", 0)
        fire(score, 200)
        score.filter("equal", 20)
        fire(score, 120)
        score.filter("increased")
        fire(score, 320)
        score.filter("greater", 40)
        # Every scale consistent so far is kept (as stable-retro does): words read through /4 are
        # still in, and the score the screen shows tells them apart.
        score.filter("equal", 60)
        found_score = score.candidates()
    for field, found, most in (("lives", found_lives, 1), ("score", found_score, 2)):
        spec = airstriker_fields[field]
        assert (spec["address"], spec["type"]) in {(c.address, c.type) for c in found}, field
        assert len(group_candidates(found)) <= most


def test_snapshots_are_console_order():
    """Genesis RAM is byte-swapped words in the core; a snapshot reads as the 68000 does."""
    with RamSearch("Dasher-Genesis", "Zone1.Act1") as search:
        search.run(["RIGHT"], 60)
        snapshot = search.engine.snapshots[-1]
        for address, code in ((0xFF002B, "|u1"), (0xFF000A, ">u2"), (0xFF0020, ">i2"), (0xFF002C, ">d4")):
            ftype = search.engine.types[search.types.index(code)]
            position = search.layout.position(address, ftype.width)
            assert ftype.decode(bytes(snapshot[position : position + ftype.width])) == search.emulator.peek(
                address, code
            )


def test_poke_shows_on_the_next_snapshot_and_screen(tmp_path):
    with RamSearch("Dasher-Genesis", "Zone1.Act1") as search:
        before = search.screen()
        search.poke(0xFF002B, 9)  # lives
        ram = search.layout.read(search.emulator.space)
        after = search.screenshot(tmp_path / "lives9.png")
        poked = search.screen()
        assert np.array_equal(search.layout.read(search.emulator.space), ram)  # the screenshots ran on a scratch copy
        assert not np.array_equal(before[:8], poked[:8])  # the HUD's top line shows 9 lives
        assert np.array_equal(before[16:], poked[16:])  # nothing else changed
        search.run([], 1)
        search.filter("equal", 9)
        assert (0xFF002B, "|u1", (3, 9)) in {(c.address, c.type, c.values) for c in search.candidates()}
        assert after.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        with pytest.raises(FileConflictError):
            search.screenshot(after)
        with pytest.raises(InvalidArgumentError, match=r"0xFF0000-0xFFFFFF"):
            search.poke(0x10, 1)
        with pytest.raises(InvalidArgumentError, match="from 0 to 255"):
            search.poke(0xFF002B, 300)


def test_a_movie_moves_the_game_as_holding_its_buttons(tmp_path):
    game = find_game("Dasher-Genesis")
    right = get_system("Genesis").mask(["RIGHT"])
    movie = tmp_path / "right.bk2"
    write_bk2(movie, Movie("Dasher-Genesis", "Genesis", 1, read_state(game.state_path("Zone1.Act1")), [(right,)] * 120))
    with RamSearch("Dasher-Genesis", "Zone1.Act1") as by_movie, RamSearch("Dasher-Genesis", "Zone1.Act1") as by_hand:
        by_movie.play(movie, until=60)
        by_hand.run(["RIGHT"], 60)
        assert np.array_equal(by_movie.engine.snapshots[-1], by_hand.engine.snapshots[-1])
        assert by_movie.emulator.peek(0xFF0020, ">i2") > 48
        with pytest.raises(InvalidArgumentError, match="--until"):
            by_movie.play(movie, until=500)
    other = tmp_path / "other.bk2"
    write_bk2(other, Movie("Airstriker-Genesis", "Genesis", 1, None, [(0,)] * 5))
    with RamSearch("Dasher-Genesis", "Zone1.Act1") as search, pytest.raises(MovieError, match="Airstriker"):
        search.play(other)
