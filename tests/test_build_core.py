"""``retrokit build-core``: every failure is one line, and a build lands where find_core looks first.

The compiler, make, the package index and the sdist are fakes here (a PATH
of scripts, an unreachable or local index, a small tarball), so these tests
run anywhere in a second; the real build runs in CI (.ci/run).
"""

from __future__ import annotations

import io
import json
import os
import re
import tarfile
from pathlib import Path

import pytest

from retrokit.cli import main
from retrokit.errors import CoreBuildError, PatchError
from retrokit.host import build
from retrokit.host.buildhint import build_hint
from retrokit.host.cores import CORES_ENV, built_cores_dir, locate_core
from retrokit.host.patching import apply_patch, parse_patch
from retrokit.host.systems import get_system
from retrokit.paths import wheel_cores_dir

RECIPE = build.RECIPES["genesis_plus_gx"]
PATCHED_FILE = "libretro/libretro.c"


@pytest.fixture(autouse=True)
def isolated(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> Path:
    """An empty data folder, no CC, and no RETROKIT_CORES."""
    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))
    monkeypatch.delenv("CC", raising=False)
    monkeypatch.delenv(CORES_ENV, raising=False)
    return tmp_path / "data"


def tools(tmp_path: Path, make: str | None = "ok", cc: bool = True, core: str = "genesis_plus_gx") -> Path:
    """A folder of fake build tools to be the whole PATH: ``cc`` and a ``make`` that succeeds (making ``core``'s
    library) or fails."""
    folder = tmp_path / "bin"
    folder.mkdir(exist_ok=True)
    scripts = {}
    if cc:
        scripts["cc"] = "#!/bin/sh\nexit 0\n"
    if make == "ok":  # lists one compile for the dry run, then "links" the library
        scripts["make"] = ('#!/bin/sh\nfor a in "$@"; do [ "$a" = -n ] && { echo "cc -c core/a.c"; exit 0; }; done\n'
                           f'echo "cc -c core/a.c"\necho fake-core > {core}_libretro.so\n')  # fmt: skip
    elif make == "fails":
        scripts["make"] = '#!/bin/sh\necho "cc -c core/vdp.c"\necho "core/vdp.c:12: error: boom"\nexit 2\n'
    for name, text in scripts.items():
        (folder / name).write_text(text)
        (folder / name).chmod(0o755)
    return folder


def original_sources(end: str = "\n", recipe: build.Recipe = RECIPE) -> dict[str, bytes]:
    """The files the patch changes, in the sdist, each holding exactly the lines it expects (its hunks' old
    sides), with ``end`` line ends."""
    return {
        f"{recipe.folder}/{patch.path}": "".join(
            line.rstrip("\n") + end for hunk in patch.hunks for line in hunk.old
        ).encode()
        for patch in parse_patch(build.patch_text(recipe))
    }


def fake_sdist(tmp_path: Path, files: dict[str, bytes], version: str = "1.0.1") -> Path:
    """A stable-retro-like sdist with these files (paths below its top folder)."""
    path = tmp_path / f"stable_retro-{version}.tar.gz"
    with tarfile.open(path, "w:gz") as tar:
        for name, data in files.items():
            info = tarfile.TarInfo(name if name.startswith("/") or ".." in name else f"stable_retro-{version}/{name}")
            info.size = len(data)
            tar.addfile(info, io.BytesIO(data))
    return path


def run_cli(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    status = main(["build-core", "genesis_plus_gx", *args])
    out, err = capsys.readouterr()
    return status, out, err


def assert_one_line_error(status: int, err: str, *fragments: str) -> None:
    lines = [line for line in err.splitlines() if line.startswith("retrokit: error:")]
    assert status == 2 and len(lines) == 1, err
    assert "Traceback" not in err
    for fragment in fragments:
        assert fragment in lines[0], lines[0]


# --- the failures the command names -------------------------------------------------------------


def test_no_compiler(monkeypatch, tmp_path, capsys) -> None:
    monkeypatch.setenv("PATH", str(tools(tmp_path, cc=False)))
    assert_one_line_error(*run_cli(capsys)[::2], "Expected a C compiler (cc) on PATH", "build-essential")


def test_no_make(monkeypatch, tmp_path, capsys) -> None:
    monkeypatch.setenv("PATH", str(tools(tmp_path, make=None)))
    assert_one_line_error(*run_cli(capsys)[::2], "Expected make (make) on PATH")


def test_a_compiler_named_by_cc_must_exist(monkeypatch, tmp_path, capsys) -> None:
    monkeypatch.setenv("PATH", str(tools(tmp_path)))
    monkeypatch.setenv("CC", "clang-99")
    assert_one_line_error(*run_cli(capsys)[::2], "(clang-99)")


def test_cc_may_carry_a_wrapper_or_flags(tmp_path) -> None:
    folder = tools(tmp_path)
    cc, make = build.check_tools({"PATH": str(folder), "CC": "cc -O2"})
    assert (cc, make) == (f"{folder}/cc -O2", f"{folder}/make")


@pytest.fixture
def pip_without_config(monkeypatch: pytest.MonkeyPatch) -> None:
    """pip with no configuration file or PIP_ variable: only the index a test names."""
    for name in [n for n in os.environ if n.startswith("PIP_")]:
        monkeypatch.delenv(name)
    monkeypatch.setenv("PIP_CONFIG_FILE", os.devnull)


def test_no_network(monkeypatch, tmp_path, capsys, pip_without_config) -> None:
    monkeypatch.setenv("PATH", str(tools(tmp_path)))
    status, _, err = run_cli(capsys, "--index-url", "http://127.0.0.1:9/simple")  # nothing listens on port 9
    assert_one_line_error(status, err, "could not reach it", "http://127.0.0.1:9/simple", "network")


def local_index(tmp_path: Path, *files: str) -> str:
    """A PEP 503 index on disk whose stable-retro page links these file names."""
    page = tmp_path / "index" / "stable-retro"
    page.mkdir(parents=True)
    links = "".join(f'<a href="{name}">{name}</a>\n' for name in files)
    (page / "index.html").write_text(f"<html><body>\n{links}</body></html>\n")
    return (tmp_path / "index").as_uri()


def test_a_version_with_only_wheels_has_no_source(monkeypatch, tmp_path, capsys, pip_without_config) -> None:
    monkeypatch.setenv("PATH", str(tools(tmp_path)))
    index = local_index(tmp_path, "stable_retro-1.0.1-cp311-cp311-manylinux_2_17_x86_64.manylinux2014_x86_64.whl")
    status, _, err = run_cli(capsys, "--index-url", index, "--stable-retro", "1.0.1")
    assert_one_line_error(status, err, "Expected a source package (sdist) of stable-retro 1.0.1", "found none")


def test_a_version_that_does_not_exist(monkeypatch, tmp_path, capsys, pip_without_config) -> None:
    monkeypatch.setenv("PATH", str(tools(tmp_path)))
    index = local_index(tmp_path, "stable_retro-1.0.1.tar.gz")
    status, _, err = run_cli(capsys, "--index-url", index, "--stable-retro", "0.0.7")
    assert_one_line_error(status, err, "sdist) of stable-retro 0.0.7", "versions there: 1.0.1")


# pip prepares a downloaded sdist's metadata: this in-tree build backend gives it, with nothing to install.
METADATA_ONLY_BACKEND = {
    "pyproject.toml": b'[build-system]\nrequires = []\nbuild-backend = "backend"\nbackend-path = ["."]\n',
    "backend.py": b"""import os


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    name = "stable_retro-1.0.1.dist-info"
    os.makedirs(os.path.join(metadata_directory, name))
    with open(os.path.join(metadata_directory, name, "METADATA"), "w") as file:
        file.write("Metadata-Version: 2.1\\nName: stable-retro\\nVersion: 1.0.1\\n")
    return name
""",
}


@pytest.fixture
def http_index(tmp_path: Path):
    """Serve ``tmp_path/index`` over HTTP on this machine; yield a function that makes its stable-retro page."""
    import functools
    import http.server
    import threading

    root = tmp_path / "index"
    (root / "stable-retro").mkdir(parents=True)
    class Quiet(http.server.SimpleHTTPRequestHandler):
        def log_message(self, *args: object) -> None:  # the command's stderr is what the test reads
            pass

    handler = functools.partial(Quiet, directory=str(root))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()

    def serve(sdist: Path) -> str:
        (root / "stable-retro" / sdist.name).write_bytes(sdist.read_bytes())
        (root / "stable-retro" / "index.html").write_text(f'<a href="{sdist.name}">{sdist.name}</a>\n')
        return f"http://127.0.0.1:{server.server_address[1]}/"

    yield serve
    server.shutdown()


def test_the_stock_pip_downloads_the_source_with_progress(monkeypatch, tmp_path, capsys, isolated, pip_without_config,
                                                          http_index) -> None:
    """The whole command against an index over HTTP, with the pip this venv has (a stock venv's: 23.0 or later)."""
    monkeypatch.setenv("PATH", f"{tools(tmp_path)}{os.pathsep}{os.environ['PATH']}")
    padding = os.urandom(300_000)  # incompressible, so pip announces a size in kB and the download takes a while
    sdist = fake_sdist(tmp_path, {**METADATA_ONLY_BACKEND, **original_sources(),
                                  "cores/nes/blob": padding})  # fmt: skip
    status, out, err = run_cli(capsys, "--index-url", http_index(sdist), "--stable-retro", "1.0.1")
    assert status == 0, err
    assert "  download: 100%" in err and "Installed" in err
    assert out.strip() == str(built_cores_dir(isolated) / "genesis_plus_gx_libretro.so")


def test_pip_failing_otherwise_names_the_command_to_rerun(monkeypatch, tmp_path, capsys, pip_without_config,
                                                          http_index) -> None:
    monkeypatch.setenv("PATH", f"{tools(tmp_path)}{os.pathsep}{os.environ['PATH']}")
    broken = {**METADATA_ONLY_BACKEND, "backend.py": b"raise SystemExit('this sdist is broken')\n"}
    index = http_index(fake_sdist(tmp_path, broken))
    status, _, err = run_cli(capsys, "--index-url", index, "--stable-retro", "1.0.1")
    assert_one_line_error(status, err, "Expected pip to download stable-retro 1.0.1's source; it failed (exit 1)",
                          f"-m pip download --no-deps --no-binary stable-retro stable-retro==1.0.1 --index-url {index}",
                          "--sdist FILE")


def test_a_python_without_pip_says_how_to_get_it(monkeypatch, tmp_path, capsys) -> None:
    """A venv made without pip (as uv makes them): the message names ensurepip and --sdist."""
    import subprocess
    import sys

    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(tmp_path / "bare")], check=True)
    bare = tmp_path / "bare" / "bin" / "python"
    monkeypatch.setattr(sys, "executable", str(bare))  # the one sys, which retrokit.host.sdist runs pip with
    monkeypatch.setenv("PATH", f"{tools(tmp_path)}{os.pathsep}{os.environ['PATH']}")
    status, _, err = run_cli(capsys, "--stable-retro", "1.0.1")
    assert_one_line_error(status, err, f"Expected pip in {bare}", "-m ensurepip", "--sdist FILE")


def test_a_patch_against_a_modified_source(monkeypatch, tmp_path, capsys) -> None:
    monkeypatch.setenv("PATH", str(tools(tmp_path)))
    sources = original_sources()
    key = f"{RECIPE.folder}/{PATCHED_FILE}"
    sources[key] = sources[key].replace(b"system_frame_gen(0);", b"system_frame_gen(frameskip);")
    sdist = fake_sdist(tmp_path, sources)
    status, _, err = run_cli(capsys, "--sdist", str(sdist))
    assert_one_line_error(status, err, "hunk 1 of genesis_plus_gx-av-enable.patch", PATCHED_FILE, "not the one")


def test_make_failing_quotes_its_error_and_keeps_the_log(monkeypatch, tmp_path, capsys, isolated) -> None:
    monkeypatch.setenv("PATH", str(tools(tmp_path, make="fails")))
    sdist = fake_sdist(tmp_path, original_sources())
    status, _, err = run_cli(capsys, "--sdist", str(sdist))
    log = built_cores_dir(isolated) / "genesis_plus_gx.build.log"
    assert_one_line_error(status, err, "exit 2", "core/vdp.c:12: error: boom", f"Full log: {log}")
    assert "error: boom" in log.read_text()
    assert not (built_cores_dir(isolated) / "genesis_plus_gx_libretro.so").exists()


@pytest.mark.parametrize(
    "files, found",
    [({"../evil.c": b"x"}, "reading it failed"), ({"README": b"x"}, "found no such folder")],
    ids=["path-leaving-the-folder", "no-core-folder"],
)
def test_hostile_or_foreign_sdists_are_refused(monkeypatch, tmp_path, capsys, files, found) -> None:
    monkeypatch.setenv("PATH", str(tools(tmp_path)))
    if "../evil.c" in files:  # a member under the core's folder that climbs out of it
        files = {f"stable_retro-1.0.1/{RECIPE.folder}/../../../../evil.c": b"x"}
    sdist = fake_sdist(tmp_path, files)
    assert_one_line_error(*run_cli(capsys, "--sdist", str(sdist))[::2], found)
    assert not (tmp_path / "evil.c").exists() and not (tmp_path.parent / "evil.c").exists()


def test_a_corrupt_sdist_is_refused(monkeypatch, tmp_path, capsys) -> None:
    monkeypatch.setenv("PATH", str(tools(tmp_path)))
    sdist = tmp_path / "stable_retro-1.0.1.tar.gz"
    sdist.write_bytes(b"\x1f\x8b" + os.urandom(4000))
    assert_one_line_error(*run_cli(capsys, "--sdist", str(sdist))[::2], "Expected a readable .tar.gz")


def test_an_unknown_core_suggests_the_known_one(capsys) -> None:
    status = main(["build-core", "genesis_plus"])
    assert_one_line_error(status, capsys.readouterr().err, "got 'genesis_plus'", "Did you mean 'genesis_plus_gx'?")


# --- a build, and where it goes -------------------------------------------------------------------


def test_a_build_is_installed_recorded_and_found_first(monkeypatch, tmp_path, capsys, isolated) -> None:
    path = os.environ["PATH"]
    monkeypatch.setenv("PATH", str(tools(tmp_path)))
    sdist = fake_sdist(tmp_path, {**original_sources(), "cores/nes/x.c": b"x"})
    status, out, err = run_cli(capsys, "--sdist", str(sdist))
    installed = built_cores_dir(isolated) / "genesis_plus_gx_libretro.so"
    assert status == 0 and out.strip() == str(installed), err
    for step in ("Unpacking cores/genesis/", "Applying genesis_plus_gx-av-enable.patch", "Compiling", "Installed"):
        assert step in err
    assert "  unpack: 100%" in err and "  compile: 50%" in err  # progress, as lines: stderr is not a terminal
    record = json.loads((built_cores_dir(isolated) / "genesis_plus_gx.build.json").read_text())
    assert record["stable_retro"] == "1.0.1" and record["patch"] == RECIPE.patch
    found = locate_core("genesis_plus_gx")
    assert (found.path, found.origin) == (installed, "built")
    assert run_cli(capsys, "--sdist", str(sdist))[2].startswith("Already built")  # nothing fetched or compiled again
    monkeypatch.setenv("PATH", path)
    assert main(["cores"]) == 0
    assert f"genesis_plus_gx    yes      built           {installed}" in capsys.readouterr().out
    assert build_hint("Genesis") == ""  # built: the line that tells of it is never shown again


@pytest.mark.parametrize(("core", "system"), [("stella", "Atari2600"), ("gambatte", "GameBoy"), ("snes9x", "Snes"), ("fceumm", "Nes"),
                                             ("mednafen_pce_fast", "PCEngine")])
def test_other_cores_are_built_installed_and_found_the_same_way(monkeypatch, tmp_path, capsys, isolated, core: str,
                                                                system: str) -> None:
    recipe = build.RECIPES[core]
    monkeypatch.setenv("PATH", str(tools(tmp_path, core=core)))
    sdist = fake_sdist(tmp_path, {**original_sources(recipe=recipe), "cores/genesis/x.c": b"x"})
    assert main(["build-core", core, "--sdist", str(sdist)]) == 0
    err = capsys.readouterr().err
    assert f"Unpacking {recipe.folder}/" in err and f"Applying {core}-av-enable.patch" in err
    installed = built_cores_dir(isolated) / f"{core}_libretro.so"
    assert (locate_core(core).path, locate_core(core).origin) == (installed, "built")
    assert locate_core("genesis_plus_gx").origin == "wheel"  # one recipe builds one core
    record = json.loads((built_cores_dir(isolated) / f"{core}.build.json").read_text())
    assert record["patch"] == f"{core}-av-enable.patch"
    assert main(["cores"]) == 0
    row = next(line for line in capsys.readouterr().out.splitlines() if line.startswith(f"{system} "))
    assert row.split()[1:5] == [core, "yes", "built", str(installed)]


def test_a_build_for_another_stable_retro_version_is_not_used(monkeypatch, tmp_path, capsys, isolated) -> None:
    monkeypatch.setenv("PATH", str(tools(tmp_path)))
    sdist = fake_sdist(tmp_path, original_sources(), version="0.9.9")
    assert run_cli(capsys, "--sdist", str(sdist), "--stable-retro", "0.9.9")[0] == 0
    assert locate_core("genesis_plus_gx").origin == "wheel"  # its states would not fit the installed wheel's


def test_a_core_retrokit_did_not_build_is_not_replaced(monkeypatch, tmp_path, capsys, isolated) -> None:
    monkeypatch.setenv("PATH", str(tools(tmp_path)))
    mine = built_cores_dir(isolated) / "genesis_plus_gx_libretro.so"
    mine.parent.mkdir(parents=True)
    mine.write_bytes(b"the user's own core")
    sdist = fake_sdist(tmp_path, original_sources())
    assert_one_line_error(*run_cli(capsys, "--sdist", str(sdist))[::2], "retrokit did not build", "--force")
    assert mine.read_bytes() == b"the user's own core"
    assert run_cli(capsys, "--sdist", str(sdist), "--force")[0] == 0
    assert mine.read_bytes() == b"fake-core\n"


# --- the patch applier -------------------------------------------------------------------------------


def test_a_failed_patch_leaves_the_tree_as_it_was(tmp_path) -> None:
    text = (
        "--- a/one.c\n+++ b/one.c\n@@ -1,2 +1,2 @@\n a\n-b\n+B\n"
        "--- a/two.c\n+++ b/two.c\n@@ -1,1 +1,1 @@\n-x\n+X\n"
    )
    (tmp_path / "one.c").write_text("a\nb\n")
    (tmp_path / "two.c").write_text("y\n")
    with pytest.raises(PatchError, match="hunk 1 of the patch in two.c"):
        apply_patch(text, tmp_path)
    assert (tmp_path / "one.c").read_text() == "a\nb\n"  # not half-patched
    (tmp_path / "two.c").write_text("x\n")
    apply_patch(text, tmp_path)
    assert (tmp_path / "one.c").read_text() == "a\nB\n" and (tmp_path / "two.c").read_text() == "X\n"


def test_hunks_apply_where_their_lines_moved_to(tmp_path) -> None:
    (tmp_path / "f.c").write_bytes(b"new\r\nlines\r\nfirst\r\na\r\nb\r\n")  # CRLF kept as it is
    apply_patch("--- a/f.c\n+++ b/f.c\n@@ -2,2 +2,2 @@\n a\r\n-b\r\n+c\r\n", tmp_path)
    assert (tmp_path / "f.c").read_bytes() == b"new\r\nlines\r\nfirst\r\na\r\nc\r\n"


@pytest.mark.parametrize(
    "text, message",
    [("not a diff at all\n", "Expected a unified diff"), ("--- a/f\n+++ b/f\n@@ -1 +1 @@\n?x\n", "found '?x'")],
    ids=["no-diff", "bad-hunk-line"],
)
def test_malformed_patches_are_refused(tmp_path, text: str, message: str) -> None:
    with pytest.raises(PatchError, match=re.escape(message)):
        apply_patch(text, tmp_path)


# --- what find_core and retrokit cores make of the data folder ------------------------------------


def test_without_a_build_the_wheel_core_is_listed_unpatched_with_the_measured_gain(isolated, capsys) -> None:
    genesis = get_system("Genesis")
    assert main(["cores"]) == 0
    out = capsys.readouterr().out
    assert "Genesis     genesis_plus_gx    no       wheel " in out and "retrokit build-core CORE" in out
    assert f"Genesis envs step {genesis.build_speedup:.1f}x faster, measured on {genesis.build_measured}" in out
    hint = build_hint("Genesis")
    assert f"Genesis envs step {genesis.build_speedup:.1f}x faster" in hint and "build-core genesis_plus_gx" in hint
    assert "\n" not in hint
    assert build_hint("PCEngine") == "" and build_hint("Sms") == "" and build_hint("Snes") == ""  # no figure measured


def test_no_line_tells_of_the_build_when_the_user_chose_a_core(isolated, monkeypatch) -> None:
    monkeypatch.setenv(CORES_ENV, str(wheel_cores_dir()))
    assert locate_core("genesis_plus_gx").origin == CORES_ENV and build_hint("Genesis") == ""


@pytest.mark.parametrize("record", [b"{not json", b"[1, 2]", b""], ids=["corrupt", "not-a-dict", "empty"])
def test_a_build_with_an_unreadable_record_is_not_used(isolated, record: bytes) -> None:
    folder = built_cores_dir(isolated)
    folder.mkdir(parents=True)
    (folder / "genesis_plus_gx_libretro.so").write_bytes(b"whatever")
    (folder / "genesis_plus_gx.build.json").write_bytes(record)
    assert locate_core("genesis_plus_gx").origin == "wheel"


def test_the_patch_applies_to_sources_with_crlf_line_ends_and_keeps_them(tmp_path) -> None:
    """Genesis Plus GX's core/ files end their lines in CRLF, libretro.c in LF; the patch is kept in LF."""
    for name, data in original_sources("\r\n").items():
        path = tmp_path / name.removeprefix(f"{RECIPE.folder}/")
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)
    changed = apply_patch(build.patch_text(RECIPE), tmp_path)
    assert len(changed) == len(original_sources()) > 1
    for path in changed:
        text = path.read_bytes()
        assert text.count(b"\n") == text.count(b"\r\n") > 0, path
    assert b"sound_skip = !(av_enable & 2)" in (tmp_path / PATCHED_FILE).read_bytes()


def test_the_sdist_is_fetched_once_and_a_failed_fetch_leaves_nothing(monkeypatch, tmp_path, isolated,
                                                                    pip_without_config, http_index) -> None:
    from retrokit.host.sdist import cached_sdist

    monkeypatch.setenv("PIP_NO_CACHE_DIR", "1")  # the same URL serves two sdists here
    (tmp_path / "broken").mkdir()

    broken = {**METADATA_ONLY_BACKEND, "backend.py": b"raise SystemExit('this sdist is broken')\n"}
    with pytest.raises(CoreBuildError, match="exit 1"):
        cached_sdist("1.0.1", index_url=http_index(fake_sdist(tmp_path / "broken", broken)))
    assert list((isolated / "sdist").iterdir()) == []  # no half file, no fetch folder
    sdist = fake_sdist(tmp_path, METADATA_ONLY_BACKEND)
    kept = cached_sdist("1.0.1", index_url=http_index(sdist))
    assert kept == isolated / "sdist" / "stable_retro-1.0.1.tar.gz" and kept.read_bytes() == sdist.read_bytes()
    # Kept: the next call reads no index (this one answers nothing).
    assert cached_sdist("1.0.1", index_url="http://127.0.0.1:9/", timeout=1) == kept
    assert sorted(p.name for p in (isolated / "sdist").iterdir()) == [kept.name]
