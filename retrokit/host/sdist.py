"""Fetching stable-retro's source package (sdist) with pip, for ``retrokit build-core``.

:func:`fetch_sdist` runs ``pip download`` in a session of its own, follows
the download's progress by the bytes pip writes, kills pip's whole process
group past a deadline (an index that accepts connections and never answers
is given up on), and turns pip's failures into one clear error each: no pip,
an unreachable or silent index, an untrusted plain-http host, no sdist of
that version. Unpacking, patching and compiling are :mod:`retrokit.host.build`'s.
"""

from __future__ import annotations

import contextlib
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from urllib.parse import urlsplit

from retrokit.errors import BuildToolError, CoreBuildError, InvalidArgumentError, SourceFetchError, SourceNotFoundError
from retrokit.paths import data_path, ensure_folder, locked

Progress = Callable[[str, int, int], None]  # (what, done, total): total 0 when unknown


def no_progress(what: str, done: int, total: int) -> None:
    """A :data:`Progress` that shows nothing."""


# pip's messages when it could not reach the index at all (as opposed to
# reaching it and finding no such file).
_NETWORK_FAILURES = (
    "NewConnectionError", "Failed to establish a new connection", "Connection refused", "Network is unreachable",
    "Temporary failure in name resolution", "Name or service not known", "ConnectTimeout", "Read timed out",
    "Max retries exceeded", "ProxyError", "SSLError", "Could not fetch URL", "ReadTimeoutError",
    "ConnectTimeoutError", "is either a non-existing path or lacks a specific scheme",
)  # fmt: skip
# How long pip waits for any one answer of the index, and for the whole download (150 MB): an index
# that accepts connections and never answers is given up on, not waited for forever.
PIP_TIMEOUT = 15.0
FETCH_DEADLINE = 1800.0


def check_index_url(url: str) -> str:
    """Return ``url`` if pip can take it as an index: ``http(s)://host/...`` or ``file:///folder``.

    Raises:
        InvalidArgumentError: It is not such a URL (pip would ignore it and report no versions at all).
    """
    parts = urlsplit(url)
    if (parts.scheme in ("http", "https") and parts.netloc) or (parts.scheme == "file" and parts.path):
        return url
    raise InvalidArgumentError(
        f"Expected --index-url to be an http(s) or file URL, e.g. https://pypi.org/simple; found {url!r}. "
        "Pass the index's full URL, or leave --index-url out to use pip's."
    )


@contextlib.contextmanager
def _killed_after(proc: subprocess.Popen, seconds: float) -> Iterator[threading.Event]:
    """Kill ``proc``'s process group if it still runs after ``seconds``, or when the block is left early.

    ``proc`` must lead its own session (``start_new_session=True``), so that
    what it started (pip's build backend, which holds its output open) goes
    with it. The event yielded is set if the time ran out.
    """
    expired = threading.Event()

    def kill() -> None:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)

    def expire() -> None:
        expired.set()
        kill()

    timer = threading.Timer(seconds, expire)
    timer.daemon = True
    timer.start()
    try:
        yield expired
    finally:
        timer.cancel()
        if proc.poll() is None:  # left early (Ctrl-C, an error): pip must not run on alone
            kill()
            proc.wait()


def fetch_sdist(
    version: str,
    dest: Path,
    *,
    index_url: str | None = None,
    progress: Progress = no_progress,
    timeout: float = PIP_TIMEOUT,
    deadline: float = FETCH_DEADLINE,
) -> Path:
    """Download stable-retro's sdist of ``version`` into ``dest`` with pip; return its path.

    Only options pip 23.0 has are passed (the pip a stock ``python3 -m venv``
    ships): pip's own progress bar is off, and progress comes from the size of
    the files pip writes, which it writes into its temporary folder (here a
    folder of ``dest``'s, through ``TMPDIR``) and then into ``dest``.

    Args:
        version: The stable-retro version.
        dest: The folder to download into.
        index_url: The index; by default pip's configuration.
        progress: Called as the download advances.
        timeout: Seconds pip waits for any one answer of the index (pip's ``--timeout``).
        deadline: Seconds the whole download may take; pip is killed past them.

    Raises:
        BuildToolError: This Python has no pip.
        SourceFetchError: The index could not be reached, or did not answer in time.
        SourceNotFoundError: The index has no sdist of that version.
        CoreBuildError: pip failed otherwise (the message quotes its error and the command to rerun).
    """
    what = [sys.executable, "-m", "pip", "download", "--no-deps", "--no-binary", "stable-retro",
            f"stable-retro=={version}", *(["--index-url", index_url] if index_url is not None else [])]  # fmt: skip
    command = [*what, "-d", str(dest), "--progress-bar", "off", "--retries", "2", "--no-input",
               "--disable-pip-version-check", "--timeout", f"{timeout:g}"]  # fmt: skip
    where = index_url or "the package index"
    scratch = dest / ".pip-tmp"
    scratch.mkdir(parents=True, exist_ok=True)
    log_path = dest / "pip.log"
    try:
        with open(log_path, "w+", encoding="utf-8", errors="replace") as log:
            proc = subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                    env={**os.environ, "TMPDIR": str(scratch)}, text=True,
                                    start_new_session=True)  # fmt: skip
            with _killed_after(proc, deadline) as expired:
                _follow_download(proc, log_path, (scratch, dest), progress)
    except OSError as exc:
        raise BuildToolError(
            f"Expected to run pip ({sys.executable} -m pip); it failed: {exc}. "
            "Download stable-retro's sdist yourself and pass it with --sdist FILE."
        ) from None
    if expired.is_set():
        raise SourceFetchError(
            f"Expected to download stable-retro {version}'s source from {where} within {deadline:g} s; it was not "
            f"done by then (the index answers too slowly, or not at all), so pip was stopped. Check the network "
            f"connection (or --index-url), or download the sdist yourself and pass --sdist FILE."
        )
    lines = log_path.read_text(encoding="utf-8", errors="replace").splitlines()
    found = sorted(dest.glob("stable_retro-*.tar.gz")) + sorted(dest.glob("stable-retro-*.tar.gz"))
    if proc.returncode == 0 and found:
        size = found[0].stat().st_size
        progress("download", size, size)
        return found[0]
    text = "\n".join(lines)
    if "No module named pip" in text:
        raise BuildToolError(
            f"Expected pip in {sys.executable} to download stable-retro's source; found none. "
            f"Install it ({sys.executable} -m ensurepip), or download the sdist yourself and pass --sdist FILE."
        )
    if "ReadTimeoutError" in text or "Read timed out" in text:
        raise SourceFetchError(
            f"Expected to download stable-retro {version}'s source from {where}; it accepted the connection but did "
            f"not answer within {timeout:g} s, three times. Check that the URL is a package index (or "
            f"--index-url), or download the sdist yourself and pass --sdist FILE."
        )
    untrusted = re.search(r"The repository located at (\S+) is not a trusted or secure host", text)
    if untrusted:
        raise SourceFetchError(
            f"Expected to download stable-retro {version}'s source from {where}; pip did not read it, as it reads "
            f"a plain-http index only on this machine or on a host it is told to trust. Use https, or trust the "
            f"host: PIP_TRUSTED_HOST={untrusted.group(1)} retrokit build-core ..."
        )
    if any(marker in text for marker in _NETWORK_FAILURES):
        reason = next(line for line in lines if any(m in line for m in _NETWORK_FAILURES))
        raise SourceFetchError(
            f"Expected to download stable-retro {version}'s source from {where}; could not reach it "
            f"({shorten(reason)}). Check the network connection (or --index-url), then run the command again."
        )
    versions = re.search(r"\(from versions: ([^)]*)\)", text)
    if "No matching distribution" in text or versions:
        listed = versions.group(1) if versions else "none"
        raise SourceNotFoundError(
            f"Expected a source package (sdist) of stable-retro {version} on {where}; found none "
            f"(versions there: {listed}). Install a stable-retro version that has one (1.0.1 has), "
            f"or build from one with --stable-retro VERSION."
        )
    errors = [line for line in lines if line.strip().lower().startswith("error:")]
    last = errors[0] if errors else next((line for line in reversed(lines) if line.strip()), "no output")
    raise CoreBuildError(
        f"Expected pip to download stable-retro {version}'s source; it failed (exit {proc.returncode}): "
        f"{shorten(last)}. Run `{shlex.join(what)}` to see why, or download the sdist yourself and pass --sdist FILE."
    )


def _follow_download(
    proc: subprocess.Popen[str], log_path: Path, folders: tuple[Path, ...], progress: Progress
) -> None:
    """Wait for pip, reporting the bytes in ``folders`` against the size pip's log announces (0 until then)."""
    total = 0
    while True:
        try:
            proc.wait(timeout=0.5)
        except subprocess.TimeoutExpired:
            pass
        if not total:  # pip logs "Downloading URL (150.3 MB)" before it writes a byte
            sizes = re.findall(r"Downloading \S+ \(([\d.]+) (bytes|kB|MB|GB)\)", log_path.read_text(errors="replace"))
            if sizes:
                number, unit = sizes[-1]
                total = int(float(number) * {"bytes": 1, "kB": 1e3, "MB": 1e6, "GB": 1e9}[unit])
        done = sum(_tree_size(folder) for folder in folders)
        if done or total:
            progress("download", min(done, total) if total else done, total)
        if proc.returncode is not None:
            return


def _tree_size(folder: Path) -> int:
    """The bytes of the archives below ``folder`` (what pip unpacks from them is not counted; files vanish while
    pip works: those are skipped)."""
    size = 0
    for root, _, files in os.walk(folder):
        for name in files:
            if not name.endswith(".tar.gz"):
                continue
            try:
                size += os.lstat(os.path.join(root, name)).st_size
            except OSError:
                continue
    return size


def shorten(text: str, limit: int = 200) -> str:
    """A tool's message line on one line of at most ``limit`` characters, without its ``ERROR:``."""
    text = " ".join(text.replace("ERROR:", "").split())
    return text if len(text) <= limit else text[: limit - 3] + "..."


#: The data folder's subfolder that keeps stable-retro's sdists once fetched (one file per version).
SDIST_FOLDER = "sdist"


def cached_sdist(
    version: str,
    *,
    data: Path | None = None,
    index_url: str | None = None,
    progress: Progress = no_progress,
    **fetch_limits: float,
) -> Path:
    """stable-retro's sdist of ``version``, kept in ``<data>/sdist/``: fetched with :func:`fetch_sdist` the first time.

    ``build-core`` and the tests that run stable-retro's own scripts share it,
    so its 150 MB are downloaded once per machine. It is fetched into a folder
    of its own and renamed into place under the folder's lock, so two
    processes fetching at once keep one whole file and a killed fetch leaves none.

    Args:
        version: The stable-retro version.
        data: The data folder; by default :func:`retrokit.paths.data_dir`.
        index_url: The index to fetch from; by default pip's configuration.
        progress: Called as the download advances.
        fetch_limits: ``timeout`` and ``deadline`` of :func:`fetch_sdist`, in seconds.

    Raises:
        SourceFetchError, SourceNotFoundError, BuildToolError, CoreBuildError: As :func:`fetch_sdist`.
        FileSystemError: The data folder cannot be written, or a link is planted in it (PlantedLinkError).
    """
    folder = ensure_folder(data_path(SDIST_FOLDER, data=data), "to keep stable-retro's sdist in")
    target = data_path(SDIST_FOLDER, f"stable_retro-{version}.tar.gz", data=data)  # what builds run: never a link
    if target.is_file():
        return target
    with locked(target):
        if target.is_file():  # another process fetched it while this one waited
            return target
        work = Path(tempfile.mkdtemp(prefix=".fetch-", dir=folder))
        try:
            fetched = fetch_sdist(version, work, index_url=index_url, progress=progress, **fetch_limits)
            os.replace(fetched, target)
        finally:
            shutil.rmtree(work, ignore_errors=True)
    return target
