"""``retrokit ramsearch``: sessions across processes, bad input, and saving into a copy of a game.yaml."""

from __future__ import annotations

import difflib
import io
import json
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
from incli import retrokit_in_process

from retrokit import cli
from retrokit.errors import SessionError
from retrokit.ramsearch import RamSearch
from retrokit.ramsearch.session import DEFAULT_SESSION

REPO = Path(__file__).resolve().parent.parent
DASHER = REPO / "games" / "Dasher-Genesis"


def ramsearch(cwd: Path, *argv: str) -> subprocess.CompletedProcess:
    """One command in its own process: what another process finds in the session file."""
    return subprocess.run(
        [sys.executable, "-m", "retrokit", "ramsearch", *argv],
        cwd=cwd, capture_output=True, text=True, timeout=120, check=False,
    )  # fmt: skip


def in_process(cwd: Path, *argv: str) -> subprocess.CompletedProcess:
    """One command, as its own process would run it, in this one (it loads the session file and saves it back)."""
    return retrokit_in_process(cwd, "ramsearch", *argv)


def run(capsys, *argv: str) -> tuple[int, str, str]:
    status = cli.main(["ramsearch", *argv])
    out, err = capsys.readouterr()
    return status, out, err


@pytest.fixture(scope="module")
def dasher_session(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A Dasher search with one snapshot, saved once for the module (tests get a copy)."""
    path = tmp_path_factory.mktemp("session") / DEFAULT_SESSION
    with RamSearch("Dasher-Genesis", "Zone1.Act1") as search:
        search.save(path)
    return path


@pytest.fixture
def session(dasher_session: Path, tmp_path: Path, monkeypatch) -> Path:
    """A Dasher search with one snapshot, in the default session file of a fresh folder (the cwd)."""
    monkeypatch.chdir(tmp_path)
    return Path(shutil.copyfile(dasher_session, tmp_path / DEFAULT_SESSION))


def test_a_cli_session_gives_the_api_candidates(tmp_path):
    steps = [
        ("new", "Dasher-Genesis", "--state", "Zone1.Act1"),
        ("filter", "equal", "3"),
        ("run", "--press", "RIGHT", "--frames", "150"),
        ("filter", "decreased"),
        ("run", "--frames", "130"),
        ("filter", "unchanged"),
        ("undo",),
        ("redo",),
        ("show", "--json", "--limit", "0"),
    ]
    outputs = []
    for step in steps:  # each command loads the session file and saves it back; the last one in another process
        done = (ramsearch if step == steps[-1] else in_process)(tmp_path, *step)
        assert done.returncode == 0, (step, done.stderr)
        outputs.append(done.stdout)
    assert "decreased --than previous: 1," in outputs[3]
    assert outputs[6].startswith("Undid unchanged --than previous") and outputs[7].startswith("Redid unchanged")
    by_cli = json.loads(outputs[-1])
    with RamSearch("Dasher-Genesis", "Zone1.Act1") as search:
        search.filter("equal", 3)
        search.run(["RIGHT"], 150)
        search.filter("decreased")
        search.run([], 130)
        search.filter("unchanged")
        by_api = [{"address": c.address, "type": c.type, "values": list(c.values)} for c in search.candidates()]
    assert by_cli == by_api
    assert {"address": 0xFF002B, "type": "|u1", "values": [3, 2, 2]} in by_cli
    assert sorted(p.name for p in tmp_path.iterdir()) == [DEFAULT_SESSION]  # no temporary files left


def test_show_lists_groups_with_addresses_as_game_yaml_writes_them(session, capsys):
    run(capsys, "filter", "equal", "3")
    run(capsys, "run", "--press", "RIGHT", "--frames", "150")
    run(capsys, "filter", "decreased")
    status, out, _ = run(capsys, "filter", "equal", "2")
    assert status == 0 and out.endswith("candidates.\n")
    status, out, _ = run(capsys, "show", "--limit", "5")
    lines = out.splitlines()
    assert lines[0].startswith(f"{len(RamSearch.load(session).candidates())} candidates in ")
    assert lines[1].split()[:4] == ["address", "type", "scale", "changes"]
    assert lines[2].split()[:6] == ["0xFF002B", "|u1", "-", "1", "3", "2"]
    assert lines[-1] == "snapshots: 0 new Zone1.Act1; 1 RIGHT for 150 frames"  # numbered from 0, as --than N


def test_undo_redo_round_trip_on_the_command_line(session, capsys):
    run(capsys, "run", "--frames", "5")
    counts = []
    for argv in (("filter", "changed"), ("filter", "greater", "100"), ("undo",), ("undo",), ("redo",), ("redo",)):
        status, out, err = run(capsys, *argv)
        assert status == 0, err
        counts.append(out.split("-> ")[1].split()[0])
    assert counts[2] == counts[0] and counts[4] == counts[0] and counts[5] == counts[1]
    assert counts[3] == f"{2_490_276:,}"
    status, _, err = run(capsys, "redo")
    assert status == 2 and "redo" in err


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (("poke", "0xFF002B", "3", "--type", "u1"), "Did you mean '|u1'?"),
        (("save", "lives", "0xFF002B", ">U2"), "Did you mean '>u2'?"),
        (("poke", "0x10", "3"), "Expected an address in RAM (0xFF0000-0xFFFFFF), got 0x000010"),
        (("save", "lives", "0xFFFFFF", ">u2"), "got 0xFFFFFF with 2 bytes"),
        (("filter", "equal", "--than", "0x20"), "Expected an address in RAM"),
        (("filter", "decreased"), "Expected two snapshots"),
        (("filter", "equl", "3"), "Did you mean 'equal'?"),
        (("filter", "equal", "--than", "frist"), "Did you mean 'first'?"),
        (("filter", "equal", "three"), "whole number"),
        (("run", "--press", "RIHGT"), "Did you mean 'RIGHT'?"),
        (("run", "--until", "5"), "--movie"),
        (("run", "--movie", "m.bk2", "--frames", "5"), "either --movie"),
        (("run", "--movie", "missing.bk2"), "missing.bk2"),
        (("poke", "0xFF002B", "300"), "from 0 to 255"),
        (("show", "--session", "missing.session"), "found no file"),
        (("show", "--limit", "0"), "Expected at most 100,000 candidates to list; found 2,490,276"),
        (("show", "--json", "--limit", "1000000000"), "Filter them first"),
        (("new", "Dasher-Genesis"), "--force"),
        (("new", "Airstriker-Genesis"), "another game, Dasher-Genesis"),
        ((), "Expected a subcommand"),
    ],
    ids=["unknown-type", "type-case", "poke-outside-ram", "save-past-the-end", "than-outside-ram",
         "filter-before-two-snapshots", "op-typo", "than-typo", "value-not-a-number", "button-typo",
         "until-without-movie", "movie-and-frames",
         "missing-movie", "value-too-big", "missing-session", "show-everything", "show-a-billion", "session-exists", "session-of-another-game",
         "no-subcommand"],
)  # fmt: skip
def test_bad_input_gets_one_line(session, capsys, argv, message):
    before = session.read_bytes()
    status, out, err = run(capsys, *argv)
    assert status == 2 and out == ""
    assert err.startswith("retrokit: error: ") and err.count("\n") == 1, err
    assert message in err
    assert session.read_bytes() == before  # never half-written, nor rewritten by a failed command


@pytest.mark.parametrize(
    "make",
    [
        lambda path, good: path.write_bytes(b"not a session"),
        lambda path, good: path.write_bytes(good[: len(good) // 2]),
        lambda path, good: path.write_bytes(b""),
        lambda path, good: shutil.copy(DASHER.parent.parent / "games" / "Dasher-Genesis" / "Zone1.Act1.state", path),
        lambda path, good: zipfile.ZipFile(path, "w").writestr("Input Log.txt", "[Input]\n[/Input]"),
        lambda path, good: path.write_bytes(good[:2000] + bytes([good[2000] ^ 0xFF]) + good[2001:]),
    ],
    ids=["garbage", "truncated", "empty", "a-state-file", "a-movie-like-zip", "bit-flip"],
)
def test_corrupt_or_foreign_session_files_get_one_line(session, capsys, make):
    bad = session.with_name("bad.session")
    make(bad, session.read_bytes())
    status, _, err = run(capsys, "show", "--session", str(bad))
    assert status == 2 and err.startswith(f"retrokit: error: {bad}") and err.count("\n") == 1, err
    assert "retrokit ramsearch new GAME" in err


def test_a_huge_session_file_is_refused_before_unpacking(session, capsys):
    bomb = session.with_name("bomb.session")
    chunk = bytes(1 << 20)
    with (
        zipfile.ZipFile(bomb, "w", zipfile.ZIP_DEFLATED, compresslevel=1) as archive,
        archive.open("snapshots.npy", "w", force_zip64=True) as member,
    ):
        for _ in range(300):
            member.write(chunk)
    status, _, err = run(capsys, "show", "--session", str(bomb))
    assert status == 2 and "at most 256 MiB" in err


def test_a_session_of_another_game_is_refused_by_the_api(session):
    with pytest.raises(SessionError, match="found one of Dasher-Genesis"):
        RamSearch.load(session, game="Airstriker-Genesis")


def test_poke_and_screenshot_on_the_command_line(session, capsys):
    status, out, _ = run(capsys, "poke", "0xFF002B", "9")
    assert status == 0 and out.startswith("Wrote 9 as |u1 at 0xFF002B")
    status, out, _ = run(capsys, "screenshot", "lives.png")
    assert status == 0 and out == "Saved the screen (320x224) to lives.png.\n"
    assert Path("lives.png").read_bytes()[:4] == b"\x89PNG"
    status, _, err = run(capsys, "screenshot", "lives.png")
    assert status == 2 and "--force" in err
    run(capsys, "run")
    status, out, _ = run(capsys, "filter", "equal", "9")
    assert status == 0


def test_save_writes_into_a_copy_of_game_yaml_and_make_reports_it(tmp_path, capsys, monkeypatch):
    games = tmp_path / "games"
    shutil.copytree(DASHER, games / "Dasher-Genesis")
    game_yaml = games / "Dasher-Genesis" / "game.yaml"
    original = game_yaml.read_text()
    monkeypatch.setenv("RETROKIT_GAMES", str(games))
    monkeypatch.chdir(tmp_path)
    assert run(capsys, "new", "Dasher-Genesis", "--state", "Zone1.Act1")[0] == 0
    status, out, err = run(capsys, "save", "lives_left", "0xFF002B", "|u1", "--game-file", str(game_yaml))
    assert status == 0, err
    assert out == f"Wrote field lives_left (0xFF002B, |u1) into {game_yaml}.\n"
    added = [d for d in difflib.ndiff(original.splitlines(), game_yaml.read_text().splitlines()) if d[:1] in "+-"]
    assert added == ['+   lives_left:  {address: 0xFF002B, type: "|u1"}']
    assert "# Player 1 (port 1)." in game_yaml.read_text()  # comments kept
    status, _, err = run(capsys, "save", "lives_left", "0xFF002B", "|u1", "--game-file", str(game_yaml))
    assert status == 2 and "--force" in err
    status, _, err = run(capsys, "save", "p1_lives", "0xFF002B", ">u2", "--game-file", str(game_yaml), "--force")
    assert status == 0
    assert '  p1_lives:    {address: 0xFF002B, type: ">u2"}' in game_yaml.read_text()

    import retrokit

    env = retrokit.make("Dasher-Genesis", state="Zone1.Act1")
    try:
        _, info = env.reset(seed=0)
    finally:
        env.close()
    assert info["lives_left"] == 3 and info["p1_lives"] == 3 << 8
    assert (DASHER / "game.yaml").read_text() != game_yaml.read_text()  # the repository's file is untouched


def test_save_refuses_another_games_file_and_a_wheel_game(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    shutil.copy(DASHER / "game.yaml", tmp_path / "dasher.yaml")
    assert run(capsys, "new", "Airstriker-Genesis")[0] == 0
    status, _, err = run(capsys, "save", "lives", "0xFF025A", ">u2")
    assert status == 2 and "--game-file" in err and "data.json" in err
    status, _, err = run(capsys, "save", "lives", "0xFF025A", ">u2", "--game-file", "dasher.yaml")
    assert status == 2 and "another game's" in err
    assert (tmp_path / "dasher.yaml").read_bytes() == (DASHER / "game.yaml").read_bytes()


def test_the_default_session_name_lives_in_the_current_folder(tmp_path, monkeypatch):
    done = in_process(tmp_path, "new", "Airstriker-Genesis", "--types", "|u1,>u2")
    assert done.returncode == 0, done.stderr
    assert "2 types" in done.stdout and (tmp_path / DEFAULT_SESSION).is_file()
    monkeypatch.setenv("RETROKIT_GAMES", "")
    done = in_process(tmp_path, "filter", "decreased")
    assert done.returncode == 2 and done.stderr.count("\n") == 1 and "Traceback" not in done.stderr


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"regions": ((0, 1 << 31),)}, "expected at most 134,217,728 candidates"),
        ({"types": ("|u1", "|x1")}, "expected the searched type codes"),
        ({"emulator_state": b"not a core state"}, "the core refused it"),
        ({"rom_sha1": "0" * 40}, "belongs to another ROM"),
        ({"regions": ((0xFF0000, 0x8000), (0, 0x8000))}, "expected RAM regions 0xFF0000-0xFFFFFF"),
        ({"game": "Airstriker-Genesis"}, "belongs to another ROM"),
    ],
    ids=["huge-ram", "unknown-type", "bad-emulator-state", "other-rom", "other-regions", "other-game"],
)
def test_sessions_that_do_not_fit_are_refused_in_one_line(session, capsys, change, message):
    from dataclasses import replace

    from retrokit.ramsearch.session import encode_session, read_session

    data = read_session(session)
    bad = session.with_name("bad.session")
    bad.write_bytes(encode_session(replace(data, **change)))
    status, _, err = run(capsys, "show", "--session", str(bad))
    assert status == 2 and message in err and err.count("\n") == 1, err


def test_a_session_file_listing_the_scales_in_another_order_has_them_mapped(session, capsys):
    """A file of a version that lists the scales in another order: each candidate's scale bits are mapped to ours."""
    from retrokit.ramsearch.session import read_session

    run(capsys, "filter", "equal", "3")  # a value search pins each candidate's scales: masks that differ
    with np.load(session) as archive:
        arrays = dict(archive)
    meta = json.loads(bytes(arrays["meta"]))
    count = len(meta["scales"])
    meta["scales"] = meta["scales"][::-1]
    arrays["meta"] = np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8)
    for name in [name for name in arrays if name.endswith("_scale")]:
        stored, one = arrays[name], arrays[name].dtype.type(1)
        arrays[name] = sum((((stored >> stored.dtype.type(bit)) & one) << stored.dtype.type(count - 1 - bit)
                            for bit in range(count)), np.zeros_like(stored))  # fmt: skip
    reordered = session.with_name("reordered.session")
    with reordered.open("wb") as f:
        np.savez_compressed(f, **arrays)
    ours, theirs = read_session(session), read_session(reordered)
    assert len(set(ours.candidates.pack().scales.tolist())) > 1
    assert (theirs.candidates.pack().scales == ours.candidates.pack().scales).all()
    assert [(theirs_packed.scales == ours_packed.scales).all() for (_, theirs_packed), (_, ours_packed)
            in zip(theirs.history, ours.history, strict=True)] == [True] * len(ours.history)  # fmt: skip


def test_run_plays_a_movie_up_to_a_frame(session, capsys):
    from retrokit.data.states import read_state
    from retrokit.host.systems import get_system
    from retrokit.movie import Movie, write_bk2

    right = get_system("Genesis").mask(["RIGHT"])
    state = read_state(DASHER / "Zone1.Act1.state")
    write_bk2("right.bk2", Movie("Dasher-Genesis", "Genesis", 1, state, [(right,)] * 90))
    status, out, err = run(capsys, "run", "--movie", "right.bk2", "--until", "45")
    assert status == 0, err
    assert out == "Snapshot 1: movie right.bk2 to frame 45.\n"
    status, out, _ = run(capsys, "filter", "increased")
    assert status == 0
    status, out, _ = run(capsys, "show", "--json", "--limit", "0")
    assert {"address": 0xFF0020, "type": ">i2"} in [{k: c[k] for k in ("address", "type")} for c in json.loads(out)]


def test_the_shell_runs_subcommands_line_by_line(tmp_path, monkeypatch):
    lines = [
        "new Dasher-Genesis --state Zone1.Act1",
        "# comments and blank lines are skipped",
        "",
        "filter equal 3",
        "run --press RIGHT --frames 150",
        "filter decreased",
        "filter equl 2",
        "filter equal 2 --than 'unclosed",
        "show --limit 3",
        "quit",
        "filter changed",
    ]
    monkeypatch.setattr(sys, "stdin", io.StringIO("\n".join(lines)))  # read as from a pipe: no prompt
    done = in_process(tmp_path, "shell", "--session", "s.session")
    assert done.returncode == 0, done.stderr
    assert "decreased --than previous: 1," in done.stdout and "0xFF002B  |u1" in done.stdout
    assert "changed" not in done.stdout  # after quit
    errors = done.stderr.splitlines()
    assert len(errors) == 2 and "Did you mean 'equal'?" in errors[0] and "a line of words" in errors[1]


def test_a_session_whose_state_changed_is_probed_before_it_is_loaded(session, capsys, monkeypatch):
    from retrokit.data import probe

    probed = []

    def crashing_probe(data, system, rom, **kwargs):
        probed.append(len(data))
        return probe.ProbeVerdict(False, "the emulator crashed (SIGSEGV) within 600 frames of loading it")

    monkeypatch.setattr(probe, "probe_state", crashing_probe)
    assert run(capsys, "show")[0] == 0 and probed == []  # the state this tool wrote (and noted as written)
    with np.load(session) as archive:
        arrays = dict(archive)
    body = bytearray(arrays["emulator_state"].tobytes())
    body[4096:8192] = bytes(4096)  # its bytes edited since; the record in the meta still vouches for the old ones
    arrays["emulator_state"] = np.frombuffer(bytes(body), dtype=np.uint8)
    tampered = session.with_name("tampered.session")
    with tampered.open("wb") as out:
        np.savez_compressed(out, **arrays)
    status, _, err = run(capsys, "show", "--session", str(tampered))
    assert probed == [len(body)]
    assert status == 2 and "SIGSEGV" in err and err.count("\n") == 1


def test_a_bit_search_finds_a_flag_held_in_one_bit_and_saves_it_with_its_mask(tmp_path, capsys, monkeypatch):
    """Dasher keeps the buttons held in one byte (pad1, 0xFF0014: RIGHT is 0x08): a search of `bits` finds the
    RIGHT bit where a byte search cannot tell it from the other buttons, and saves it as |u1 with a mask."""
    games = tmp_path / "games"
    shutil.copytree(DASHER, games / "Dasher-Genesis")
    game_yaml = games / "Dasher-Genesis" / "game.yaml"
    monkeypatch.setenv("RETROKIT_GAMES", str(games))
    monkeypatch.chdir(tmp_path)
    status, out, err = run(capsys, "new", "Dasher-Genesis", "--types", "bits")
    assert status == 0 and "(8 types at every address of 0xFF0000-0xFFFFFF)" in out, err
    for press, op in (("RIGHT", "not-equal 0"), ("", "equal 0"), ("RIGHT+B", "changed"), ("B", "changed")):
        assert run(capsys, "run", *(["--press", *press.split("+")] if press else []), "--frames", "3")[0] == 0
        assert run(capsys, "filter", *op.split())[0] == 0
    status, out, _ = run(capsys, "show", "--json")
    found = {(c["address"], c["type"]) for c in json.loads(out)}
    assert (0xFF0014, "|u1&0x08") in found and len(found) < 20
    status, out, err = run(capsys, "save", "right_held", "0xFF0014", "|u1&0x08", "--game-file", str(game_yaml))
    assert status == 0, err
    assert '  right_held:  {address: 0xFF0014, type: "|u1", mask: 0x08}' in game_yaml.read_text()
    status, _, err = run(capsys, "save", "two_bits", "0xFF0014", "|u1&0x0C", "--game-file", str(game_yaml))
    assert status == 2 and "Expected a bit type: |u1&MASK with one bit" in err
