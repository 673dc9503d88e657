"""The command line: structure, ``retrokit games`` and ``retrokit import``."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from retrokit import cli, paths
from retrokit.commands import command_modules

AIRSTRIKER_DIR = paths.wheel_dir() / "data" / "stable" / "Airstriker-Genesis-v0"
REPO = Path(__file__).resolve().parent.parent


@pytest.fixture(autouse=True)
def data_dir(tmp_path, monkeypatch) -> Path:
    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))
    monkeypatch.delenv("RETROKIT_GAMES", raising=False)
    return tmp_path / "data"


def run(capsys, *argv: str) -> tuple[int, str, str]:
    status = cli.main(list(argv))
    out, err = capsys.readouterr()
    return status, out, err


def test_every_command_module_registers_a_runnable_parser():
    modules = command_modules()
    assert {"retrokit.commands.games", "retrokit.commands.import_"} <= {m.__name__ for m in modules}
    parser = cli.build_parser()
    for module in modules:
        assert callable(module.register) and callable(module.run)
    assert parser.parse_args(["games"]).run.__module__ == "retrokit.commands.games"
    assert parser.parse_args(["import", "x"]).run.__module__ == "retrokit.commands.import_"


def test_help_and_usage(capsys):
    status, out, _ = run(capsys, "--help")
    assert status == 0 and "games" in out and "import" in out
    status, _, err = run(capsys)
    assert status == 2 and "usage: retrokit" in err
    status, _, err = run(capsys, "games", "--no-such-option")
    assert status == 2 and "unrecognized arguments" in err


def test_games_lists_states_and_rom_status(capsys):
    status, out, _ = run(capsys, "games", "SonicTheHedgehog*Genesis")
    assert status == 0
    line = next(line for line in out.splitlines() if line.startswith("SonicTheHedgehog-Genesis "))
    assert "ROM missing" in line and "GreenHillZone.Act1*" in line and "StarLightZone.Act3" in line
    status, out, _ = run(capsys, "games", "Airstriker")
    assert "ROM bundled" in out and "states: Level1*" in out


def test_games_imported_only(capsys, tmp_path):
    status, out, _ = run(capsys, "games", "--imported")
    assert status == 0
    # With nothing imported, only the free ROMs that ship are available:
    # Airstriker in the wheel and our own cartridges in games/ (tools/cartridges.yaml).
    cartridges = yaml.safe_load((REPO / "tools" / "cartridges.yaml").read_text())
    expected = sorted(["Airstriker-Genesis", *cartridges])
    assert [line.split()[0] for line in out.splitlines()[:-1]] == expected


def test_games_with_no_match_suggests(capsys):
    status, out, err = run(capsys, "games", "SonicTheHedgehg-Genesis")
    assert status == 2 and out == ""
    assert err.startswith("retrokit: error: ") and "Did you mean" in err and "Traceback" not in err


def test_import_a_folder(capsys, tmp_path, data_dir):
    roms = tmp_path / "roms"
    roms.mkdir()
    (roms / "airstriker.md").write_bytes((AIRSTRIKER_DIR / "rom.md").read_bytes())
    status, out, _ = run(capsys, "import", str(roms))
    assert status == 0
    assert "Imported 1 ROM into" in out and "Airstriker-Genesis <- " in out
    assert (data_dir / "roms" / "Airstriker-Genesis" / "rom.md").is_file()
    status, out, _ = run(capsys, "import", str(roms))
    assert "Imported 0 ROMs" in out and "Already imported (1)" in out


def test_import_conflict_exits_1(capsys, tmp_path, data_dir):
    dest = data_dir / "roms" / "Airstriker-Genesis" / "rom.md"
    dest.parent.mkdir(parents=True)
    dest.write_bytes(b"something else")
    status, out, _ = run(capsys, "import", str(AIRSTRIKER_DIR / "rom.md"))
    assert status == 1 and "--force" in out
    assert dest.read_bytes() == b"something else"


def test_import_game_lists_expected_sha1s(capsys):
    status, out, _ = run(capsys, "import", "--game", "SonicTheHedgehog-Genesis-v0")
    assert status == 0
    for sha1 in (paths.wheel_dir() / "data/stable/SonicTheHedgehog-Genesis-v0/rom.sha").read_text().split():
        assert sha1 in out
    assert "Its ROM is missing" in out and "retrokit import /path/to/your/roms" in out


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["import"], "Expected at least one PATH"),
        (["import", "--game", "SonicTheHedgehg-Genesis"], "Did you mean 'SonicTheHedgehog-Genesis'"),
    ],
    ids=["no-paths", "misspelled-game"],
)
def test_errors_are_one_clean_message(capsys, argv, message):
    status, _, err = run(capsys, *argv)
    assert status == 2
    assert err.startswith("retrokit: error: ") and message in err and "Traceback" not in err


def test_python_dash_m(tmp_path):
    env = {**os.environ, "PYTHONPATH": str(REPO), "RETROKIT_DATA": str(tmp_path)}
    env.pop("RETROKIT_GAMES", None)
    done = subprocess.run(
        [sys.executable, "-m", "retrokit", "games", "Airstriker"], capture_output=True, text=True, env=env, timeout=120, check=False
    )
    assert done.returncode == 0, done.stderr
    assert "Airstriker-Genesis" in done.stdout


@pytest.mark.parametrize("command", [["games"], ["cores"]], ids=["games", "cores"])
def test_a_closed_pipe_ends_the_command_quietly(command: list[str]) -> None:
    # `retrokit games | head -1`: the reader goes away after one line.
    process = subprocess.Popen(
        [sys.executable, "-m", "retrokit", *command], stdout=subprocess.PIPE, stderr=subprocess.PIPE
    )
    process.stdout.readline()
    process.stdout.close()
    stderr = process.stderr.read().decode()
    process.wait(timeout=120)
    assert "Traceback" not in stderr and "BrokenPipeError" not in stderr


def test_import_lists_unmatched_files_with_their_sha1_and_suggests_new(capsys, tmp_path):
    from runner_rom import write_runner_rom

    from retrokit.data.roms import rom_sha1

    runner = write_runner_rom(tmp_path / "runner.bin")
    status, out, _ = run(capsys, "import", str(runner))
    assert status == 0
    assert f"  {runner}  SHA-1 {rom_sha1(runner, 'Genesis')}  Genesis" in out
    assert f"Start one with: retrokit new {runner} --name NAME-Genesis" in out


def test_import_of_a_path_that_does_not_exist_exits_2(capsys, tmp_path, data_dir):
    roms = tmp_path / "roms"
    roms.mkdir()
    (roms / "airstriker.md").write_bytes((AIRSTRIKER_DIR / "rom.md").read_bytes())
    status, out, err = run(capsys, "import", str(roms), str(tmp_path / "romz"))
    assert status == 2 and out == "" and "no such path" in err and "romz" in err
    assert not (data_dir / "roms").exists()  # nothing imported: the typo is fixed first


def test_import_game_with_part_of_a_name_suggests_the_games_holding_it(capsys):
    status, out, err = run(capsys, "import", "--game", "Sonic")
    assert status == 2 and out == ""
    assert "Did you mean one of: 'Sonic" in err and err.count("\n") == 1
