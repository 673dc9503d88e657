"""Hostile save states: corrupt bodies, gzip bombs and other games' states, through make(), playback and integrate.

A corrupt state crashes Genesis Plus GX (SIGSEGV), so every case runs in a
child process (tests/childproc.py): a regression fails the test instead of
killing the suite.
"""

from __future__ import annotations

import gzip
import hashlib
import json
import shutil
import zipfile
from pathlib import Path

import pytest
from bombs import gzip_of_zeros, zip_bytes
from childproc import MAX_RSS_MB, REPO, Child, run_child, run_cli_cases
from probestore import seed_shipped, shared_verdicts

from retrokit.data.games import cached_rom_sha1, find_game
from retrokit.data.probe import probe_key, probe_state
from retrokit.data.states import StateRecord, compress_state, read_state, read_state_file, state_record, write_state
from retrokit.errors import StateError
from retrokit.movie import Movie, write_bk2

DASHER = REPO / "games" / "Dasher-Genesis"


@pytest.fixture(scope="module")
def bomb() -> bytes:
    """About 1 MiB of gzip that inflates to 1 GiB."""
    return gzip_of_zeros(1024)


@pytest.fixture(scope="module")
def verdicts(tmp_path_factory: pytest.TempPathFactory, corrupt_state: bytes) -> Path:
    """The corrupt state vetted once in a bare data folder (a real probe, SIGSEGV): that folder's verdicts.

    test_a_probe_verdict_is_cached_by_sha256 checks this first vetting; the tests that refuse the state through a
    command start their data folders from its verdict, as on a machine that probed the state before: the state is
    still vetted (a command that skipped vetting would load it and crash), by its verdict.
    """
    from retrokit.data import probe

    data = tmp_path_factory.mktemp("probing")
    rom = DASHER / "rom.md"
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("RETROKIT_DATA", str(data))
        with pytest.raises(StateError, match="SIGSEGV"):
            probe.vet_state(corrupt_state, "Genesis", rom, cached_rom_sha1(rom, "Genesis"), source="x")
    return data / "state-probes"


def test_the_corrupt_state_really_crashes_the_core(corrupt_state: bytes) -> None:
    verdict = probe_state(corrupt_state, "Genesis", DASHER / "rom.md", frames=60)
    assert not verdict.safe and "SIGSEGV" in verdict.reason


def _movie(tmp_path: Path, state: bytes, game: str = "Dasher-Genesis", header: dict[str, str] | None = None) -> Path:
    path = tmp_path / "hostile.bk2"
    movie = Movie(game, "Genesis", 1, state, [(0,)] * 30)
    movie.header.update(header or {})
    write_bk2(path, movie)
    return path


def _bomb_movie(tmp_path: Path) -> Path:
    """A movie whose Core.bin inflates to 1 GiB (its zip is about 1 MiB)."""
    with zipfile.ZipFile(_movie(tmp_path, b"\0")) as archive:
        text = [(name, [archive.read(name)], True) for name in ("Input Log.txt", "Header.txt")]
    path = tmp_path / "bomb.bk2"
    path.write_bytes(zip_bytes([*text, ("Core.bin", [1024], True)]))
    return path


HOSTILE_STATES = {"corrupt-body": "SIGSEGV", "gzip-bomb": "inflates past"}  # each case, and what refuses it


@pytest.fixture(scope="module")
def makes(
    tmp_path_factory: pytest.TempPathFactory, corrupt_state: bytes, bomb: bytes, verdicts: Path
) -> tuple[dict, Child]:
    """make() on each hostile state file, in one child under the memory cap: what each answered, and the child.

    Each case is its own make(); the child's peak memory bounds each one's.
    """
    folder = tmp_path_factory.mktemp("hostile-states")
    paths = {"corrupt-body": str(folder / "corrupt.state"), "gzip-bomb": str(folder / "bomb.state")}
    Path(paths["corrupt-body"]).write_bytes(compress_state(corrupt_state))
    Path(paths["gzip-bomb"]).write_bytes(bomb)
    with shared_verdicts(verdicts, folder / "data"):
        child = run_child(f"""
            import json
            import retrokit
            from retrokit.errors import StateError
            answers = {{}}
            for case, path in {paths!r}.items():
                try:
                    env = retrokit.make('Dasher-Genesis', path)
                    env.reset()
                    answers[case] = 'played'
                except StateError as exc:
                    answers[case] = f'refused: {{exc}}'
            print(json.dumps(answers))
            """, env={"RETROKIT_DATA": str(folder / "data")})
    assert child.returncode == 0, child.describe()
    return json.loads(child.stdout), child


@pytest.mark.parametrize("kind", list(HOSTILE_STATES))
def test_make_refuses_a_hostile_state_file(makes: tuple[dict, Child], kind: str) -> None:
    answers, child = makes
    assert answers[kind].startswith("refused:"), (answers[kind], child.describe())
    assert HOSTILE_STATES[kind] in answers[kind], answers[kind]
    assert child.peak_rss_mb < MAX_RSS_MB, child.describe()


def test_a_probe_verdict_is_cached_by_sha256(corrupt_state: bytes, verdicts: Path, monkeypatch) -> None:
    from retrokit.data import probe

    rom = DASHER / "rom.md"
    sha1 = cached_rom_sha1(rom, "Genesis")
    # the first vetting, in a bare data folder, probed and was refused: the verdicts fixture
    cache = verdicts / probe_key(corrupt_state, "Genesis", sha1)
    assert cache.is_file()
    monkeypatch.setenv("RETROKIT_DATA", str(verdicts.parent))
    monkeypatch.setattr(probe, "probe_state", lambda *a, **k: pytest.fail("probed again"))
    with pytest.raises(StateError, match="SIGSEGV"):
        probe.vet_state(corrupt_state, "Genesis", rom, sha1, source="x")


def wild_map(good_state: bytes, value: int = 0xF3) -> bytes:
    """``good_state`` with bank 0 of its cartridge memory map pointing ``value`` banks into the ROM area."""
    from retrokit.host.statelayout import GENESIS_BANK_MAP

    state = bytearray(good_state)
    state[GENESIS_BANK_MAP] = value
    return bytes(state)


def test_a_memory_map_outside_the_rom_area_is_refused_before_any_probe_or_record(
    tmp_path: Path, good_state: bytes, monkeypatch
) -> None:
    # Such a state crashes or not by the process's memory layout (issue 24's fuzz, state 7): no probe can vouch.
    from retrokit.data import probe
    from retrokit.host.statelayout import state_layout_problem

    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))
    rom = DASHER / "rom.md"
    sha1 = cached_rom_sha1(rom, "Genesis")
    state = wild_map(good_state)
    probe._remember(probe_key(state, "Genesis", sha1), probe.ProbeVerdict(True))  # an old probe's lucky verdict
    monkeypatch.setattr(probe, "probe_state", lambda *a, **k: pytest.fail("probed"))
    with pytest.raises(StateError, match=r"points 1 of the 68000's 64 banks outside the core's ROM area \(bank 0x00 at"):
        probe.vet_state(state, "Genesis", rom, sha1, source="x")
    for edge in (0x9F, 0xFF):  # the last ROM bank, and the battery RAM: what a core writes
        assert state_layout_problem("Genesis", wild_map(good_state, edge)) == ""
    assert "0xa0" in state_layout_problem("Genesis", wild_map(good_state, 0xA0))


def test_a_z80_bank_outside_the_68000s_space_is_refused(good_state: bytes) -> None:
    import struct

    from retrokit.host.statelayout import GENESIS_Z80_BANK, state_layout_problem

    state = bytearray(good_state)
    struct.pack_into("<I", state, GENESIS_Z80_BANK, 0x7F8000)  # the highest bank a core writes
    assert state_layout_problem("Genesis", bytes(state)) == ""
    struct.pack_into("<I", state, GENESIS_Z80_BANK, 0x1FF8000)
    assert "Z80 bank address is 0x1ff8000" in state_layout_problem("Genesis", bytes(state))


def test_a_vdp_fifo_index_past_the_fifo_is_refused(good_state: bytes) -> None:
    import struct

    from retrokit.host.statelayout import GENESIS_FIFO_INDEX, state_layout_problem

    state = bytearray(good_state)
    assert struct.unpack_from("<I", state, GENESIS_FIFO_INDEX)[0] < 4  # the offset holds what the core wrote
    struct.pack_into("<I", state, GENESIS_FIFO_INDEX, 3)
    assert state_layout_problem("Genesis", bytes(state)) == ""
    struct.pack_into("<I", state, GENESIS_FIFO_INDEX, 4)
    assert "VDP FIFO write index is 0x4," in state_layout_problem("Genesis", bytes(state))


def test_a_wild_vdp_fifo_index_really_crashes_the_core(tmp_path: Path, good_state: bytes) -> None:
    import struct

    from retrokit.host.statelayout import GENESIS_FIFO_INDEX

    state = bytearray(good_state)
    struct.pack_into("<I", state, GENESIS_FIFO_INDEX, 0x40000000)
    (tmp_path / "wild.bin").write_bytes(state)
    child = run_child(f"""
        from retrokit.host.emulator import Emulator, claim_mint
        emu = Emulator.for_rom({str(DASHER / "rom.md")!r})
        emu.set_state(claim_mint()(open({str(tmp_path / "wild.bin")!r}, 'rb').read(), 'Genesis'))
        emu.run([0, 0], 10)
        print('survived')
    """)
    assert child.signal == "SIGSEGV", child.describe()


def test_the_probe_child_refuses_a_wild_memory_map_too(good_state: bytes) -> None:
    verdict = probe_state(wild_map(good_state, 0xA0), "Genesis", DASHER / "rom.md", frames=1, input_frames=0)
    assert not verdict.safe and "outside the core's ROM area" in verdict.reason, verdict


def test_shipped_genesis_states_have_their_memory_map_inside_the_rom_area() -> None:
    from retrokit.host.statelayout import GENESIS_BANK_MAP, GENESIS_BANKS, GENESIS_STATE_SIZE, state_layout_problem
    from retrokit.paths import wheel_dir

    def head(path: Path) -> bytes:
        """The state up to its memory map (all the check reads), padded to a state's size: 7 times less to inflate."""
        with gzip.open(path) as f:
            data = f.read(GENESIS_BANK_MAP + GENESIS_BANKS)
        return data + bytes(GENESIS_STATE_SIZE - len(data))

    # One state of each game (all 928 pass too; every game has its own cartridge and mapper), and all of Dasher's.
    games = sorted((wheel_dir() / "data" / "stable").glob("*-Genesis*"))
    files = [f for g in games for f in sorted(g.glob("*.state"))[:1]] + sorted(DASHER.glob("*.state"))
    assert len(files) > 100
    problems = {f"{f.parent.name}/{f.name}": state_layout_problem("Genesis", head(f)) for f in files}
    assert not any(problems.values()), {k: v for k, v in problems.items() if v}


def test_shipped_and_recorded_states_need_no_probe(tmp_path: Path, good_state: bytes, monkeypatch) -> None:
    from retrokit.data import probe, statecheck

    monkeypatch.setattr(probe, "probe_state", lambda *a, **k: pytest.fail("a trusted state was probed"))
    monkeypatch.setattr(statecheck, "vet_state", lambda *a, **k: pytest.fail("a trusted state was vetted"))
    game = find_game("Dasher-Genesis")
    assert statecheck.load_state(game, DASHER / "Zone1.Act1.state") == good_state  # shipped
    mine = write_state(tmp_path / "mine.state", good_state, record=StateRecord.of(game.name, game.sha1s[0], good_state))
    assert statecheck.load_state(game, mine) == good_state  # written by retrokit, unchanged


def test_a_state_changed_since_retrokit_wrote_it_is_probed(
    tmp_path: Path, corrupt_state: bytes, verdicts: Path, monkeypatch
) -> None:
    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))
    from retrokit.data import statecheck

    game = find_game("Dasher-Genesis")
    record = StateRecord.of(game.name, game.sha1s[0], b"some other state")  # the record no longer describes the body
    path = tmp_path / "edited.state"
    path.write_bytes(compress_state(corrupt_state, record))
    with shared_verdicts(verdicts, tmp_path / "data"), pytest.raises(StateError, match="SIGSEGV"):
        statecheck.load_state(game, path)  # vetted (here by the verdict of the module's probe), not trusted


HOSTILE_CORE_BINS = {"corrupt-core-bin": "SIGSEGV", "gzip-bomb-core-bin": "at most"}  # each case, and its message


@pytest.fixture(scope="module")
def playbacks(
    tmp_path_factory: pytest.TempPathFactory, corrupt_state: bytes, good_state: bytes, verdicts: Path
) -> dict[str, tuple[Child, str, str]]:
    """``retrokit playback`` of each hostile movie, each its own command, all in one child under the memory cap:
    each command's answer (the child's peak memory bounds each), movie and output path."""
    folder = tmp_path_factory.mktemp("hostile-movies")
    for case in ("corrupt", "bomb", "other"):
        (folder / case).mkdir()
    # A Dasher movie's Core.bin and header, under Airstriker's name.
    dasher = find_game("Dasher-Genesis")
    header = {"SHA1": dasher.sha1s[0], "StateSHA256": StateRecord.of(dasher.name, dasher.sha1s[0], good_state).sha256}
    cases = {
        "corrupt-core-bin": (str(_movie(folder / "corrupt", corrupt_state)), str(folder / "corrupt" / "out.gif")),
        "gzip-bomb-core-bin": (str(_bomb_movie(folder / "bomb")), str(folder / "bomb" / "out.gif")),
        "another-games-state": (
            str(_movie(folder / "other", good_state, game="Airstriker-Genesis", header=header)),
            str(folder / "other" / "out"),
        ),
    }
    with shared_verdicts(verdicts, folder / "data"):
        answers = run_cli_cases(
            {case: ["playback", movie, out] for case, (movie, out) in cases.items()},
            env={"RETROKIT_DATA": str(folder / "data")},
        )
    return {case: (answers[case], movie, out) for case, (movie, out) in cases.items()}


@pytest.mark.parametrize("kind", list(HOSTILE_CORE_BINS))
def test_playback_refuses_a_hostile_core_bin(playbacks: dict[str, tuple[Child, str, str]], kind: str) -> None:
    child, movie, out = playbacks[kind]
    assert child.returncode == 2, child.describe()
    last = child.stderr.strip().splitlines()[-1]
    assert last.startswith(f"retrokit: error: {movie}") and "Traceback" not in child.stderr, child.describe()
    assert HOSTILE_CORE_BINS[kind] in last, child.describe()
    assert child.peak_rss_mb < MAX_RSS_MB, child.describe()
    assert not Path(out).exists()


@pytest.fixture(scope="module")
def integrations(tmp_path_factory: pytest.TempPathFactory, corrupt_state: bytes, verdicts: Path) -> dict:
    """``retrokit integrate`` over a damaged Zone1.Act1.state of a Dasher copy, without then with --force, in one child.

    Each command's status and stdout, and the SHA-256 of the state file after it.
    """
    tmp = tmp_path_factory.mktemp("integrate")
    folder = tmp / "games" / "Dasher-Genesis"
    folder.mkdir(parents=True)
    for name in ("game.yaml", "rom.md", "scenario.yaml"):
        shutil.copy(DASHER / name, folder / name)
    damaged = folder / "Zone1.Act1.state"
    damaged.write_bytes(compress_state(corrupt_state))
    args = ["integrate", "Dasher-Genesis", "--state", "Zone1.Act1", "--out", str(folder)]  # over the damaged one
    runs = {"check": args, "force": [*args, "--force"]}  # check first: it must leave the damaged state as it was
    env = {"RETROKIT_GAMES": str(folder.parent), "RETROKIT_DATA": str(tmp / "data")}
    with shared_verdicts(verdicts, tmp / "data"):
        child = run_child(f"""
            import contextlib, hashlib, io, json
            from retrokit.cli import main
            answers = {{}}
            for case, args in {runs!r}.items():
                with contextlib.redirect_stdout(io.StringIO()) as out:
                    status = main(args)
                state = open({str(damaged)!r}, 'rb').read()
                answers[case] = [status, out.getvalue(), hashlib.sha256(state).hexdigest()]
            print(json.dumps(answers))
            """, env=env)
    assert child.returncode == 0, child.describe()
    return {"answers": json.loads(child.stdout), "state": damaged, "child": child}


@pytest.mark.parametrize("force", [False, True], ids=["check", "force"])
def test_integrate_over_a_damaged_state(integrations: dict, corrupt_state: bytes, force: bool) -> None:
    status, stdout, state_sha256 = integrations["answers"]["force" if force else "check"]
    assert status == (0 if force else 1), (stdout, integrations["child"].describe())
    assert ("replaced" if force else "damaged") in stdout, stdout
    if force:
        damaged = integrations["state"]
        assert read_state_file(damaged).record.describes(read_state(damaged))
        assert state_sha256 == hashlib.sha256(damaged.read_bytes()).hexdigest()
    else:
        assert state_sha256 == hashlib.sha256(compress_state(corrupt_state)).hexdigest()  # kept as it was


# --- another game's state ---------------------------------------------------------------------


def test_states_retrokit_writes_record_game_and_rom_and_stay_plain_gzip(good_state: bytes) -> None:
    blob = (DASHER / "Zone1.Act1.state").read_bytes()
    record = state_record(blob)
    assert record == StateRecord("Dasher-Genesis", find_game("Dasher-Genesis").sha1s[0], record.sha256)
    assert record.describes(good_state)
    assert gzip.decompress(blob) == good_state  # any gzip reader (stable-retro's is Python's) reads it


def test_stable_retro_loads_a_state_retrokit_wrote(tmp_path: Path) -> None:
    stable_retro = pytest.importorskip("stable_retro")
    env = stable_retro.make("Airstriker-Genesis-v0", render_mode=None)
    try:
        game = find_game("Airstriker-Genesis")
        data = read_state(game.state_path("Level1"))
        path = write_state(tmp_path / "Level1.state", data, record=StateRecord.of(game.name, game.sha1s[0], data))
        env.load_state(str(path))
        env.reset()
        assert env.unwrapped.em.get_state() is not None
    finally:
        env.close()


def test_make_refuses_another_games_recorded_state() -> None:
    import retrokit

    with pytest.raises(StateError, match="recorded on another ROM .*, of Dasher-Genesis"):
        retrokit.make("Airstriker-Genesis", str(DASHER / "Zone1.Act1.state"))


def test_playback_refuses_a_movie_recorded_with_another_games_state(playbacks) -> None:
    child, _, _ = playbacks["another-games-state"]  # the playbacks fixture's Dasher movie under Airstriker's name
    assert child.returncode == 2, child.describe()
    assert f"recorded on another ROM (SHA-1 {find_game('Dasher-Genesis').sha1s[0]})" in child.stderr, child.describe()


def test_a_recorded_movie_names_its_rom_and_state(tmp_path: Path) -> None:
    import retrokit
    from retrokit.movie import read_bk2

    env = retrokit.make("Dasher-Genesis", record=tmp_path, max_episode_steps=3)
    env.reset(seed=0)
    for _ in range(3):
        env.step(env.action_space.sample())
    env.close()
    (path,) = tmp_path.glob("*.bk2")
    movie = read_bk2(path)
    game = find_game("Dasher-Genesis")
    assert movie.header["SHA1"] == game.sha1s[0]
    assert StateRecord.of(game.name, game.sha1s[0], movie.state).sha256 == movie.header["StateSHA256"]


def test_make_refuses_a_state_from_another_games_folder(airstriker_dir: Path) -> None:
    import retrokit
    from retrokit.paths import wheel_data_dirs

    sonic = next(d / "SonicTheHedgehog-Genesis-v0" for d in wheel_data_dirs() if (d / "SonicTheHedgehog-Genesis-v0").is_dir())
    with pytest.raises(StateError, match="in the folder of SonicTheHedgehog-Genesis, a game on another ROM"):
        retrokit.make("Airstriker-Genesis", str(sonic / "GreenHillZone.Act1.state"))


def test_games_sharing_a_rom_may_share_states(tmp_path: Path, good_state: bytes, monkeypatch) -> None:
    from retrokit.data.statecheck import load_state

    # as on a machine that loaded Dasher's shipped Zone1.Act1 before: known by its bytes, not probed again (what
    # is tested is that the twin's folder, another integration of the same ROM, does not refuse it)
    (tmp_path / "data" / "state-probes").mkdir(parents=True)
    data = seed_shipped(tmp_path / "data" / "state-probes").parent
    monkeypatch.setenv("RETROKIT_DATA", str(data))
    twin = tmp_path / "DasherTwin-Genesis"  # another integration of Dasher's ROM, with a state of its own
    twin.mkdir()
    shutil.copy(DASHER / "game.yaml", twin / "game.yaml")
    (twin / "Start.state").write_bytes(compress_state(good_state))  # as stable-retro writes it: no record
    assert load_state(find_game("Dasher-Genesis"), twin / "Start.state") == good_state


HOPPER = {"Sms": REPO / "games" / "Hopper-Sms" / "rom.sms", "GameGear": REPO / "games" / "Hopper-GameGear" / "rom.gg"}


def wild_wave(system: str, value: int, channel: int = 0, slot: int = 0) -> bytes:
    """Hopper's Level1 state with one YM2413 operator's sine-table offset set to ``value``."""
    import struct

    from retrokit.data.states import read_state
    from retrokit.host.statelayout import MS_YM2413, YM2413_CHANNEL_SIZE, YM2413_SLOT_SIZE, YM2413_WAVETABLE

    state = bytearray(read_state(HOPPER[system].parent / "Level1.state"))
    at = MS_YM2413 + channel * YM2413_CHANNEL_SIZE + slot * YM2413_SLOT_SIZE + YM2413_WAVETABLE
    struct.pack_into("<I", state, at, value)
    return bytes(state)


@pytest.mark.parametrize("system", ["Sms", "GameGear"])
def test_a_wild_fm_sine_table_offset_really_crashes_the_core(tmp_path: Path, system: str) -> None:
    # Past the layout check (the child takes the mint itself), the core reads sin_tab 4 GiB on: SIGSEGV.
    state = tmp_path / "wild.bin"
    state.write_bytes(wild_wave(system, 0x40000000))
    child = run_child(f"""
        import struct
        from retrokit.host.emulator import Emulator, claim_mint
        from retrokit.host.statelayout import MS_YM2413
        state = bytearray(open({str(state)!r}, 'rb').read())
        struct.pack_into('<ii', state, MS_YM2413 + 44, 0, 0)  # operator 1's level and envelope: loud, so it is read
        emu = Emulator.for_rom({str(HOPPER[system])!r})
        emu.set_state(claim_mint()(bytes(state), {system!r}))
        emu.run([0, 0], 5)
        print('survived')
    """)
    assert child.signal == "SIGSEGV", child.describe()


@pytest.mark.parametrize("system", ["Sms", "GameGear"])
def test_a_wild_fm_sine_table_offset_is_refused_before_any_probe_or_record(
    tmp_path: Path, system: str, monkeypatch
) -> None:
    from retrokit.data import probe
    from retrokit.host.statelayout import state_layout_problem

    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))
    rom = HOPPER[system]
    sha1 = cached_rom_sha1(rom, system)
    state = wild_wave(system, 0x1000, channel=8, slot=1)
    probe._remember(probe_key(state, system, sha1), probe.ProbeVerdict(True))  # an old probe's lucky verdict
    monkeypatch.setattr(probe, "probe_state", lambda *a, **k: pytest.fail("probed"))
    with pytest.raises(StateError, match=r"YM2413 sound chip indexes its sine table with 1 wild offset\(s\) \(channel 8"):
        probe.vet_state(state, system, rom, sha1, source="x")
    for edge in (0, 1024):  # the full and the half sine: what a core writes
        assert state_layout_problem(system, wild_wave(system, edge)) == ""
    assert "at 0x401" in state_layout_problem(system, wild_wave(system, 1025))
    assert state_layout_problem("Genesis", state) != state_layout_problem(system, state)  # each system its layout


def test_shipped_master_system_and_game_gear_states_have_their_fm_offsets_in_the_table() -> None:
    from retrokit.data.states import read_state
    from retrokit.host.statelayout import state_layout_problem
    from retrokit.paths import wheel_dir

    stable = wheel_dir() / "data" / "stable"
    files = {"Sms": sorted(stable.glob("*-Sms*/*.state")), "GameGear": sorted(stable.glob("*-GameGear*/*.state"))}
    for system, rom in HOPPER.items():
        files[system] += sorted(rom.parent.glob("*.state"))
    assert sum(map(len, files.values())) > 50
    problems = {
        f"{f.parent.name}/{f.name}": state_layout_problem(system, read_state(f)) for system in files for f in files[system]
    }
    assert not any(problems.values()), {k: v for k, v in problems.items() if v}
