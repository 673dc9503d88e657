"""Building a patched libretro core from stable-retro's source (``retrokit build-core``).

The stable-retro wheel's Genesis Plus GX never asks the frontend whether a
frame will be seen, so it draws every frame a frame-skipping env throws away.
Its source, in stable-retro's sdist on the package index, already has the
switch (``system_frame_gen(do_skip)``); a small patch kept in this package
(``retrokit/native/patches/``) makes ``retro_run`` ask libretro's
``GET_AUDIO_VIDEO_ENABLE`` and pass the answer on. The same is done for
stella, whose ``retro_run`` then skips converting the frames nobody sees,
gambatte, which then skips making and resampling the sound nobody hears,
snes9x and mednafen_pce_fast, which then draw no frame nobody sees, and
fceumm, which then converts none.

:func:`build_core` fetches the sdist of the installed stable-retro version
with pip (:mod:`retrokit.host.sdist`), unpacks only the core's folder, applies the patch, runs the core's
makefile the way stable-retro's own build does (same flags), and installs the
library into ``<data>/cores``, where :func:`retrokit.host.cores.find_core`
prefers it to the wheel's, with a record of what it was built from.
"""

from __future__ import annotations

import hashlib
import json
import os
import shlex
import shutil
import subprocess
import tarfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from retrokit.errors import (
    BuildToolError,
    CoreBuildError,
    FileConflictError,
    SourceNotFoundError,
    UnknownNameError,
    did_you_mean,
)
from retrokit.host.cores import build_record_path, built_cores_dir, core_filename, read_build_record
from retrokit.host.patching import apply_patch
from retrokit.host.sdist import Progress, cached_sdist, check_index_url, no_progress, shorten
from retrokit.host.workdirs import work_folder
from retrokit.paths import atomic_write, require_regular_file

PATCHES_DIR = Path(__file__).resolve().parent.parent / "native" / "patches"

MIB = 2**20
# Bounds on the core's folder extracted from an sdist: stable-retro 1.0.1's cores/genesis holds 558 files,
# 16 MiB in all, the biggest 3.4 MiB; these leave room for growth and none for a bomb.
MAX_MEMBER_BYTES = 32 * MIB
MAX_SOURCE_BYTES = 128 * MIB
MAX_SOURCE_FILES = 10_000

# What stable-retro's CMakeLists.txt passes to every core's makefile with GCC
# (add_core): warnings off, C17, the C++ runtime linked in.
WHEEL_MAKE_ENV = {"CFLAGS": "-w -std=gnu17", "CXXFLAGS": "-w", "LDFLAGS": "-w -static-libstdc++ -Wl,--exclude-libs,ALL"}


@dataclass(frozen=True)
class Recipe:
    """How one core is built from stable-retro's sdist.

    Attributes:
        core: The core's name (``genesis_plus_gx``).
        folder: Its source folder in the sdist, below the top folder.
        makefile: The makefile stable-retro's build runs there.
        patch: The patch file in ``retrokit/native/patches``.
        version_tag: Appended to the core's reported library version, so a
            built core says what it is.
        subdir: Where in ``folder`` make runs and the library appears, as
            stable-retro's build has it (snes9x's ``libretro``); the patch
            applies to ``folder``.
    """

    core: str
    folder: str
    makefile: str
    patch: str
    version_tag: str
    subdir: str = ""


RECIPES = {
    "genesis_plus_gx": Recipe(
        "genesis_plus_gx", "cores/genesis", "Makefile.libretro", "genesis_plus_gx-av-enable.patch", "+av-enable"
    ),
    "stella": Recipe("stella", "cores/atari2600", "Makefile", "stella-av-enable.patch", "+av-enable"),
    "gambatte": Recipe("gambatte", "cores/gb", "Makefile.libretro", "gambatte-av-enable.patch", "+av-enable"),
    "snes9x": Recipe("snes9x", "cores/snes", "Makefile", "snes9x-av-enable.patch", "+av-enable", subdir="libretro"),
    "fceumm": Recipe("fceumm", "cores/nes", "Makefile.libretro", "fceumm-av-enable.patch", "+av-enable"),
    "mednafen_pce_fast": Recipe(
        "mednafen_pce_fast", "cores/pce", "Makefile", "mednafen_pce_fast-av-enable.patch", "+av-enable"
    ),
}


def recipe_for(core: str) -> Recipe:
    """Return the recipe of a core ``retrokit build-core`` can build.

    Raises:
        UnknownNameError: No recipe for that core.
    """
    if core not in RECIPES:
        raise UnknownNameError(
            f"Expected a core retrokit can build ({', '.join(RECIPES)}); got {core!r}." + did_you_mean(core, RECIPES)
        )
    return RECIPES[core]


def check_tools(env: dict[str, str] | None = None) -> tuple[str, str]:
    """Return the C compiler command and make the build will run, as found on ``PATH``.

    The compiler is ``$CC`` if set, else ``cc``.

    Raises:
        BuildToolError: Either is missing.
    """
    env = dict(os.environ if env is None else env)
    path = env.get("PATH", "")
    cc = env.get("CC") or "cc"
    try:
        words = shlex.split(cc) or ["cc"]  # CC may carry a wrapper or flags: "ccache gcc"
    except ValueError as exc:  # an unclosed quote or a trailing backslash
        raise BuildToolError(
            f"Expected CC to be a command line, as a shell splits it (e.g. 'gcc' or 'ccache gcc'); found {cc!r}, "
            f"which does not split ({exc}). Fix its quoting, or unset CC to use cc."
        ) from None
    found_cc, found_make = shutil.which(words[0], path=path), shutil.which("make", path=path)
    for name, found, what in ((words[0], found_cc, "a C compiler"), ("make", found_make, "make")):
        if found is None:
            raise BuildToolError(
                f"Expected {what} ({name}) on PATH to build the core; found none. Install one "
                f"(Debian/Ubuntu: apt install build-essential), or keep using the wheel's core, which needs no build."
            )
    return shlex.join([found_cc, *words[1:]]), found_make  # type: ignore[list-item,return-value]


def unpack_core_source(sdist: Path, folder: str, dest: Path, *, progress: Progress = no_progress) -> Path:
    """Extract only ``folder`` (e.g. ``cores/genesis``) of the sdist into ``dest``; return where it is.

    What is extracted is bounded (:data:`MAX_MEMBER_BYTES` a file, :data:`MAX_SOURCE_BYTES` and
    :data:`MAX_SOURCE_FILES` in all), by the sizes the archive declares, before a byte is written.

    Raises:
        FileSystemError: ``sdist`` is missing, or not a regular file (a FIFO would block forever).
        CoreBuildError: The sdist is unreadable, has no such folder, or its folder is over the bounds.
    """
    require_regular_file(sdist, "a stable-retro sdist (.tar.gz)")
    try:
        with tarfile.open(sdist, "r:gz") as tar:
            members, total = [], 0
            for member in tar:
                rest = member.name.partition("/")[2]
                if rest == folder or rest.startswith(folder + "/"):
                    members.append(member)
                    total += member.size
                    _check_bounds(sdist, member, len(members), total)
            if not members:
                raise CoreBuildError(f"Expected {folder}/ in {sdist.name}; found no such folder. Is it stable-retro's sdist?")
            for i, member in enumerate(members, 1):
                tar.extract(member, dest, filter="data")  # refuses links and paths leaving dest
                progress("unpack", i, len(members))
    except (tarfile.TarError, OSError, EOFError) as exc:
        raise CoreBuildError(f"Expected a readable .tar.gz at {sdist}; reading it failed: {exc}.") from None
    return dest / members[0].name.partition("/")[0] / folder


def _check_bounds(sdist: Path, member: tarfile.TarInfo, count: int, total: int) -> None:
    """Refuse a core folder bigger than any real one (an archive bomb fills the disk, not the source tree)."""
    over = (
        f"{member.name} of {member.size / MIB:,.0f} MiB (at most {MAX_MEMBER_BYTES // MIB} MiB a file)"
        if member.size > MAX_MEMBER_BYTES
        else f"{total / MIB:,.0f} MiB in all (at most {MAX_SOURCE_BYTES // MIB} MiB)"
        if total > MAX_SOURCE_BYTES
        else f"more than {MAX_SOURCE_FILES:,} files"
        if count > MAX_SOURCE_FILES
        else None
    )
    if over is not None:
        raise CoreBuildError(
            f"Expected a core's source in {sdist.name}, as in stable-retro's sdist (16 MiB, 558 files for "
            f"genesis_plus_gx); found {over}, so nothing was extracted past it. Use stable-retro's own sdist."
        )


def patch_text(recipe: Recipe) -> str:
    """Return the recipe's patch, as shipped in the package."""
    return (PATCHES_DIR / recipe.patch).read_text(encoding="utf-8")


def make_core(
    recipe: Recipe, source: Path, cc: str, *, jobs: int | None = None, progress: Progress = no_progress
) -> Path:
    """Run the core's makefile in ``source`` as stable-retro's build does; return the library.

    Raises:
        CoreBuildError: make failed (the message quotes its first error; the full log is kept).
    """
    args = ["make", "-f", recipe.makefile, f"-j{jobs or os.cpu_count() or 1}", f"CC={cc}", "fpic=-fPIC",
            f"GIT_VERSION={recipe.version_tag}"]  # fmt: skip
    env = {**os.environ, **WHEEL_MAKE_ENV}
    where = source / recipe.subdir
    try:  # the dry run lists the commands, so progress has a total
        dry = subprocess.run([*args, "-n"], cwd=where, env=env, capture_output=True, text=True, check=False).stdout
        total = sum(" -c " in line for line in dry.splitlines()) + 1
        log_path = source / "build.log"
        done = 0
        with open(log_path, "w", encoding="utf-8") as log:
            proc = subprocess.Popen(args, cwd=where, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
            assert proc.stdout is not None
            for line in proc.stdout:
                log.write(line)
                if " -c " in line or " -shared " in line:
                    done += 1
                    progress("compile", min(done, total), total)
            proc.wait()
    except OSError as exc:
        raise BuildToolError(
            f"Expected to run make in {source}; it failed: {exc}. Install make and a C compiler "
            f"(Debian/Ubuntu: apt install build-essential), then run the command again."
        ) from None
    library = where / core_filename(recipe.core)
    if proc.returncode != 0 or not library.is_file():
        lines = log_path.read_text(encoding="utf-8", errors="replace").splitlines()
        first = next((line for line in lines if "error" in line.lower()), lines[-1] if lines else "no output")
        raise CoreBuildError(
            f"Expected make to build {library.name}; it failed (exit {proc.returncode}): {shorten(first)}. "
            f"Full log: {log_path} . Fix what it names (a missing compiler or header: on Debian/Ubuntu "
            f"apt install build-essential), then run retrokit build-core {recipe.core} again; meanwhile retrokit "
            f"uses the wheel's core."
        )
    return library


def check_target(recipe: Recipe, data: Path | None, *, force: bool) -> Path:
    """Return where the build goes; a library there that ``build-core`` did not make is replaced only with ``force``.

    Raises:
        FileConflictError: Such a library is in the way.
    """
    target = built_cores_dir(data) / core_filename(recipe.core)
    if target.exists() and read_build_record(recipe.core, data) is None and not force:
        raise FileConflictError(
            f"Expected no core at {target} that retrokit did not build; found one. Move it away, "
            f"or pass --force to replace it."
        )
    return target


def install_core(library: Path, recipe: Recipe, version: str, data: Path | None, *, force: bool) -> Path:
    """Put a built library into ``<data>/cores`` with its record; return its path."""
    target = check_target(recipe, data, force=force)
    record = {
        "core": recipe.core,
        "stable_retro": version,
        "patch": recipe.patch,
        "patch_sha256": hashlib.sha256(patch_text(recipe).encode()).hexdigest(),
        "library_sha256": hashlib.sha256(library.read_bytes()).hexdigest(),
    }
    atomic_write(target, library.read_bytes(), overwrite=True)
    os.chmod(target, 0o755)
    atomic_write(build_record_path(recipe.core, data), json.dumps(record, indent=2).encode(), overwrite=True)
    return target


def up_to_date(recipe: Recipe, version: str, data: Path | None = None) -> Path | None:
    """Return the installed build of a recipe if it is intact and made from ``version`` with today's patch."""
    target = built_cores_dir(data) / core_filename(recipe.core)
    record = read_build_record(recipe.core, data)
    if record is None or not target.is_file():
        return None
    wanted = {
        "stable_retro": version,
        "patch_sha256": hashlib.sha256(patch_text(recipe).encode()).hexdigest(),
        "library_sha256": hashlib.sha256(target.read_bytes()).hexdigest(),
    }
    return target if all(record.get(key) == value for key, value in wanted.items()) else None


def build_core(
    core: str,
    *,
    version: str | None = None,
    index_url: str | None = None,
    data: Path | None = None,
    sdist: Path | None = None,
    force: bool = False,
    progress: Progress = no_progress,
    step: Callable[[str], None] = lambda message: None,
    **fetch_limits: float,
) -> Path:
    """Fetch, patch, build and install a core; return the installed library.

    Args:
        core: The core's name (see :data:`RECIPES`).
        version: The stable-retro version whose source to build; by default the installed one.
        index_url: The package index to fetch from; by default pip's configuration.
        data: The data folder to install into; by default :func:`retrokit.paths.data_dir`.
        sdist: A stable-retro sdist already on disk, instead of fetching one.
        force: Build again even if an intact build exists, and replace a
            core in the way that ``build-core`` did not make.
        progress: Called as steps advance: ``(what, done, total)``.
        step: Called with a line saying what happens next.
        fetch_limits: ``timeout`` and ``deadline`` of :func:`fetch_sdist`, in seconds.

    Raises:
        CoreBuildError: A tool is missing, the index is unreachable or has no
            sdist, the patch does not apply, or make failed (each a subclass).
    """
    from retrokit.host.cores import stable_retro_version

    recipe = recipe_for(core)
    if index_url is not None and sdist is None:
        check_index_url(index_url)
    version = version or stable_retro_version()
    if version is None:
        raise SourceNotFoundError(
            "Expected stable-retro to be installed (its version picks the source to build); found it missing. "
            "Install it (pip install 'stable-retro>=1.0,<2'), or pass --stable-retro VERSION."
        )
    current = up_to_date(recipe, version, data)
    if current is not None and not force:
        step(f"Already built from stable-retro {version} with {recipe.patch}: {current} (--force builds it again)")
        return current
    check_target(recipe, data, force=force)
    cc, _ = check_tools()
    with work_folder() as work:  # removes the folders of builds that were killed, too
        if sdist is None:
            step(f"Fetching stable-retro {version}'s source from {index_url or 'the package index'} (about 150 MB, once: it is kept in the data folder's sdist/)")
            sdist = cached_sdist(version, data=data, index_url=index_url, progress=progress, **fetch_limits)
        step(f"Unpacking {recipe.folder}/ from {sdist.name}")
        source = unpack_core_source(sdist, recipe.folder, work / "src", progress=progress)
        step(f"Applying {recipe.patch}")
        apply_patch(patch_text(recipe), source, recipe.patch)
        step(f"Compiling {recipe.core} with {cc} (about a minute)")
        try:
            library = make_core(recipe, source, cc, progress=progress)
        except CoreBuildError as exc:  # keep the log: the temporary folder goes away
            if not (source / "build.log").is_file():
                raise
            log = built_cores_dir(data) / f"{recipe.core}.build.log"
            atomic_write(log, (source / "build.log").read_bytes(), overwrite=True)
            raise CoreBuildError(str(exc).replace(str(source / "build.log"), str(log))) from None
        target = install_core(library, recipe, version, data, force=force)
    step(f"Installed {target}")
    return target
