"""``retrokit build-core`` against hostile input: a CC that does not split, FIFOs and bombs as sdists, killed builds.

The tools and sdists are fakes built here (see test_build_core.py), so these
run in seconds; a hang or a blow-up runs in a child process with a time limit.
"""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import tarfile
import tempfile
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from bombs import MIB, tar_gz_of_zeros
from childproc import MAX_RSS_MB, run_cli
from test_build_core import (
    RECIPE,
    assert_one_line_error,
    fake_sdist,
    original_sources,
    pip_without_config,  # noqa: F401 (a fixture the index tests use)
    tools,
)

from retrokit.cli import main
from retrokit.errors import CoreBuildError, InvalidArgumentError, SourceFetchError
from retrokit.host import build, workdirs
from retrokit.host.cores import CORES_ENV

CORE_FILE = f"stable_retro-1.0.1/{RECIPE.folder}/libretro/libretro.c"


@pytest.fixture(autouse=True)
def isolated(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> Path:
    """An empty data folder, a temporary folder of the test's own, fake tools on PATH, no CC."""
    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))
    monkeypatch.delenv("CC", raising=False)
    monkeypatch.delenv(CORES_ENV, raising=False)
    (tmp_path / "tmp").mkdir()
    monkeypatch.setenv("TMPDIR", str(tmp_path / "tmp"))
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "tmp"))
    monkeypatch.setenv("PATH", str(tools(tmp_path)))
    return tmp_path / "data"


def build_cli(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str]:
    status = main(["build-core", "genesis_plus_gx", *args])
    return status, capsys.readouterr().err


def test_a_cc_that_does_not_split_is_one_line(monkeypatch, capsys) -> None:
    monkeypatch.setenv("CC", '"unterminated')
    assert_one_line_error(*build_cli(capsys), "Expected CC to be a command line", "'\"unterminated'", "quoting")


def test_a_fifo_as_sdist_is_refused_at_once(tmp_path) -> None:
    fifo = tmp_path / "stable_retro-1.0.1.tar.gz"
    os.mkfifo(fifo)  # nobody ever writes: a reader would wait forever
    child = run_cli(["build-core", "genesis_plus_gx", "--sdist", str(fifo)], timeout=60)
    assert child.returncode == 2, child.describe()
    assert "found a FIFO" in child.stderr and "Traceback" not in child.stderr


@pytest.mark.parametrize(
    ("members", "found"),
    [
        ([(CORE_FILE, 1024)], "libretro.c of 1,024 MiB (at most 32 MiB a file)"),
        ([(f"{CORE_FILE}.{i}", 30) for i in range(5)], "150 MiB in all (at most 128 MiB)"),
    ],
    ids=["a-1-GiB-file", "150-MiB-in-all"],
)
def test_a_bomb_sdist_is_refused_before_anything_is_written(tmp_path, members, found) -> None:
    sdist = tmp_path / "stable_retro-1.0.1.tar.gz"
    sdist.write_bytes(tar_gz_of_zeros(members))
    assert sdist.stat().st_size < 2 * MIB
    dest = tmp_path / "src"
    with pytest.raises(CoreBuildError, match="Use stable-retro's own sdist") as caught:
        build.unpack_core_source(sdist, RECIPE.folder, dest)
    assert found in str(caught.value)
    assert not dest.exists() or not any(p.is_file() for p in dest.rglob("*"))


def test_a_bomb_sdist_through_the_command_stays_small(tmp_path) -> None:
    sdist = tmp_path / "stable_retro-1.0.1.tar.gz"
    sdist.write_bytes(tar_gz_of_zeros([(CORE_FILE, 1024)]))
    child = run_cli(["build-core", "genesis_plus_gx", "--sdist", str(sdist)], timeout=120)
    assert child.returncode == 2 and "1,024 MiB" in child.stderr and "Traceback" not in child.stderr, child.describe()
    assert child.peak_rss_mb < MAX_RSS_MB
    assert list((tmp_path / "tmp").iterdir()) == []  # the work folder went with the error


def test_a_source_of_too_many_files_is_refused(tmp_path) -> None:
    sdist = tmp_path / "stable_retro-1.0.1.tar.gz"
    with tarfile.open(sdist, "w:gz") as tar:
        for i in range(build.MAX_SOURCE_FILES + 1):
            tar.addfile(tarfile.TarInfo(f"stable_retro-1.0.1/{RECIPE.folder}/f{i}.c"))
    with pytest.raises(CoreBuildError, match="more than 10,000 files"):
        build.unpack_core_source(sdist, RECIPE.folder, tmp_path / "src")


def dead_pid() -> int:
    """The PID of a process that has ended."""
    proc = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True, check=True)
    return int(proc.stdout)


def test_only_work_folders_of_ended_processes_are_removed(tmp_path) -> None:
    parent = tmp_path / "tmp"
    stale = parent / f"{workdirs.PREFIX}{dead_pid()}-abc123"
    live = parent / f"{workdirs.PREFIX}{os.getppid()}-def456"  # pytest's parent: alive
    other = parent / "retrokit-build-notapid"
    for folder in (stale, live, other):
        (folder / "src").mkdir(parents=True)
        (folder / "src" / "a.c").write_bytes(b"x")
    (parent / f"{workdirs.PREFIX}1-link").symlink_to(live)
    assert workdirs.remove_stale(parent) == [stale]
    assert not stale.exists() and live.exists() and other.exists() and (parent / f"{workdirs.PREFIX}1-link").exists()


def test_a_killed_build_leaves_a_named_folder_the_next_build_removes(tmp_path, capsys) -> None:
    (tmp_path / "sleepy").mkdir()
    sleepy = tools(tmp_path / "sleepy")  # a make that hangs until killed (its dry run answers at once)
    (sleepy / "make").write_text('#!/bin/sh\nfor a in "$@"; do [ "$a" = -n ] && exit 0; done\nexec /bin/sleep 120\n')
    sdist = fake_sdist(tmp_path, original_sources())
    env = {**os.environ, "PATH": str(sleepy)}
    code = f"from retrokit.cli import main; main(['build-core', 'genesis_plus_gx', '--sdist', {str(sdist)!r}])"
    proc = subprocess.Popen([sys.executable, "-c", code], env=env, start_new_session=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)  # fmt: skip
    try:
        deadline = time.monotonic() + 60
        while not list((tmp_path / "tmp").glob(f"{workdirs.PREFIX}{proc.pid}-*/src")):
            assert time.monotonic() < deadline and proc.poll() is None, "the build never got to make"
            time.sleep(0.1)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)  # the build and the make it started: a killed terminal
        proc.wait()
    (left,) = (tmp_path / "tmp").iterdir()
    assert left.name.startswith(f"{workdirs.PREFIX}{proc.pid}-")
    status, err = build_cli(capsys, "--sdist", str(sdist))  # the next build, with a make that works
    assert status == 0, err
    assert list((tmp_path / "tmp").iterdir()) == []


# --- indexes that do not answer, or cannot be reached ------------------------------------------


@pytest.fixture
def black_hole() -> Iterator[str]:
    """The URL of an index on 127.0.0.1 that accepts every connection and never answers."""
    server = socket.create_server(("127.0.0.1", 0))
    server.settimeout(0.1)  # so the thread sees the end of the test
    held: list[socket.socket] = []
    done = threading.Event()

    def accept() -> None:
        while not done.is_set():
            try:
                held.append(server.accept()[0])
            except TimeoutError:
                continue

    thread = threading.Thread(target=accept, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{server.getsockname()[1]}/simple"
    done.set()
    thread.join(timeout=10)
    server.close()
    for connection in held:
        connection.close()


@pytest.mark.usefixtures("pip_without_config")
def test_an_index_that_never_answers_times_out(black_hole) -> None:
    start = time.monotonic()
    with pytest.raises(SourceFetchError, match="accepted the connection") as caught:
        build.build_core("genesis_plus_gx", index_url=black_hole, version="1.0.1", timeout=1, deadline=120)
    assert black_hole in str(caught.value) and "did not answer within 1 s" in str(caught.value)
    assert time.monotonic() - start < 60  # pip's answer timeout of 1 s, three tries: not 300 s


@pytest.mark.usefixtures("pip_without_config")
def test_a_download_past_its_deadline_is_stopped(black_hole) -> None:
    start = time.monotonic()
    with pytest.raises(SourceFetchError, match="within 2 s; it was not done by then") as caught:
        build.build_core("genesis_plus_gx", index_url=black_hole, version="1.0.1", timeout=600, deadline=2)
    assert "--sdist FILE" in str(caught.value)
    assert time.monotonic() - start < 30


@pytest.mark.parametrize("url", ["not a url", "nonexistent.invalid/simple", "ftp://host/simple", "http:///simple"])
def test_an_index_url_that_is_not_a_url_is_refused_first(url: str, capsys) -> None:
    with pytest.raises(InvalidArgumentError, match="Expected --index-url to be an http"):
        build.check_index_url(url)
    assert_one_line_error(*build_cli(capsys, "--index-url", url), f"found {url!r}")


@pytest.mark.usefixtures("pip_without_config")
def test_a_plain_http_index_elsewhere_is_said_to_be_unread(capsys) -> None:
    status, err = build_cli(capsys, "--index-url", "http://nonexistent.invalid/simple", "--stable-retro", "1.0.1")
    assert_one_line_error(status, err, "pip did not read it", "PIP_TRUSTED_HOST=nonexistent.invalid")
    assert "versions there" not in err
