"""A state cannot answer for itself: the crash probe's verdict travels on a channel no core writes to.

pce_fast prints every variable name of a state it does not know on stdout
(``Unknown variable in save state: <name>``), byte for byte from the state.
The forged state here (issue 42) is Skipper-PCEngine's Level1 whose VRAM
variable is renamed into 41 unknown ones: the first name holds a line of the
probe child's own answer (``{"name": "state", ..., "loaded": true}``) and a
byte that is not UTF-8, the others pad the core's stdout past its buffer so
the line is written; its CPU timestamp is then the largest an ``int32``
holds, and the core's first frame dies by SIGSEGV. The state keeps its
size, so it reaches the core. Before the fix, the probe read that line as its
child's answer and called the state safe (or raised a raw UnicodeDecodeError).

The probe is what stands behind the layout checks (:mod:`retrokit.host.statelayout`):
these tests run with them switched off in every process (a ``sitecustomize`` on
the path), so they show the probe alone refusing a state those checks miss.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest
from childproc import MAX_RSS_MB, REPO, run_child
from pcestate import renamed, with_variable

from retrokit.data.states import compress_state, read_state

SKIPPER = REPO / "games" / "Skipper-PCEngine"
FORGED_LINE = json.dumps({"name": "state", "path": "", "loaded": True}).encode()


NO_LAYOUT_CHECK = """
import retrokit.host.statelayout as layout
layout.state_layout_problem = lambda system, state: ""  # the probe alone decides
"""


@pytest.fixture(scope="module")
def unchecked(tmp_path_factory: pytest.TempPathFactory) -> str:
    """A PYTHONPATH whose sitecustomize switches the layout checks off in every process that starts with it."""
    folder = tmp_path_factory.mktemp("unchecked")
    (folder / "sitecustomize.py").write_text(NO_LAYOUT_CHECK)
    return f"{folder}{os.pathsep}{REPO}"


@pytest.fixture
def probe_alone(unchecked: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """The layout checks off here and in the children this process starts."""
    from retrokit.data import probe

    monkeypatch.setenv("PYTHONPATH", unchecked)
    monkeypatch.setattr(probe, "state_layout_problem", lambda system, state: "")


@pytest.fixture(scope="module")
def forged(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The forged state's file, in a copy of Skipper's folder (as ``Forged``)."""
    state = read_state(SKIPPER / "Level1.state")
    first = b"\n" + FORGED_LINE + b"\n\xff"
    names = [first + b"x" * (250 - len(first))] + [b"pad%03d" % i + b"y" * 240 for i in range(40)]
    state = with_variable(renamed(state, b"VDC0", b"VRAM", names), b"CPU", b"timestamp", b"\xff\xff\xff\x7f")
    assert len(state) == len(read_state(SKIPPER / "Level1.state"))
    folder = tmp_path_factory.mktemp("games") / "Skipper-PCEngine"
    shutil.copytree(SKIPPER, folder)
    (folder / "Forged.state").write_bytes(compress_state(state))
    return folder


def test_the_raw_core_prints_the_forged_answer_then_dies(forged: Path) -> None:
    """What the probe faces: past every check (the mint taken directly), the core writes the line and crashes."""
    child = run_child(f"""
        from retrokit.data.states import read_state
        from retrokit.host.emulator import Emulator, claim_mint
        emu = Emulator("PCEngine", {str(forged / 'rom.pce')!r})
        emu.set_state(claim_mint()(read_state({str(forged / 'Forged.state')!r}), "PCEngine"))
        emu.run([0], 60)
        print("survived")
    """)
    assert child.signal == "SIGSEGV", child.describe()
    assert FORGED_LINE.decode() in child.stdout.splitlines(), child.describe()


def test_the_probe_answers_by_how_its_child_ended_not_by_what_it_printed(
    forged: Path, tmp_path: Path, monkeypatch, probe_alone: None
) -> None:
    from retrokit.data.probe import probe_state

    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path))
    verdict = probe_state(read_state(forged / "Forged.state"), "PCEngine", forged / "rom.pce", frames=60, input_frames=0)
    assert not verdict.safe and "crashed (SIGSEGV)" in verdict.reason, verdict


ENTRY_POINTS = """
import contextlib, io, json, os, traceback
from starlette.testclient import TestClient
import retrokit
from retrokit.cli import main
from retrokit.errors import RetrokitError
from retrokit.studio.app import create_app
from retrokit.studio.session import Session

def make():
    env = retrokit.make("Skipper-PCEngine", "Forged")
    env.reset(seed=0)
    for _ in range(300):
        env.step(env.action_space.sample())
    env.close()

def validate():
    with contextlib.redirect_stdout(io.StringIO()):
        main(["validate", "Skipper-PCEngine", "--frames", "10", "--json", REPORT])
    found = [r for r in json.load(open(REPORT))["games"][0]["results"] if r.get("state") == "Forged"]
    loads = [r for r in found if r["check"] == "state loads"]
    raise RetrokitError(loads[0]["status"] + ": " + loads[0]["message"]) if loads else AssertionError(found)

def playback():
    from retrokit.data.states import read_state
    from retrokit.movie import Movie, write_bk2

    movie = os.path.join(DATA, "forged.bk2")
    state = read_state(os.path.join(GAMES, "Skipper-PCEngine", "Forged.state"))
    write_bk2(movie, Movie("Skipper-PCEngine", "PCEngine", 1, state, [(0,)] * 300))
    with contextlib.redirect_stderr(io.StringIO()) as err:
        status = main(["playback", movie, os.path.join(DATA, "forged.gif")])
    raise RetrokitError(f"status {status}: {err.getvalue().strip().splitlines()[-1]}")  # after its progress bar

def studio():
    session = Session("Skipper-PCEngine", "Level1")
    session.paused = True
    try:
        with TestClient(create_app(session, token="t", port=8765), base_url="http://127.0.0.1:8765",
                        headers={"X-Retrokit-Token": "t"}) as client:
            answer = client.post("/api/states/load", json={"name": "Forged"})
    finally:
        session.close()
    raise RetrokitError(f"{answer.status_code} {answer.json()['kind']}: {answer.json()['error']}")

answers = {}
for name, run in [("make", make), ("validate", validate), ("playback", playback), ("studio", studio)]:
    os.environ["RETROKIT_DATA"] = os.path.join(DATA, name)  # each asks the probe itself: no verdict carried over
    try:
        run()
        answers[name] = "accepted"
    except RetrokitError as exc:
        answers[name] = f"{type(exc).__name__}: {exc}"
    except BaseException:
        answers[name] = "raw: " + traceback.format_exc()
    print(json.dumps([name, answers[name]]), flush=True)
"""


@pytest.fixture(scope="module")
def entry_points(
    forged: Path, unchecked: str, tmp_path_factory: pytest.TempPathFactory
) -> tuple[dict[str, str], Path]:
    """make() with 300 steps, validate, playback of a movie from it and the studio's load of the forged state, in one
    child; each one's answer."""
    data = tmp_path_factory.mktemp("data")
    code = f"DATA = {str(data)!r}\nGAMES = {str(forged.parent)!r}\nREPORT = {str(data / 'report.json')!r}\n" + ENTRY_POINTS
    child = run_child(code, env={"RETROKIT_GAMES": str(forged.parent), "PYTHONPATH": unchecked}, timeout=600)
    assert child.returncode == 0 and child.peak_rss_mb < MAX_RSS_MB, child.describe()
    return dict(json.loads(line) for line in child.stdout.splitlines() if line.startswith("[")), data


@pytest.mark.parametrize("entry", ["make", "validate", "playback", "studio"])
def test_every_entry_point_refuses_the_forged_state(entry_points, entry: str) -> None:
    answers, _ = entry_points
    answer = answers[entry]
    assert "crashed (SIGSEGV)" in answer and "\n" not in answer, answer
    starts = {"make": "StateError", "validate": "RetrokitError: fail", "playback": "RetrokitError: status 2",
              "studio": "RetrokitError: 400"}
    assert answer.startswith(starts[entry]), answer


def test_no_verdict_calls_the_forged_state_safe(entry_points, forged: Path) -> None:
    from retrokit.data.games import cached_rom_sha1
    from retrokit.data.probe import probe_key

    _, data = entry_points
    key = probe_key(read_state(forged / "Forged.state"), "PCEngine", cached_rom_sha1(forged / "rom.pce", "PCEngine"))
    verdicts = [p.read_text() for p in data.glob(f"*/state-probes/{key}")]
    # each entry point's own probe kept its verdict
    assert verdicts == ["the emulator crashed (SIGSEGV) within the frames run after loading it"] * 4, verdicts


def test_a_frame_wider_than_the_system_draws_is_one_line(tmp_path: Path) -> None:
    """A dot clock of 10 makes pce_fast read its frame width past its table of three (a zero there; other values
    read garbage of gigapixels): ``screen()`` refuses the size instead of allocating it."""
    state = tmp_path / "dot-clock.state"
    state.write_bytes(with_variable(read_state(SKIPPER / "Level1.state"), b"VCE", b"dot clock", bytes([10])))
    child = run_child(f"""
        from retrokit.errors import CoreError
        from retrokit.host.emulator import Emulator, claim_mint
        emu = Emulator("PCEngine", {str(SKIPPER / 'rom.pce')!r})
        emu.set_state(claim_mint()(open({str(state)!r}, "rb").read(), "PCEngine"))
        emu.run([0], 2)
        try:
            emu.screen()
        except CoreError as exc:
            print("refused:", exc)
    """)
    refused = [line for line in child.stdout.splitlines() if line.startswith("refused:")]
    assert child.returncode == 0 and len(refused) == 1, child.describe()
    assert "expected a frame of at most 512x243 pixels from the pcengine core; found 0x242" in refused[0].lower()


def test_a_child_that_failed_before_any_state_leaves_no_verdict(tmp_path: Path, monkeypatch) -> None:
    """A child that could not load the ROM (no memory, say) says nothing of the states it never began: reported,
    and nothing kept, so the next run probes them."""
    from retrokit.data import probe

    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))
    state = bytearray(read_state(SKIPPER / "Level1.state"))
    state[100] ^= 0xFF  # nothing ships or vouches for it
    (tmp_path / "Unknown.state").write_bytes(compress_state(bytes(state)))
    failure = probe.ProbeVerdict(False, "the state loader exited with status 1: x")
    monkeypatch.setattr(probe, "run_child", lambda *a, **k: ({}, None, failure))
    results = probe.probe_files("PCEngine", SKIPPER / "rom.pce", "0" * 40, {"Unknown": tmp_path / "Unknown.state"})
    assert results["Unknown"].error == "the state loader exited with status 1: x" and not results["Unknown"].loaded
    assert not (tmp_path / "data" / "state-probes").exists()


def test_verdicts_of_the_probe_a_state_could_forge_count_for_nothing(forged: Path, tmp_path: Path, monkeypatch) -> None:
    """A "safe" the old probe kept (under the old key: SHA-256 of system, ROM SHA-1 and state) is not read."""
    import hashlib

    from retrokit.data import probe
    from retrokit.data.games import cached_rom_sha1

    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path))
    state, sha1 = read_state(forged / "Forged.state"), cached_rom_sha1(forged / "rom.pce", "PCEngine")
    old = hashlib.sha256(f"PCEngine\0{sha1}\0".encode() + state).hexdigest()
    (tmp_path / "state-probes").mkdir()
    (tmp_path / "state-probes" / old).write_text("safe")
    assert probe._cached(probe.probe_key(state, "PCEngine", sha1)) is None
