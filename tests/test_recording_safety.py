"""make(record=...): the folder is checked at make(), and a movie survives a kill or a script that never closes.

Issue 19 section 5. The folder is made and tried when the env is made, so a
file in the way, a name too long, a NUL byte or a folder under /proc is a
retrokit error there, not a raw OSError at the first reset(). A recording
movie is written whole every ``FLUSH_SECONDS`` it has new frames, by a thread
(issue 42: the check ran only as frames were recorded, so a script that paused
after its steps lost them all to a kill), so a process killed with SIGKILL
leaves a movie that plays up to about a second before the kill; and a
finalizer writes the movie of a script that exits without ``env.close()``.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest
from childproc import REPO

import retrokit
from retrokit.errors import FileSystemError, InvalidArgumentError
from retrokit.movie import play, read_bk2
from retrokit.movie.recorder import FLUSH_SECONDS, MovieRecorder

BAD_FOLDERS = {
    "an-existing-file": (lambda tmp: tmp / "afile", FileSystemError, "found a file, not a folder"),
    "under-a-file": (lambda tmp: tmp / "afile" / "movies", FileSystemError, "parent folders should be"),
    "a-300-character-name": (lambda tmp: tmp / ("m" * 300), FileSystemError, "File name too long"),
    "a-folder-under-proc": (lambda tmp: Path("/proc/movies"), FileSystemError, "cannot be made"),
    "proc-itself": (lambda tmp: Path("/proc"), FileSystemError, "cannot be written"),
    "a-nul-byte": (lambda tmp: f"{tmp}/mo\0vies", FileSystemError, "holds a NUL byte"),
    "an-empty-string": (lambda tmp: "", InvalidArgumentError, "Expected record to be a folder path"),
}


@pytest.mark.parametrize("case", list(BAD_FOLDERS), ids=list(BAD_FOLDERS))
def test_a_record_folder_that_cannot_take_movies_is_refused_at_make(tmp_path: Path, case: str) -> None:
    (tmp_path / "afile").write_text("not a folder")
    folder, error, message = BAD_FOLDERS[case]
    with pytest.raises(error, match=message) as info:
        retrokit.make("Dasher-Genesis", record=folder(tmp_path))
    assert "\n" not in str(info.value)
    assert (tmp_path / "afile").read_text() == "not a folder"  # the file in the way is left alone


def test_the_record_folder_is_made_at_make(tmp_path: Path) -> None:
    folder = tmp_path / "new" / "movies"
    env = retrokit.make("Dasher-Genesis", record=folder)
    try:
        assert folder.is_dir() and list(folder.iterdir()) == []  # made and tried; the probe file is gone
    finally:
        env.close()


RECORDING = """
import sys, time
import retrokit
env = retrokit.make("Dasher-Genesis", record={folder!r})
env.reset(seed=0)
env.action_space.seed(0)
recorder = env.unwrapped.movies.recorder
while True:
    env.step(env.action_space.sample())
    print(len(recorder), time.monotonic(), flush=True)
    time.sleep(0.004)  # a script's own pace (an agent thinking): flushes are by the clock, not by frames
"""


def test_a_movie_survives_sigkill_up_to_about_a_second_before(tmp_path: Path) -> None:
    folder = tmp_path / "movies"
    child = subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(RECORDING.format(folder=str(folder)))],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=REPO,
    )
    reports: list[tuple[int, float]] = []
    try:
        assert child.stdout is not None
        started = None
        for line in child.stdout:
            frames, at = line.split()
            reports.append((int(frames), float(at)))
            started = started or float(at)
            # Two flushes in, and over a flush and a second's slack past the first report: the frames of that
            # first half second must be in the movie (the child paces its steps, so waiting costs little CPU).
            if float(at) - started > 2 * FLUSH_SECONDS + 0.5:
                break
        killed_at = time.monotonic()
        child.send_signal(signal.SIGKILL)
    finally:
        child.kill()
        child.wait(timeout=30)
    assert child.returncode == -signal.SIGKILL, child.stderr.read() if child.stderr else ""
    movies = sorted(folder.glob("*.bk2"))
    assert len(movies) == 1 and movies[0].stat().st_size > 0, movies
    movie = read_bk2(movies[0])
    # Every frame recorded more than a flush (and a second's slack for a loaded machine) before the kill is there.
    settled = max((frames for frames, at in reports if at < killed_at - FLUSH_SECONDS - 1), default=0)
    assert settled > 0 and settled <= len(movie.frames) <= reports[-1][0], (settled, len(movie.frames), reports[-1])
    assert sum(1 for _ in play(movie)) == len(movie.frames)  # and it plays back, frame for frame
    assert not [p for p in folder.iterdir() if p.suffix != ".bk2"]  # no temporary file left


EXITING = """
import retrokit
env = retrokit.make("Dasher-Genesis", record={folder!r})
env.reset(seed=0)
env.action_space.seed(0)
for _ in range(50):
    env.step(env.action_space.sample())
print(len(env.unwrapped.movies.recorder))
{ending}
"""
ENDINGS = {
    "script-ends": "",
    "system-exit": "raise SystemExit(3)",
    "env-dropped": "del env; import gc; gc.collect(); print('dropped')",
}

#: Forks one script per ending, one after the other, from an interpreter that made and closed an env first (imports
#: and the game's checks warm). Each child runs its script at the top level, as ``python -c`` would, and then ends
#: as that interpreter would: falling off the end or raising SystemExit, its finalizers and atexit run.
EXIT_LAUNCHER = """
import json, os, sys, tempfile
import retrokit
with tempfile.TemporaryDirectory() as warm:
    retrokit.make("Dasher-Genesis", record=warm).close()
scripts, script = json.loads(sys.argv[1]), None
statuses = {}
for name, (code, out, err) in scripts.items():
    sys.stdout.flush()
    pid = os.fork()
    if pid == 0:
        for fd, path in ((1, out), (2, err)):
            os.dup2(os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC), fd)
        script = code
        break
    statuses[name] = os.waitstatus_to_exitcode(os.waitpid(pid, 0)[1])
if script is None:
    print(json.dumps(statuses))
else:
    del scripts, statuses, warm
    exec(compile(script, "<script>", "exec"))
"""


@pytest.fixture(scope="module")
def scripts_that_never_close(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[int, str, str, Path]]:
    """Each ending's script run to its end: its exit status, stdout, stderr and movie folder."""
    root = tmp_path_factory.mktemp("endings")
    scripts = {
        name: (textwrap.dedent(EXITING.format(folder=str(root / name / "movies"), ending=ending)),
               str(root / f"{name}.out"), str(root / f"{name}.err"))
        for name, ending in ENDINGS.items()
    }  # fmt: skip
    done = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(EXIT_LAUNCHER), json.dumps(scripts)],
        capture_output=True, text=True, timeout=240, cwd=REPO, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    statuses = json.loads(done.stdout)
    return {
        name: (statuses[name], Path(out).read_text(), Path(err).read_text(), root / name / "movies")
        for name, (_, out, err) in scripts.items()
    }


@pytest.mark.parametrize("ending", list(ENDINGS))
def test_a_script_that_never_closes_its_env_leaves_a_complete_movie(scripts_that_never_close, ending: str) -> None:
    status, stdout, stderr, folder = scripts_that_never_close[ending]
    assert status == (3 if ending == "system-exit" else 0) and "Traceback" not in stderr, stderr
    recorded = int(stdout.split()[0])
    movies = sorted(folder.glob("*.bk2"))
    assert len(movies) == 1, movies
    movie = read_bk2(movies[0])
    assert recorded >= 50 and len(movie.frames) == recorded  # every frame, not only those of the last flush
    assert sum(1 for _ in play(movie)) == recorded


def test_a_forked_child_does_not_write_its_parents_movie(tmp_path: Path) -> None:
    recorder = MovieRecorder(tmp_path / "m.bk2", "Dasher-Genesis", "Genesis", 1)
    recorder.record([0])
    pid = os.fork()
    if pid == 0:  # the child exits at once, running its finalizers only if they are its own
        import atexit

        atexit._run_exitfuncs()
        os._exit(0)
    os.waitpid(pid, 0)
    assert read_bk2(tmp_path / "m.bk2").frames == []  # as the recorder wrote it when made: the child wrote nothing
    assert recorder.close() == tmp_path / "m.bk2" and len(read_bk2(tmp_path / "m.bk2").frames) == 1


def test_a_recorder_killed_in_its_first_second_leaves_a_movie_that_plays(tmp_path: Path) -> None:
    """Killed right after reset(), before any flush: the movie already holds its header and start state."""
    folder = tmp_path / "movies"
    code = (
        "import os, signal, retrokit\n"
        f"env = retrokit.make('Dasher-Genesis', record={str(folder)!r})\n"
        "env.reset(seed=0)\n"
        "env.step(env.action_space.sample())\n"
        "os.kill(os.getpid(), signal.SIGKILL)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=REPO, timeout=120, check=False)
    assert done.returncode == -signal.SIGKILL, done.stderr
    (movie_file,) = sorted(folder.glob("*.bk2"))
    assert movie_file.stat().st_size > 0
    movie = read_bk2(movie_file)
    assert movie.state and sum(1 for _ in play(movie)) == len(movie.frames)
    assert not [p for p in folder.iterdir() if p.suffix != ".bk2"]


#: Forks one recorder per line read (the folder it records into), each told apart by its pid. The launcher made and
#: closed an env first, so each recorder's make() finds the game, its checks and the emulator host warm: what a
#: kill interrupts is make(), reset() and the recording, not a fresh interpreter's second of imports.
LAUNCHER = """
import os, sys, tempfile, traceback
import retrokit
with tempfile.TemporaryDirectory() as warm:
    retrokit.make("Dasher-Genesis", record=warm).close()
def say(*words):
    os.write(1, (" ".join(map(str, words)) + "\\n").encode())
for folder in sys.stdin:
    pid = os.fork()
    if pid == 0:
        try:
            env = retrokit.make("Dasher-Genesis", record=folder.strip())
            say(os.getpid(), "ready")
            env.reset(seed=0)  # the episode's movie begins here
            env.action_space.seed(0)
            say(os.getpid(), "recording")
            while True:
                env.step(env.action_space.sample())
        except BaseException:
            traceback.print_exc()
        os._exit(1)
    say(pid, "forked")
    _, status = os.waitpid(pid, 0)
    say(pid, "ended", status)
"""
#: When to kill: at fork (None: not waiting for it to be ready), then from 0 to 300 ms after it is ready to reset(),
#: then ("recording") from 0 to 300 ms after reset() returned.
KILL_AFTER = [
    (None, 0), (None, 0), *(("ready", d) for d in (0, 0.002, 0.005, 0.01, 0.02, 0.03, 0.045, 0.06, 0.08, 0.1, 0.15,
    0.2, 0.3)), *(("recording", d) for d in (0, 0.01, 0.1, 0.3)),
]


def test_a_recorder_killed_at_any_moment_leaves_no_movie_or_one_that_plays(tmp_path: Path) -> None:
    """The movie appears only once it is whole: a name was reserved by an empty .bk2 first, and a kill in the
    milliseconds before the movie replaced it left that empty file, which plays nowhere."""
    launcher = subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(LAUNCHER)],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=REPO,
    )  # fmt: skip
    assert launcher.stdin is not None and launcher.stdout is not None
    played = 0
    try:
        for attempt, (mark, delay) in enumerate(KILL_AFTER):
            folder = tmp_path / f"try-{attempt}"
            launcher.stdin.write(f"{folder}\n")
            launcher.stdin.flush()
            said = ""
            while said != (mark or "forked"):  # the child may speak before its launcher says it forked it
                pid, said, *_ = launcher.stdout.readline().split() or ("", "gone")
                if said not in ("forked", "ready", "recording"):  # ended or gone before the kill: show why
                    launcher.kill()
                    raise AssertionError(f"{pid} {said}: {launcher.communicate()[1]}")
            time.sleep(delay)  # the moment of the kill is what this test varies
            os.kill(int(pid), signal.SIGKILL)
            for line in launcher.stdout:  # "ready" or "recording" may come before the kill lands
                if line.startswith(f"{pid} ended"):
                    assert os.waitstatus_to_exitcode(int(line.split()[2])) == -signal.SIGKILL, line
                    break
            else:
                raise AssertionError(f"the launcher ended: {launcher.stderr.read() if launcher.stderr else ''}")
            for movie_file in sorted(folder.glob("*.bk2")):
                movie = read_bk2(movie_file)  # an empty or half-written file raises here
                assert movie.state and sum(1 for _ in play(movie)) == len(movie.frames), (delay, movie_file)
                played += 1
    finally:
        launcher.kill()
        launcher.wait(timeout=30)
    assert played >= sum(mark == "recording" for mark, _ in KILL_AFTER)  # every kill after reset() left a movie


#: Forks one recorder per line read ("<folder> <steps> <steps of a second episode, or -1 for none>"): it records
#: that many steps, says how many frames its movie holds, then idles as a script that thinks or waits would,
#: recording nothing more, until it is killed.
IDLER = """
import os, sys, tempfile, time
import retrokit
with tempfile.TemporaryDirectory() as warm:
    retrokit.make("Dasher-Genesis", record=warm).close()
for line in sys.stdin:
    folder, steps, again = line.split()
    pid = os.fork()
    if pid == 0:
        env = retrokit.make("Dasher-Genesis", record=folder)
        env.reset(seed=0)
        env.action_space.seed(0)
        for episode_steps in (int(steps), int(again)):
            if episode_steps < 0:
                break
            if episode_steps != int(steps):
                env.reset()  # the first episode's movie is closed whole; the second one records
            for _ in range(episode_steps):
                env.step(env.action_space.sample())
        os.write(1, f"{os.getpid()} {len(env.unwrapped.movies.recorder)}\\n".encode())
        time.sleep(3600)
        os._exit(1)
    os.waitpid(pid, 0)
    os.write(1, b"ended\\n")
"""
#: (steps, steps of a second episode): just after reset(), after one step, after 300 (the issue's case), and
#: 20 steps into a second episode.
IDLE_POINTS = [(0, -1), (1, -1), (300, -1), (300, 20)]


def _movie_holding(folder: Path, frames: int) -> Path:
    """The newest movie in ``folder`` once it holds ``frames`` frames (the recorder's thread writes it within a
    second; a minute is slack for a loaded machine, not a measured time)."""
    waited = time.monotonic()
    while time.monotonic() - waited < 60:
        newest = sorted(folder.glob("*.bk2"))[-1:]
        if newest and len(read_bk2(newest[0]).frames) == frames:
            return newest[0]
        time.sleep(0.05)  # polling a condition, not timing it
    raise AssertionError(f"no movie in {folder} came to hold the {frames} frames recorded before the kill")


def test_a_recorder_killed_while_idle_keeps_every_frame_it_recorded(tmp_path: Path) -> None:
    """Issue 42: 300 steps, then a pause, then SIGKILL left a movie with an empty input log (flushes waited for the
    next step). Each point is killed once its movie holds all it recorded: every frame, and it plays back."""
    launcher = subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(IDLER)],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=REPO,
    )  # fmt: skip
    assert launcher.stdin is not None and launcher.stdout is not None
    try:
        for steps, again in IDLE_POINTS:
            folder = tmp_path / f"{steps}-{again}"
            launcher.stdin.write(f"{folder} {steps} {again}\n")
            launcher.stdin.flush()
            answer = launcher.stdout.readline().split()
            assert len(answer) == 2, f"{answer}: {launcher.stderr.read() if launcher.stderr else ''}"
            pid, frames = map(int, answer)
            movie_file = _movie_holding(folder, frames)
            os.kill(pid, signal.SIGKILL)
            assert launcher.stdout.readline() == "ended\n"
            movie = read_bk2(movie_file)
            assert len(movie.frames) == frames == (again if again >= 0 else steps)  # a frame a step: no frameskip
            assert movie.state and sum(1 for _ in play(movie)) == frames
            assert len(list(folder.glob("*.bk2"))) == (2 if again >= 0 else 1)
            assert not [p for p in folder.iterdir() if p.suffix != ".bk2"]
    finally:
        launcher.kill()
        launcher.wait(timeout=30)
