"""Hostile game folders through ``validate``, ``make`` and ``import retrokit``: a failed check or one line of error.

Each case builds a copy of Dasher's folder with one file made hostile (an alias
bomb, a FIFO, a link to /dev/zero, a symlink loop, 100,000 fields at one
address), and runs the tool in a child process under a timeout and an address
space limit, so a regression fails the test instead of hanging the suite. The
child's peak memory is held to the 500 MB every input must stay under.
"""

from __future__ import annotations

import json
import os
import shutil
from collections.abc import Callable
from pathlib import Path

import pytest
from childproc import MAX_RSS_MB, run_child, run_cli

DASHER = Path(__file__).resolve().parent.parent / "games" / "Dasher-Genesis"
GAME_YAML = (DASHER / "game.yaml").read_text().partition("\nmovies:")[0] + "\n"  # no movies: quick to check


def _alias_bomb(key: str = "x-bomb") -> str:
    """Ten lines of YAML standing for 10**9 values: each list holds the one above it ten times."""
    lines = [f"{key}:", "  a0: &a0 [x, x, x, x, x, x, x, x, x, x]"]
    lines += [f"  a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 10)}]" for i in range(1, 9)]
    return "\n".join(lines) + "\n"


def dasher_copy(root: Path, name: str = "Dasher-Genesis") -> Path:
    """A copy of Dasher's folder (game.yaml without movies, the default scenario, one state, the ROM)."""
    folder = root / name
    folder.mkdir(parents=True)
    (folder / "game.yaml").write_text(GAME_YAML.replace("states:\n  default: Zone1.Act1\n  by_players: "
                                                        "[Zone1.Act1, Zone1.Act1.2P]", "states:\n  default: Zone1.Act1"))
    for file in ("scenario.yaml", "Zone1.Act1.state", "rom.md"):
        shutil.copy(DASHER / file, folder / file)
    return folder


def _validate(folder: Path, tmp_path: Path) -> tuple[list[dict], object]:
    out = tmp_path / "report.json"
    child = run_cli(["validate", str(folder), "--frames", "5", "-q", "--json", str(out)], timeout=120, cwd=tmp_path)
    assert child.signal is None and child.peak_rss_mb < MAX_RSS_MB, child.describe()
    assert out.is_file(), f"validate wrote no report:\n{child.describe()}"
    assert "Traceback" not in child.stderr, child.describe()
    return json.loads(out.read_text())["games"][0]["results"], child


def _fifo(path: Path) -> None:
    path.unlink(missing_ok=True)
    os.mkfifo(path)


def _dev_zero(path: Path) -> None:
    path.unlink(missing_ok=True)
    path.symlink_to("/dev/zero")


def _loop(path: Path) -> None:
    path.unlink(missing_ok=True)
    path.symlink_to(path.name)  # relative: the link names itself


SPECIAL: dict[str, Callable[[Path], None]] = {"fifo": _fifo, "link-to-dev-zero": _dev_zero, "symlink-loop": _loop}
#: What the report names for each special file.
FOUND = {"fifo": "found a FIFO", "link-to-dev-zero": "found a device", "symlink-loop": "found a symlink loop"}


FILES = ["scenario.yaml", "extra.yaml", "Zone1.Act1.state"]


def _validate_all(root: Path, folders: list[Path]) -> tuple[dict[str, list[dict]], object]:
    """Validate several hostile game folders in ONE child: interpreter start and imports were most of each case's cost.

    Returns:
        Each folder's results by its name (a folder's game is named after it; missing if the child died first), and
        the child.
    """
    out = root / "report.json"
    child = run_cli(["validate", *map(str, folders), "--frames", "5", "-q", "--json", str(out)], timeout=240, cwd=root)
    games = json.loads(out.read_text())["games"] if out.is_file() else []
    return {g["game"]: g["results"] for g in games}, child


def _ends_cleanly(shared: tuple[dict[str, list[dict]], object], names: list[str]) -> None:
    reports, child = shared
    assert child.signal is None and child.peak_rss_mb < MAX_RSS_MB, child.describe()
    assert "Traceback" not in child.stderr, child.describe()
    assert set(names) <= set(reports), child.describe()  # (the child validates the cases of both fixtures)


def _unreadable_movie(folder: Path, special: str) -> None:
    (folder / "movies").mkdir()
    (folder / "game.yaml").write_text(GAME_YAML + "movies:\n  Zone1.Act1: {done_at: 621, reward: 3552}\n")
    SPECIAL[special](folder / "movies" / "Zone1.Act1.bk2")


def _alias_bombed(folder: Path) -> None:
    (folder / "game.yaml").write_text(GAME_YAML + _alias_bomb())


#: Every case validated by the one shared child, by its folder's (and so its game's) name: how to make it hostile.
UNREADABLE: dict[str, Callable[[Path], None]] = {
    **{f"{file}-{special}": (lambda f, file=file, make=make: make(f / file))
       for file in FILES for special, make in SPECIAL.items()},
    **{f"movie-{special}": (lambda f, special=special: _unreadable_movie(f, special)) for special in SPECIAL},
    **{f"game.yaml-{special}": (lambda f, make=make: make(f / "game.yaml")) for special, make in SPECIAL.items()},
    "alias-bomb": _alias_bombed,
}


def _unreadable_results(shared, case: str, tmp_path: Path) -> tuple[list[dict], object]:
    """The case's results from the shared child; if it died before the case, from a child of the case's own."""
    reports, child = shared
    if case in reports:
        return reports[case], child
    folder = dasher_copy(tmp_path / "games")  # so the failure names its case
    UNREADABLE[case](folder)
    return _validate(folder, tmp_path)


@pytest.fixture(scope="module")
def unreadable_files(hostile_folders) -> tuple[dict[str, list[dict]], object]:
    """The cases of :data:`UNREADABLE`, each a game folder named after it, validated by the shared child."""
    return hostile_folders


def test_one_validate_of_every_unreadable_folder_ends_cleanly(unreadable_files) -> None:
    _ends_cleanly(unreadable_files, list(UNREADABLE))


@pytest.mark.parametrize("special", list(SPECIAL), ids=list(SPECIAL))
@pytest.mark.parametrize("file", FILES)
def test_an_unreadable_file_in_a_game_folder_is_a_failed_check(
    tmp_path: Path, file: str, special: str, unreadable_files
) -> None:
    results, child = _unreadable_results(unreadable_files, f"{file}-{special}", tmp_path)
    failed = [r for r in results if r["status"] == "fail"]
    assert any(FOUND[special] in r["message"] and file in r["message"] for r in failed), child.describe()


@pytest.mark.parametrize("special", list(SPECIAL), ids=list(SPECIAL))
def test_an_unreadable_solution_movie_is_a_failed_check(tmp_path: Path, special: str, unreadable_files) -> None:
    results, child = _unreadable_results(unreadable_files, f"movie-{special}", tmp_path)
    movie = [r for r in results if r["check"] == "movie"]
    assert [r["status"] for r in movie] == ["fail"], child.describe()
    assert FOUND[special] in movie[0]["message"] and "Zone1.Act1.bk2" in movie[0]["message"], child.describe()


@pytest.mark.parametrize("special", list(SPECIAL), ids=list(SPECIAL))
def test_an_unreadable_game_yaml_fails_the_data_check(tmp_path: Path, special: str, unreadable_files) -> None:
    results, child = _unreadable_results(unreadable_files, f"game.yaml-{special}", tmp_path)
    data = [r for r in results if r["check"] == "data file"]
    assert data and data[0]["status"] == "fail" and FOUND[special] in data[0]["message"], child.describe()


OVERLAYS = {"fifo": _fifo, "folder": lambda p: p.mkdir(), "symlink-loop": _loop}


@pytest.fixture(scope="module")
def overlaid(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, object]:
    """Each overlay case's validate, then make, all in ONE child (a child each was three starts), each case with
    RETROKIT_GAMES at a folder of its own searched first, holding Dasher-Genesis/game.yaml made hostile.

    Returns:
        The root (``<case>/first/Dasher-Genesis/game.yaml`` and ``<case>/report.json`` in it), and the child.
    """
    root = tmp_path_factory.mktemp("overlays")
    for overlay, make in OVERLAYS.items():
        (root / overlay / "first" / "Dasher-Genesis").mkdir(parents=True)
        make(root / overlay / "first" / "Dasher-Genesis" / "game.yaml")
    # make's error is printed, not raised, so a traceback on stderr is validate's
    child = run_child(
        f"""
        import os
        import retrokit
        from retrokit.cli import main
        from retrokit.errors import RetrokitError

        for case in {list(OVERLAYS)!r}:
            os.environ["RETROKIT_GAMES"] = os.path.join({str(root)!r}, case, "first")
            main(["validate", "Dasher-Genesis", "--frames", "5", "-q", "--json",
                  os.path.join({str(root)!r}, case, "report.json")])
            try:
                retrokit.make("Dasher-Genesis")
            except RetrokitError as exc:
                print(f"make refused {{case}}:", " ".join(str(exc).split()))
        """,
        timeout=240, cwd=root,
    )
    return root, child


@pytest.mark.parametrize("overlay", list(OVERLAYS), ids=list(OVERLAYS))
def test_an_overlay_game_yaml_that_cannot_be_read_is_said_not_skipped(overlaid, overlay: str) -> None:
    """A game.yaml in a folder searched first is the game's data file: one that is no file is an error."""
    root, child = overlaid
    overlay_yaml = root / overlay / "first" / "Dasher-Genesis" / "game.yaml"
    out = root / overlay / "report.json"
    assert child.signal is None and child.peak_rss_mb < MAX_RSS_MB, child.describe()
    assert out.is_file() and "Traceback" not in child.stderr, child.describe()
    data = [r for r in json.loads(out.read_text())["games"][0]["results"] if r["check"] == "data file"]
    assert data and data[0]["status"] == "fail", child.describe()
    assert str(overlay_yaml) in data[0]["message"], child.describe()
    refused = [line for line in child.stdout.splitlines() if line.startswith(f"make refused {overlay}:")]
    assert len(refused) == 1 and str(overlay_yaml) in refused[0], child.describe()


def test_a_game_folder_linking_to_itself_breaks_no_command(tmp_path: Path) -> None:
    games = tmp_path / "games"
    games.mkdir()
    (games / "Loop-Genesis").symlink_to("Loop-Genesis")
    # Every command lists the search folders first (the loop once broke `import retrokit`); listing one game keeps
    # the child to a second, where all 1,038 compile their scenarios (4 CPU-s, over a minute under a soak's load).
    child = run_cli(["games", "Dasher-Genesis"], env={"RETROKIT_GAMES": str(games)}, timeout=60)
    assert child.returncode == 0 and "Dasher-Genesis" in child.stdout, child.describe()


def test_an_alias_bomb_in_game_yaml_is_refused_quickly(tmp_path: Path, unreadable_files) -> None:
    folder = dasher_copy(tmp_path / "games")
    _alias_bombed(folder)
    assert (folder / "game.yaml").stat().st_size - len(GAME_YAML) < 1024
    results, child = _unreadable_results(unreadable_files, "alias-bomb", tmp_path)  # validate (in the shared child)
    failed = [r for r in results if r["status"] == "fail"]
    assert any("aliases (*name) to add at most" in r["message"] for r in failed), child.describe()
    child = run_child(f"import retrokit\nretrokit.make({str(folder)!r})", timeout=60)
    last = child.stderr.strip().splitlines()[-1]
    assert "DataFileError" in last and "aliases (*name) to add at most" in last, child.describe()


def test_a_hundred_thousand_fields_at_one_address_give_one_warning() -> None:
    """The overlap check sweeps once: 100,000 fields at one address are one group, not 5 billion pairs.

    (A game.yaml of 100,000 fields is near the 4 MiB a YAML file may hold, and
    takes a minute to parse on a loaded machine, so the check is run on the
    fields directly.)
    """
    child = run_child(
        """
        from types import SimpleNamespace
        from retrokit.data.games import find_game
        from retrokit.host.fields import FieldSpec
        from retrokit.testing.fields import check_fields
        from retrokit.testing.report import GameReport

        fields = {f"f{i}": FieldSpec(f"f{i}", 0xFF0000, "|u1") for i in range(100_000)}
        game = SimpleNamespace(fields=fields, system=find_game("Dasher-Genesis").system)
        report = GameReport("many")
        check_fields(game, report, None)
        for result in report.find("field overlap"):
            print(result.status, result.message)
        """,
        timeout=120,
    )
    assert child.returncode == 0 and child.peak_rss_mb < MAX_RSS_MB, child.describe()
    lines = child.stdout.splitlines()
    assert len(lines) == 1 and lines[0].startswith("warn f0 (0xff0000), f1 (0xff0000), f10 (0xff0000)"), child.describe()
    assert lines[0].endswith("and 99992 more fields share bytes; if not meant, fix an address"), child.describe()


MOVIE_ENTRIES = {
    "without-reward": ("{done_at: 621}", "to have a 'reward'"),
    "reward-is-a-word": ("{done_at: 621, reward: abc}", "a finite number as 'reward'"),
    "entry-is-a-list": ("[621, 3552]", "to have the form {done_at: F, reward: R}"),
    "tolerance-is-nan": ("{done_at: 621, reward: 1, tolerance: .nan}", "a finite number as 'tolerance'"),
    "done-at-is-a-word": ("{done_at: soon, reward: 1}", "a frame number (1 or more) or null"),
}


#: The control of the malformed entries (a finite tolerance and a wrong reward), validated in their child too.
CONTROL = ("control-wrong-reward", "{done_at: 621, reward: 1}")


def _with_movie_entry(root: Path, name: str, entry: str) -> Path:
    folder = dasher_copy(root, name)
    (folder / "movies").mkdir()
    shutil.copy(DASHER / "movies" / "Zone1.Act1.bk2", folder / "movies" / "Zone1.Act1.bk2")
    (folder / "game.yaml").write_text(GAME_YAML + f"movies:\n  Zone1.Act1: {entry}\n")
    return folder


@pytest.fixture(scope="module")
def hostile_folders(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict[str, list[dict]], object]:
    """The cases of :data:`UNREADABLE`, the malformed movies entries and their control, each a game folder named
    after its case, validated by ONE child: a validate child's start and imports were most of each case's cost."""
    root = tmp_path_factory.mktemp("hostile")
    folders = []
    for case, make in UNREADABLE.items():
        folders.append(dasher_copy(root / "games", case))
        make(folders[-1])
    entries = {case: entry for case, (entry, _) in MOVIE_ENTRIES.items()} | dict([CONTROL])
    folders += [_with_movie_entry(root / "games", case, entry) for case, entry in entries.items()]
    return _validate_all(root, folders)


@pytest.fixture(scope="module")
def movie_entries(hostile_folders) -> tuple[dict[str, list[dict]], object]:
    """The malformed movies entries and their control, each a game folder named after its case, validated by the shared
    child."""
    return hostile_folders


def _movie_entry_results(shared, case: str, entry: str, tmp_path: Path) -> tuple[list[dict], object]:
    """The case's results from the shared child; if it died before the case, from a child of the case's own."""
    reports, child = shared
    if case in reports:
        return reports[case], child
    return _validate(_with_movie_entry(tmp_path / "games", "Dasher-Genesis", entry), tmp_path)  # names its case


def test_one_validate_of_every_malformed_movies_entry_ends_cleanly(movie_entries) -> None:
    _ends_cleanly(movie_entries, [*MOVIE_ENTRIES, CONTROL[0]])
    assert len(movie_entries[0]) == len(UNREADABLE) + len(MOVIE_ENTRIES) + 1, movie_entries[1].describe()  # no others


@pytest.mark.parametrize("case", list(MOVIE_ENTRIES), ids=list(MOVIE_ENTRIES))
def test_a_malformed_movies_entry_is_a_failed_check(tmp_path: Path, case: str, movie_entries) -> None:
    entry, message = MOVIE_ENTRIES[case]
    results, child = _movie_entry_results(movie_entries, case, entry, tmp_path)
    movie = [r for r in results if r["check"] == "movie"]
    assert [r["status"] for r in movie] == ["fail"] and message in movie[0]["message"], child.describe()


def test_a_nan_tolerance_no_longer_passes_a_wrong_reward(tmp_path: Path, movie_entries) -> None:
    """The control: a finite tolerance and a wrong reward fail, as NaN's must too (above)."""
    results, child = _movie_entry_results(movie_entries, *CONTROL, tmp_path)
    movie = [r for r in results if r["check"] == "movie"]
    assert [r["status"] for r in movie] == ["fail"] and "a total reward of 1" in movie[0]["message"], child.describe()


def test_a_scenario_whose_integers_grow_fails_its_smoke_run_quickly(tmp_path: Path) -> None:
    """prev(t, 3) * prev(t, 3) made each step 3 times slower than the last: now step 5 fails, and says why."""
    folder = dasher_copy(tmp_path / "games")
    # as the game's only scenario: the shipped one's 600-frame smoke runs are not the claim
    (folder / "scenario.yaml").write_text("define:\n  t: prev(t, 3) * prev(t, 3)\nreward: t / 1\n")
    out = tmp_path / "report.json"
    child = run_cli(["validate", str(folder), "--frames", "600", "-q", "--json", str(out)], timeout=120, cwd=tmp_path)
    assert child.signal is None and child.peak_rss_mb < MAX_RSS_MB and out.is_file(), child.describe()
    smoke = [r for r in json.loads(out.read_text())["games"][0]["results"]
             if r["check"] == "smoke run" and r["scenario"] == "scenario"]
    assert smoke and all(r["status"] == "fail" and "integers are 64-bit" in r["message"] for r in smoke), child.describe()
