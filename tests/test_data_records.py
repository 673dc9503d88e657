"""retrokit's own records in the data folder (verdicts, owners, caches) are never read or written through a link.

A record vouches: a "safe" verdict lets a state load unprobed, an owner
record says whose a state is. So a symlink planted at a records folder
(``<data>/state-probes`` pointing at a folder of forged verdicts) or at one
record is refused (:func:`retrokit.paths.records_dir`): nothing is read
through it, nothing written through it, and the state is probed as one
nobody vouches for.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from retrokit.data import probe
from retrokit.data.games import find_game
from retrokit.data.states import compress_state, read_state
from retrokit.errors import StateError

DASHER = Path(__file__).resolve().parent.parent / "games" / "Dasher-Genesis"


@pytest.fixture
def planted(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> tuple[Path, Path]:
    """A data folder whose state-probes folder is a link to a folder elsewhere; returns both."""
    data, elsewhere = tmp_path / "data", tmp_path / "elsewhere"
    data.mkdir()
    elsewhere.mkdir()
    (data / "state-probes").symlink_to(elsewhere)
    monkeypatch.setenv("RETROKIT_DATA", str(data))
    return data, elsewhere


def _unknown_state() -> bytes:
    """Dasher's Zone1.Act1 with one RAM byte changed: nothing ships it or has probed it."""
    state = bytearray(read_state(DASHER / "Zone1.Act1.state"))
    state[0x4000] ^= 0xFF
    return bytes(state)


@pytest.mark.parametrize("where", ["folder", "file"])
def test_a_planted_safe_verdict_vouches_for_nothing(planted, where: str, monkeypatch) -> None:
    data, elsewhere = planted
    game, state = find_game("Dasher-Genesis"), _unknown_state()
    key = probe.probe_key(state, "Genesis", game.sha1s[0])
    if where == "folder":  # the whole folder is the link
        (elsewhere / key).write_text("safe")
    else:  # a real folder, with one verdict a link to a file that says "safe"
        (data / "state-probes").unlink()
        (data / "state-probes").mkdir()
        (elsewhere / "forged").write_text("safe")
        (data / "state-probes" / key).symlink_to(elsewhere / "forged")
    asked = []
    monkeypatch.setattr(probe, "probe_state", lambda *a, **k: asked.append(1) or probe.ProbeVerdict(False, "crashed"))
    with pytest.raises(StateError, match="crashed"):
        probe.vet_state(state, "Genesis", game.require_rom(), game.sha1s[0], source="x")
    assert asked == [1]  # probed: the planted verdict was not read
    assert sorted(p.name for p in elsewhere.iterdir()) == [key if where == "folder" else "forged"]
    assert (elsewhere / (key if where == "folder" else "forged")).read_text() == "safe"  # nor written through


def test_no_verdict_or_owner_is_written_through_a_planted_folder(planted, tmp_path: Path) -> None:
    from retrokit.data import statecheck

    data, elsewhere = planted
    (data / "state-owners").symlink_to(elsewhere)
    game = find_game("Dasher-Genesis")
    emu_state = probe._mint(read_state(DASHER / "Zone1.Act2.state"), "Genesis")
    probe.remember(emu_state, game.sha1s[0])
    statecheck._record_owner(game, emu_state, game.sha1s[0])
    assert list(elsewhere.iterdir()) == []


def test_the_gymnasium_ids_cache_is_not_read_through_a_link(tmp_path: Path, monkeypatch) -> None:
    """A link to /dev/zero at the cache would never end a read: the ids are made again instead."""
    from retrokit.envs.registration import known_ids

    (tmp_path / "cache").mkdir()
    (tmp_path / "cache" / "gymnasium-ids.json").symlink_to("/dev/zero")
    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path))
    games, _ = known_ids()
    assert "Dasher-Genesis" in games
    cache = tmp_path / "cache" / "gymnasium-ids.json"
    assert not cache.is_symlink() and b"Dasher-Genesis" in cache.read_bytes()  # the link replaced, not written through


def test_a_hang_is_not_kept_as_the_states_verdict(tmp_path: Path, monkeypatch) -> None:
    """A child that misses its deadline may only have been starved of a CPU: the state is reported as hanging
    this time, and no verdict is kept, so the next load probes it again (as the core probe does).

    A deadline of a millisecond stands in for a loaded machine: no core runs the probe's frames that fast.
    """
    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path))
    game = find_game("Dasher-Genesis")
    (tmp_path / "Unknown.state").write_bytes(compress_state(_unknown_state()))
    results = probe.probe_files("Genesis", game.require_rom(), game.sha1s[0], {"Unknown": tmp_path / "Unknown.state"},
                                timeout=0.001)  # fmt: skip
    assert not results["Unknown"].loaded and "hangs the core" in results["Unknown"].error
    assert probe._cached(probe.probe_key(_unknown_state(), "Genesis", game.sha1s[0])) is None
    assert not (tmp_path / "state-probes").exists()


def test_only_lasting_verdicts_are_kept(tmp_path: Path, monkeypatch) -> None:
    """The one rule both probes keep verdicts by: a hang (:attr:`ChildEnd.lasting`) is not kept, a crash is."""
    from retrokit.host.child import ChildEnd
    from retrokit.host.verdicts import ProbeVerdict, keep_verdict, kept_verdict

    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path))
    hung, crashed = ChildEnd(-9, True, "no message"), ChildEnd(-11, False, "no message")
    keep_verdict("state-probes", "hung", ProbeVerdict(False, "it hangs", lasting=hung.lasting))
    keep_verdict("state-probes", "crashed", ProbeVerdict(False, "SIGSEGV", lasting=crashed.lasting))
    assert kept_verdict("state-probes", "hung", "a verdict") is None
    assert kept_verdict("state-probes", "crashed", "a verdict") == ProbeVerdict(False, "SIGSEGV")
