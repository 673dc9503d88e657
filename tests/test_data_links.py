"""Nothing retrokit writes into the data folder goes through a link planted there (issue 42, point 6).

Every path below the data folder comes from :func:`retrokit.paths.data_path`,
which refuses a symlink at any level under it: a planted ``<data>/roms``,
``<data>/games`` or ``<data>/games/<Game>`` (pointing at someone else's
folder) makes ``import``, ``integrate``, ``ramsearch save`` and ``savestate``
and the emulator's saves and built cores fail with one line naming the link, and the folder
it points at stays as it was. The data folder itself may be a link: the user
chose it.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from childproc import Child, run_cli_cases

from retrokit import paths
from retrokit.errors import PlantedLinkError

AIRSTRIKER_ROM = paths.wheel_dir() / "data" / "stable" / "Airstriker-Genesis-v0" / "rom.md"
MARK = b"someone else's file\n"

#: Each case: the link planted in its data folder (below it), and the command run there.
CASES: dict[str, tuple[str, list[str]]] = {
    "import-roms": ("roms", ["import", str(AIRSTRIKER_ROM)]),
    "import-game": ("roms/Airstriker-Genesis", ["import", str(AIRSTRIKER_ROM)]),
    "integrate-games": ("games", ["integrate", "Dasher-Genesis", "Zone1.Act1"]),
    "integrate-game": ("games/Dasher-Genesis", ["integrate", "Dasher-Genesis", "Zone1.Act1"]),
    "ramsearch-save-games": ("games", ["ramsearch", "save", "planted", "0xFF0100", "|u1"]),
    "ramsearch-save-game": ("games/Dasher-Genesis", ["ramsearch", "save", "planted", "0xFF0100", "|u1"]),
    "savestate-game": ("games/Dasher-Genesis", ["ramsearch", "savestate", "Mine"]),
    "savestate-default": ("games/Dasher-Genesis", ["ramsearch", "savestate", "--default", "Mine"]),
    "emulator-saves": ("saves", ["ramsearch", "new", "Dasher-Genesis", "--state", "Zone1.Act1"]),
    "emulator-cores": ("cores", ["ramsearch", "new", "Dasher-Genesis", "--state", "Zone1.Act1"]),
}


def _snapshot(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[Child, Path, Path]]:
    """Every case in one child; the ramsearch cases share a session made first in a clean data folder.

    Returns each case's answer, its planted link and the folder the link points at.
    """
    root = tmp_path_factory.mktemp("links")
    session = root / "search.session"
    commands = {"new": ["ramsearch", "new", "Dasher-Genesis", "--state", "Zone1.Act1", "--session", str(session)]}
    case_env = {"new": {paths.DATA_ENV: str(root / "clean")}}
    planted = {}
    for case, (link, argv) in CASES.items():
        data, elsewhere = root / case / "data", root / case / "elsewhere"
        elsewhere.mkdir(parents=True)
        (elsewhere / "keep.txt").write_bytes(MARK)
        (data / link).parent.mkdir(parents=True, exist_ok=True)
        (data / link).symlink_to(elsewhere, target_is_directory=True)
        planted[case] = (data / link, elsewhere)
        commands[case] = [*argv, "--session", str(session)] if argv[0] == "ramsearch" and argv[1] != "new" else argv
        case_env[case] = {paths.DATA_ENV: str(data)}
    env = {k: v for k, v in os.environ.items() if k != paths.GAMES_ENV}  # Dasher is the checkout's: a shipped game
    answers = run_cli_cases(commands, timeout=300, env=env, case_env=case_env)
    assert answers["new"].returncode == 0, answers["new"].describe()
    return {case: (answers[case], *planted[case]) for case in CASES}


@pytest.mark.parametrize("case", list(CASES), ids=list(CASES))
def test_a_planted_link_is_refused_in_one_line_and_nothing_goes_through_it(runs, case: str) -> None:
    child, link, elsewhere = runs[case]
    assert child.returncode != 0, child.describe()
    error = child.stderr.strip()
    assert "\n" not in error and "Traceback" not in error, child.describe()
    assert f"'{link}'" in error and "found a symlink to" in error and "Remove the link" in error, child.describe()
    assert _snapshot(elsewhere) == {"keep.txt": MARK}  # the folder it points at: untouched, nothing added
    assert link.is_symlink()


@pytest.mark.parametrize("level", ["games", "games/Dasher-Genesis", "games/Dasher-Genesis/game.yaml", "roms",
                                   "roms/Dasher-Genesis", "studio/drafts", "state-probes", "state-owners",
                                   "core-probes", "cache", "system", "saves", "cores", "sdist"])  # fmt: skip
def test_the_resolver_refuses_a_link_at_each_level(tmp_path: Path, monkeypatch, level: str) -> None:
    data, elsewhere = tmp_path / "data", tmp_path / "elsewhere"
    elsewhere.mkdir()
    (data / level).parent.mkdir(parents=True, exist_ok=True)
    (data / level).symlink_to(elsewhere)
    monkeypatch.setenv(paths.DATA_ENV, str(data))
    deeper = [*level.split("/"), "x"]
    with pytest.raises(PlantedLinkError, match="found a symlink to") as caught:
        paths.data_path(*deeper)
    assert f"'{data / level}'" in str(caught.value) and "\n" not in str(caught.value)
    assert str(paths.data_path(*deeper[:-2]) if len(deeper) > 2 else data)  # the levels above it are fine


def test_the_data_folder_itself_may_be_a_link(tmp_path: Path, monkeypatch) -> None:
    """The user names the data folder (one on another disk, linked from home): it is trusted, what is below it not."""
    (tmp_path / "disk").mkdir()
    (tmp_path / "data").symlink_to(tmp_path / "disk")
    monkeypatch.setenv(paths.DATA_ENV, str(tmp_path / "data"))
    assert paths.data_path("games", "Dasher-Genesis") == tmp_path / "data" / "games" / "Dasher-Genesis"
    assert paths.inside_data(tmp_path / "data" / "games" / "x.yaml") == tmp_path / "data" / "games" / "x.yaml"
    (tmp_path / "disk" / "games").symlink_to(tmp_path)
    with pytest.raises(PlantedLinkError):
        paths.inside_data(tmp_path / "data" / "games" / "x.yaml")
    assert paths.inside_data(tmp_path / "elsewhere.yaml") == tmp_path / "elsewhere.yaml"  # not in the data folder


def test_a_build_record_linked_elsewhere_vouches_for_nothing(tmp_path: Path) -> None:
    """A core's build record vouches for its bytes: one that is a link (to a forged record) is not read."""
    from retrokit.host.corecheck import built_vouchers
    from retrokit.host.cores import read_build_record

    (tmp_path / "cores").mkdir()
    forged = tmp_path / "forged.json"
    forged.write_text('{"core": "genesis_plus_gx", "library_sha256": "00", "stable_retro": "1"}')
    (tmp_path / "cores" / "genesis_plus_gx.build.json").symlink_to(forged)
    assert read_build_record("genesis_plus_gx", tmp_path) is None
    assert built_vouchers(tmp_path) == {}
    (tmp_path / "cores" / "genesis_plus_gx.build.json").unlink()
    (tmp_path / "cores" / "genesis_plus_gx.build.json").write_bytes(forged.read_bytes())  # the same, as a file: read
    assert len(built_vouchers(tmp_path)) == 1


def test_a_planted_sdist_is_not_what_a_core_is_built_from(tmp_path: Path) -> None:
    """The kept sdist is what build-core compiles: a link at its folder or at the file is refused before any use."""
    from retrokit.host.sdist import cached_sdist

    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (elsewhere / "stable_retro-1.0.1.tar.gz").write_bytes(MARK)
    kept = elsewhere / "stable_retro-1.0.1.tar.gz"
    for data, link, target in ((tmp_path / "a", "sdist", elsewhere), (tmp_path / "b", f"sdist/{kept.name}", kept)):
        (data / link).parent.mkdir(parents=True)
        (data / link).symlink_to(target)
        with pytest.raises(PlantedLinkError, match="found a symlink to"):
            cached_sdist("1.0.1", data=data, index_url="http://127.0.0.1:9/")  # never reached
    assert _snapshot(elsewhere) == {"stable_retro-1.0.1.tar.gz": MARK}


@pytest.mark.parametrize("parts", [("games", "/etc"), ("games", "..", ".."), ("/tmp",)], ids=["absolute", "up", "root"])
def test_the_resolver_never_leads_out_of_the_data_folder(tmp_path: Path, parts: tuple[str, ...]) -> None:
    from retrokit.errors import InvalidArgumentError

    with pytest.raises(InvalidArgumentError, match="leads out of it"):
        paths.data_path(*parts, data=tmp_path)
