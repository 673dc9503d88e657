"""``Session``: one game running in the studio, on its own emulator thread.

A session owns a :class:`~retrokit.ramsearch.RamSearch` (the emulator, the
search, the inputs played, the state and field writers) and runs its frame
loop on one thread, at ``speed`` times the console's frame rate, paused or
running. Everything that touches the emulator runs on that thread, between
frames: request handlers go through :meth:`Session.call`, which queues a
function and waits for its result without blocking the server's event loop.

Screens and messages reach the browser through subscribers (one per
WebSocket, see :mod:`retrokit.studio.app`): after each tick the newest screen
is offered to every subscriber, which drops the ones it had no time to send,
so a slow tab never slows the game down.
"""

from __future__ import annotations

import asyncio
import queue
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from retrokit.errors import InvalidArgumentError, RetrokitError
from retrokit.ramsearch import RamSearch
from retrokit.studio.push import Screen, Subscriber

MIN_SPEED, MAX_SPEED = 0.25, 8.0
GRACE_SECONDS = 10.0
"""How long a session keeps its thread after its last WebSocket closed (a reload reconnects within it)."""
STATUS_PERIOD = 0.25
"""Seconds between status messages while running (paused, speed, frame, fps)."""
_LAG_LIMIT = 0.1  # seconds behind schedule after which the loop stops catching up (drops time, not frames)

FrameHook = Callable[["Session"], None]


@dataclass
class _Job:
    fn: Callable[..., Any]
    args: tuple[Any, ...]
    done: Callable[[Any, BaseException | None], None]


@dataclass
class _Stats:
    """Frames emulated over the last second, for the ``fps`` of the status."""

    times: list[float] = field(default_factory=list)

    def add(self, now: float, count: int) -> None:
        self.times.extend([now] * count)
        cut = now - 1.0
        if self.times and self.times[0] < cut:
            self.times = [t for t in self.times if t >= cut]

    def fps(self, now: float) -> float:
        return float(sum(1 for t in self.times if t >= now - 1.0))


class Session:
    """A game played in the studio.

    Args:
        game: The game's name (or folder).
        state: The state to start from (by default the game's default state).
        grace: Seconds the thread lives on, paused, after the last subscriber left.

    Attributes:
        search: The :class:`RamSearch` the session plays (touch it only on the emulator thread).
        frame: Frames played since the session began.
    """

    def __init__(self, game: str, state: str | None = None, *, grace: float = GRACE_SECONDS) -> None:
        self.search = RamSearch(game, state)
        self.grace = grace
        self.frame = 0
        self.speed = 1.0
        self.paused = False
        self.rate = self.search.game.system.frame_rate(self.search.emulator.av_info().get("fps"))
        self._buttons: tuple[str, ...] = ()
        self._hooks: list[FrameHook] = []
        self._subscribers: set[Subscriber] = set()
        self._jobs: queue.SimpleQueue[_Job | None] = queue.SimpleQueue()
        self._thread: threading.Thread | None = None
        self._stopped: threading.Thread | None = None  # the last thread stopped: the next one waits for it
        self._lock = threading.Lock()
        self._stats = _Stats()
        self._leave_timer: threading.Timer | None = None
        self._frame_source: Callable[[Session], bool] | None = None
        self._status_at = 0.0
        self.closed = False
        self.recording = False  # a movie is being recorded (see retrokit.studio.states)
        self._loaded = True  # a state was just loaded: no frame has drawn it yet (see mark_loaded)

    # --- the thread ------------------------------------------------------------------------------

    @property
    def running(self) -> bool:
        """Whether the emulator thread is alive."""
        return self._thread is not None and self._thread.is_alive()

    def start(self) -> None:
        """Start the emulator thread (again, after :meth:`stop`)."""
        with self._lock:
            self._ensure_thread()

    def _ensure_thread(self) -> None:
        """Start a thread unless one runs (hold ``_lock``). A new thread first waits for the stopped one to end,
        so two threads never touch the emulator at once."""
        if self.closed:
            raise InvalidArgumentError("Expected an open session; this one was closed. Start the studio again.")
        if self._thread is None:
            self._thread = threading.Thread(
                target=self._loop, args=(self._jobs, self._stopped), name="retrokit-studio-emulator", daemon=True
            )
            self._thread.start()

    def stop(self) -> None:
        """Stop the emulator thread, keeping the game where it is (a later :meth:`start` goes on).

        Jobs queued before it still run; later ones go to the next thread's queue.
        """
        with self._lock:
            thread = self._retire()
        if thread is not None and thread is not threading.current_thread():
            thread.join()

    def _retire(self) -> threading.Thread | None:
        """Make the running thread the last of its queue and return it (hold ``_lock``): it ends once the jobs
        queued so far have run, and the next job starts a new thread, which waits for it."""
        thread, jobs = self._thread, self._jobs
        if thread is not None:
            self._thread, self._jobs, self._stopped = None, queue.SimpleQueue(), thread
            jobs.put(None)
        return thread

    def close(self) -> None:
        """Stop the thread and close the emulator.

        The session is marked closed before its thread is stopped, under the lock that starts threads: a job
        queued meanwhile (a click-to-find chunk, a frame request) is refused instead of starting a new thread,
        which would hold the emulator while it is closed (it was then left open, about 1 Ctrl-C in 4).
        """
        if self._leave_timer is not None:
            self._leave_timer.cancel()
        with self._lock:
            if self.closed:
                return
            self.closed = True
        self.stop()
        self.search.close()

    def _loop(self, jobs: queue.SimpleQueue[_Job | None], previous: threading.Thread | None) -> None:
        if previous is not None:
            previous.join()
        due = time.perf_counter()
        credit = 0.0
        while True:
            timeout = None if self.paused else max(0.0, due - time.perf_counter())
            try:
                job = jobs.get(timeout=timeout)
            except queue.Empty:
                job = False
            if job is None:
                return
            if job:
                self._run_job(job)
                if self.paused:
                    due = time.perf_counter()  # resuming starts a fresh schedule
                continue
            if self.paused:
                continue
            now = time.perf_counter()
            if now - due > _LAG_LIMIT:  # too slow for this speed: run flat out rather than pile up debt
                due = now
            due += 1.0 / (self.rate * min(self.speed, 1.0))
            credit += max(self.speed, 1.0)
            count, credit = int(credit), credit - int(credit)
            try:
                self.advance(count)
            except Exception as exc:  # noqa: BLE001 (a replayed movie or a core that fails must not end the thread)
                self.paused = True
                self._frame_source = None
                self.publish(_error_message(exc))
                self.publish(self.status())

    def _put(self, job: _Job) -> None:
        with self._lock:
            self._ensure_thread()
            self._jobs.put(job)

    def _run_job(self, job: _Job) -> None:
        try:
            result = job.fn(self, *job.args)
        except BaseException as exc:  # noqa: BLE001 (handed to the caller, who raises it)
            job.done(None, exc)
        else:
            job.done(result, None)

    # --- the entry points ----------------------------------------------------------------------

    async def call(self, fn: Callable[..., Any], *args: Any) -> Any:
        """Run ``fn(session, *args)`` on the emulator thread between frames; return its result or raise its error.

        Raises:
            InvalidArgumentError: The session is closed.
        """
        if self.closed:
            raise InvalidArgumentError("Expected an open session; this one was closed. Start the studio again.")
        loop = asyncio.get_running_loop()
        future: asyncio.Future[Any] = loop.create_future()

        def done(result: Any, exc: BaseException | None) -> None:
            def settle() -> None:
                if future.cancelled():
                    return
                if exc is not None:
                    future.set_exception(exc)
                else:
                    future.set_result(result)

            try:
                loop.call_soon_threadsafe(settle)
            except RuntimeError:  # the caller's event loop closed meanwhile: no one waits for the answer
                pass

        self._put(_Job(fn, args, done))
        return await future

    def call_blocking(self, fn: Callable[..., Any], *args: Any) -> Any:
        """:meth:`call` for a caller that is not on an event loop (a test, a script); it waits."""
        if self.running and self._thread is threading.current_thread():
            return fn(self, *args)
        box: dict[str, Any] = {}
        event = threading.Event()

        def done(result: Any, exc: BaseException | None) -> None:
            box.update(result=result, exc=exc)
            event.set()

        self._put(_Job(fn, args, done))
        event.wait()
        if box["exc"] is not None:
            raise box["exc"]
        return box["result"]

    def on_frame(self, callback: FrameHook) -> Callable[[], None]:
        """Call ``callback(session)`` on the emulator thread after every frame; return a function that stops it."""
        self._hooks.append(callback)

        def remove() -> None:
            if callback in self._hooks:
                self._hooks.remove(callback)

        return remove

    def set_buttons(self, names: Sequence[str]) -> None:
        """Hold these buttons from the next frame on (thread safe).

        Raises:
            InvalidArgumentError: ``names`` is not a list of strings.
            UnknownNameError: A name is not one of the system's buttons (``RIGHT``, or ``2:START`` for port 2).
        """
        if isinstance(names, str) or not all(isinstance(n, str) for n in names):
            raise InvalidArgumentError(f"Expected a list of button names, got {names!r}.")
        self.search.buttons(names)  # checks every name; pure, so safe off the thread
        self._buttons = tuple(names)

    @property
    def buttons(self) -> tuple[str, ...]:
        """The buttons held now."""
        return self._buttons

    def publish(self, message: dict[str, Any]) -> None:
        """Send a JSON message (``{"type": ..., ...}``) to every connected page, the newest of a type first."""
        if not isinstance(message, dict) or not isinstance(message.get("type"), str):
            raise InvalidArgumentError(f'Expected a message {{"type": "...", ...}}, got {message!r}.')
        for subscriber in list(self._subscribers):
            subscriber.offer_message(message)

    # --- subscribers -----------------------------------------------------------------------------

    def subscribe(self, subscriber: Subscriber) -> None:
        """Add a page to send screens and messages to; restart the emulator thread if it had stopped."""
        if self._leave_timer is not None:
            self._leave_timer.cancel()
            self._leave_timer = None
        self._subscribers.add(subscriber)
        self.start()
        subscriber.offer_message(self.status())
        self.call_later(_offer_screen, subscriber)

    def unsubscribe(self, subscriber: Subscriber) -> None:
        """Remove a page; after the last one, pause now and stop the thread after the grace period."""
        self._subscribers.discard(subscriber)
        if self._subscribers or self.closed:
            return
        self.paused = True  # read by the loop before its next frame
        self._leave_timer = threading.Timer(self.grace, self._leave)
        self._leave_timer.daemon = True
        self._leave_timer.start()

    def _leave(self) -> None:
        """The grace period after the last page is over: end the thread if it is idle, deciding on the thread."""
        self.call_later(Session._end_if_idle)

    def _end_if_idle(self) -> None:
        """End the emulator thread if nothing runs on it: paused, no page, no job waiting (on the emulator thread).

        Decided here, between jobs, and not on the grace timer's thread: a request that came after the last page
        left (a replay, a resume by a script) un-pauses the session on this thread, and the timer's stop ended the
        thread in the middle of it, the status saying ``replaying`` and not paused for ever with no thread left to
        play (a replay started within the grace period froze when it ran out). Under ``_lock``, which every job is
        queued under: a job queued meanwhile is either seen here (the thread stays) or goes to the next thread.
        """
        with self._lock:
            idle = self.paused and not self._subscribers and self._jobs.empty()
            if idle and self._thread is threading.current_thread():
                self._retire()

    @property
    def subscribers(self) -> int:
        """How many pages are connected."""
        return len(self._subscribers)

    def call_later(self, fn: Callable[..., Any], *args: Any) -> None:
        """Queue ``fn(session, *args)`` on the emulator thread without waiting (its errors are published)."""

        def done(_result: Any, exc: BaseException | None) -> None:
            if exc is not None:
                self.publish(_error_message(exc))

        with self._lock:
            if self._thread is not None:
                self._jobs.put(_Job(fn, args, done))

    # --- on the emulator thread ------------------------------------------------------------------

    def advance(self, count: int = 1) -> None:
        """Play ``count`` frames holding the buttons (or the movie being replayed), then send the screen."""
        played = 0
        for _ in range(count):
            if self._frame_source is not None and not self._frame_source(self):
                self._frame_source = None
                self.paused = True
                break
            if self._frame_source is None:
                self.search.step(self._buttons, 1)
            self.frame += 1
            played += 1
            self._loaded = False
            for hook in list(self._hooks):
                try:
                    hook(self)
                except Exception as exc:  # noqa: BLE001 (a tool's bug must not stop the game: it is told, and unhooked)
                    self._hooks.remove(hook)
                    message = _error_message(exc)
                    self.publish({**message, "error": f"a frame hook failed and was removed: {message['error']}"})
        now = time.perf_counter()
        self._stats.add(now, played)
        self.send_screen()
        if self.paused or now - self._status_at >= STATUS_PERIOD:
            self._status_at = now
            self.publish(self.status())

    def play_frames(self, source: Callable[[Session], bool] | None) -> None:
        """Take each frame's input from ``source(session)`` (it runs the frame; False: it is over) instead of the buttons."""
        self._frame_source = source

    def mark_loaded(self) -> None:
        """Say the emulator was just put in a saved state (emulator thread).

        Loading a state does not draw it: the video buffer keeps the picture of before (black after a reset).
        Until the next frame runs, :meth:`screen` is the next frame's, emulated on a scratch run
        (:meth:`RamSearch.screen`), so a page paused after a reset sees the state it chose.
        """
        self._loaded = True

    def screen(self) -> np.ndarray:
        """The picture a page should show now (emulator thread)."""
        return self.search.screen() if self._loaded else self.search.emulator.screen()

    def send_screen(self) -> None:
        """Offer the screen now to every page."""
        if not self._subscribers:
            return
        screen = Screen(self.frame, self.screen())
        for subscriber in list(self._subscribers):
            subscriber.offer_screen(screen)

    def status(self) -> dict[str, Any]:
        """The status message: paused, speed, frame, fps (frames emulated in the last second)."""
        return {
            "type": "status",
            "game": self.search.game.name,
            "state": self.search.state,
            "paused": self.paused,
            "speed": self.speed,
            "frame": self.frame,
            "fps": self._stats.fps(time.perf_counter()),
            "replaying": self._frame_source is not None,
            "recording": self.recording,
        }

    def set_speed(self, value: object) -> None:
        """Run at ``value`` times the console's rate, from 0.25 to 8.

        Raises:
            InvalidArgumentError: ``value`` is not a number in that range.
        """
        if not isinstance(value, (int, float)) or isinstance(value, bool) or not MIN_SPEED <= value <= MAX_SPEED:
            raise InvalidArgumentError(f"Expected a speed from {MIN_SPEED} to {MAX_SPEED:g}, got {value!r}.")
        self.speed = float(value)

    def set_paused(self, paused: bool) -> None:
        """Pause or resume, and tell the pages."""
        self.paused = bool(paused)
        self.publish(self.status())

    def refresh_game(self) -> None:
        """Read the game's files again (a state or a default was written): its states, its data file (on the thread)."""
        from retrokit.data.games import Game, find_game
        from retrokit.errors import GameNotFoundError

        game = self.search.game
        try:
            fresh = find_game(game.name)
        except GameNotFoundError:  # a game opened by its folder, outside every games folder
            fresh = None
        if fresh is None or game.folders[0] not in fresh.folders:
            fresh = Game(game.name, game.folders)
        self.search.game = fresh

    def replace_search(self, search: RamSearch) -> None:
        """Play another game (or the same one afresh): close the old search, keep the pages (on the thread)."""
        old, self.search = self.search, search
        self._frame_source = None
        self._buttons = ()
        self.recording = False
        self.rate = search.game.system.frame_rate(search.emulator.av_info().get("fps"))
        old.close()
        self._loaded = True
        self.send_screen()
        self.publish(self.status())


def _offer_screen(session: Session, subscriber: Subscriber) -> None:
    """A new page's first screen (on the emulator thread), unless a frame played since it came offered one.

    A running game's frame can end between :meth:`Session.subscribe` and this job, and offer the page that
    frame's screen: offered again here, the page got the same frame twice (1 run of test_studio_server in 9
    under load). Both run on this thread, so the count is not raced.
    """
    if subscriber.screens == 0:
        subscriber.offer_screen(Screen(session.frame, session.screen()))


def _error_message(exc: BaseException) -> dict[str, Any]:
    """The ``error`` message of an exception: a RetrokitError's one line, else the class and the text."""
    text = str(exc) if isinstance(exc, RetrokitError) else f"{type(exc).__name__}: {exc}"
    return {"type": "error", "error": text, "kind": type(exc).__name__}
