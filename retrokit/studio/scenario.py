"""Scenario: the YAML in an editor, its compile errors where the language puts them, and its reward live.

Text from the page is compiled by :func:`retrokit.dsl.scenario.scenario_from_text`,
read exactly as the file it will be saved to, so an error carries the line and
column the language reports for that file. Saving writes the file atomically,
only when asked and only once it compiles. Every edit can also be kept as a
draft in the data folder (``<data>/studio/drafts/<Game>/<name>.yaml``), so a
closed tab or a stopped server loses nothing: the page gets it back with the
scenario.

While a scenario is live, a frame hook evaluates it after every frame, as an
env with ``scenario_every_frame`` does: the game's fields read by the envs'
:class:`~retrokit.host.memory.FieldReader`, then ``Run.step`` of the compiled
scenario. Loading a state starts a new episode (``initial()`` and the total
begin again); once done, the total stays until then. The page gets
``{"type": "reward", "frame", "samples": [[frame, reward, total, done], ...], "total", "done"}``
20 times a second (the samples overlap: the page keeps each frame once), and
``GET /api/scenario/live`` returns the last :data:`HISTORY` frames.

Routes (under ``/api``): ``GET /scenario?name=``, ``POST /scenario/compile``
``{"text", "name"?}``, ``PUT /scenario/draft`` ``{"text", "name"?}``, ``DELETE
/scenario/draft?name=``, ``POST /scenario/save`` ``{"text", "name"?}``, ``POST
/scenario/live`` ``{"name"?, "text"?}``, ``GET /scenario/live``, ``DELETE /scenario/live``.
"""

from __future__ import annotations

import asyncio
import collections
import weakref
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from starlette.requests import Request
from starlette.responses import JSONResponse
from starlette.routing import Route

from retrokit import paths
from retrokit.data.names import check_state_name
from retrokit.dsl.scenario import Run, Scenario, scenario_from_text
from retrokit.dsl.source import read_source
from retrokit.errors import DataFileError, InvalidArgumentError, ScenarioError, ScenarioRuntimeError
from retrokit.studio.fields import field_reader
from retrokit.studio.search import Pacer
from retrokit.studio.security import check_inside, expect, game_roots, json_body, resolve_path, session_of

if TYPE_CHECKING:
    from retrokit.studio.session import Session

HISTORY = 600
"""Frames of reward kept for the plot: 10 seconds at 60 fps."""
_OVERLAP = 12  # samples a push repeats from before the last one: a push the page missed is covered by the next


def _name(value: object, game: Any) -> str:
    """The scenario's name: given, or the game's default (``scenario``)."""
    if value is None or value == "":
        return game.default_scenario or "scenario"
    return check_state_name(value, what="scenario name")


def draft_path(game: str, name: str) -> Path:
    """The draft of a game's scenario in the data folder."""
    return paths.data_path("studio", "drafts", game, f"{name}.yaml")  # never through a planted link


@dataclass(frozen=True)
class Where:
    """A scenario of the session's game: its name, its file, where it is saved, and its draft."""

    game: Any
    name: str
    path: Path | None  # the file the game reads it from, if it has one
    target: Path | None  # where saving writes it: beside the game's own game.yaml
    why_not: str | None  # why it cannot be saved (a game inside an installed package)

    @property
    def source(self) -> str:
        """What its errors call it: the file saving writes (or reads)."""
        return str(self.target or self.path or f"{self.name}.yaml")

    @property
    def draft(self) -> Path:
        return draft_path(self.game.name, self.name)


def where(session: Session, name: object) -> Where:
    """Scenario ``name`` (the default one if none) of the session's game (emulator thread: the game may change)."""
    search = session.search
    game = search.game
    name = _name(name, game)
    try:
        target, why_not = search.default_game_file().parent / f"{name}.yaml", None
    except DataFileError as exc:  # a shipped game: its scenarios compile and run, and are not saved
        target, why_not = None, str(exc)
    place = Where(game, name, game.scenarios.get(name), target, why_not)
    roots = game_roots(game)  # a planted link (the file, the drafts folder, game.yaml's) reaches nothing outside
    for path, what in ((place.path, "scenario file"), (place.target, "scenario file"), (place.draft, "scenario draft")):
        if path is not None:
            check_inside(path, roots, what=what)
    return place


def _read_text(path: Path) -> str:
    return read_source(path).text


def compile_text(place: Where, text: str) -> Scenario:
    """Compile ``text`` as scenario ``place``, its errors located in the file it is saved to.

    It runs off the emulator thread: it reads no RAM, and hostile text may take a second or two.

    Raises:
        ScenarioError: It does not compile (with ``line`` and ``column`` where the language gives them).
    """
    game = place.game

    def include(base: Path, name: str) -> Path:  # the text is a request's: what it includes stays in the game's folders
        return resolve_path(name, base, game.folders, what="scenario file to include")

    return scenario_from_text(
        text, list(game.fields), source=place.source, name=place.name, game_dir=game.folders[0], resolve_include=include
    )


def _compile_saved(place: Where) -> Scenario:
    """The scenario as its file holds it (a Gym Retro ``.json`` one too)."""
    from retrokit.dsl.scenario import load_scenario

    path = place.game.scenario_path(place.name)  # none of that name: UnknownNameError, with a did-you-mean
    if path.suffix.lower() == ".json":
        return load_scenario(path, list(place.game.fields), game_dir=path.parent, name=place.name)
    return compile_text(place, _read_text(path))


def error_json(exc: Exception) -> dict[str, Any]:
    """A scenario error as JSON: its first line, the whole message, and the line and column it points at."""
    text = str(exc)
    return {
        "error": text.splitlines()[0] if text else type(exc).__name__,
        "message": text,
        "kind": type(exc).__name__,
        "line": getattr(exc, "line", None),
        "column": getattr(exc, "column", None),
    }


# --- the live reward -------------------------------------------------------------------------------


@dataclass
class _Live:
    """A scenario evaluated after every frame of the session."""

    name: str
    scenario: Scenario
    run: Run | None = None
    search: Any = None
    start_state: bytes | None = None
    episode_frame: int = 0
    total: float = 0.0
    done: bool = False
    error: dict[str, Any] | None = None
    samples: collections.deque = field(default_factory=lambda: collections.deque(maxlen=HISTORY))
    unsent: int = 0  # samples taken since the last push
    pacer: Pacer = field(default_factory=Pacer)
    remove: Any = None

    def restart(self, session: Session) -> None:
        """A new episode from the game's moment now (a run-time error of the scenario is kept in ``error``)."""
        self.search, self.start_state = session.search, session.search.start_state
        self.episode_frame, self.total, self.done, self.error = 0, 0.0, False, None
        self.run = self.scenario.start()
        try:
            self.run.reset(field_reader(session).read())
        except ScenarioRuntimeError as exc:  # the scenario's fault, told to the page; the game goes on
            self.error = error_json(exc)

    def step(self, session: Session) -> None:
        """Evaluate the scenario on this frame's fields."""
        self.episode_frame += 1
        try:
            rewards, done = self.run.step(field_reader(session).read(), self.episode_frame, self.episode_frame)
        except ScenarioRuntimeError as exc:
            self.error = error_json(exc)
            return
        reward = float(sum(rewards))
        self.total += reward
        self.done = bool(done)
        self.samples.append([session.frame, reward, self.total, self.done])
        self.unsent += 1

    def report(self, count: int | None = None) -> dict[str, Any]:
        samples = list(self.samples)
        return {
            "type": "reward",
            "name": self.name,
            "players": self.scenario.players,
            "frame": samples[-1][0] if samples else None,
            "samples": samples if count is None else samples[-count:],
            "total": self.total,
            "done": self.done,
            "error": self.error,
        }


_live: weakref.WeakKeyDictionary[Session, _Live] = weakref.WeakKeyDictionary()


def _on_frame(session: Session) -> None:
    """Frame hook: step the live scenario on this frame's fields; push the reward 20 times a second."""
    live = _live.get(session)
    if live is None:
        return
    if live.search is not session.search or live.start_state is not session.search.start_state:
        live.restart(session)  # a state was loaded (or another game): a new episode
    if live.error is None and not live.done:
        live.step(session)
    if live.pacer.ready(session):
        session.publish(live.report(live.unsent + _OVERLAP))
        live.unsent = 0


def _go_live(session: Session, name: str, scenario: Scenario) -> dict[str, Any]:
    old = _live.get(session)
    live = _Live(name, scenario, remove=old.remove if old is not None else None)
    live.restart(session)
    _live[session] = live
    if live.remove is None:
        live.remove = session.on_frame(_on_frame)
    return live.report()


def _stop(session: Session) -> dict[str, Any]:
    live = _live.pop(session, None)
    if live is not None and live.remove is not None:
        live.remove()
    return {"live": False}


def _live_report(session: Session) -> dict[str, Any]:
    live = _live.get(session)
    return {"live": False} if live is None else {"live": True, **live.report()}


# --- the text, drafts and saving -------------------------------------------------------------------


def _get(place: Where) -> dict[str, Any]:
    text = _read_text(place.path) if place.path is not None else ""
    kept = _read_text(place.draft) if place.draft.is_file() else None
    return {
        "name": place.name,
        "names": list(place.game.scenarios),
        "path": str(place.path) if place.path is not None else None,
        "text": text,
        "draft": kept if kept != text else None,
        "save_to": str(place.target) if place.target is not None else None,
        "writable": place.target is not None,
        "why_not": place.why_not,
    }


def _checked(place: Where, text: str) -> dict[str, Any]:
    """Compile ``text``: ``{"ok": true, ...}``, or ``{"ok": false, ...}`` with the error where it is."""
    try:
        scenario = compile_text(place, text)
    except ScenarioError as exc:
        return {"ok": False, **error_json(exc)}
    return {"ok": True, "name": place.name, "players": scenario.players, "fields": list(scenario.fields)}


def _put_draft(place: Where, text: str) -> dict[str, Any]:
    paths.ensure_folder(place.draft.parent, "the studio's scenario drafts")
    paths.atomic_write(place.draft, text.encode("utf-8"), overwrite=True)  # the studio's own file, replaced at each edit
    return {"draft": str(place.draft), **_checked(place, text)}


def _save(place: Where, text: str) -> Scenario:
    """Compile, then write the file and drop the draft; nothing is written unless it compiles.

    Raises:
        DataFileError: The game's folder is inside an installed package.
        ScenarioError: The text does not compile.
    """
    if place.target is None:
        raise DataFileError(place.why_not)
    scenario = compile_text(place, text)
    paths.atomic_write(place.target, text.encode("utf-8"), overwrite=True)  # the user asked to save over it
    place.draft.unlink(missing_ok=True)
    return scenario


def _saved(session: Session, place: Where, scenario: Scenario) -> None:
    """After a save: the game's scenarios listed afresh, and the live one replaced if it is this one."""
    session.search.reload_game()
    live = _live.get(session)
    if live is not None and live.name == place.name:
        _go_live(session, place.name, scenario)


def _utf8(text: str) -> str:
    """``text`` if it can be saved as UTF-8 (JSON can carry a lone surrogate, which no file holds).

    Raises:
        InvalidArgumentError: It cannot.
    """
    try:
        text.encode("utf-8")
    except UnicodeEncodeError as exc:
        raise InvalidArgumentError(
            f"Expected the scenario's text as Unicode text; found {exc.object[exc.start]!r} at character {exc.start}, "
            "half of a UTF-16 pair, which no file can hold. Remove it."
        ) from None
    return text


async def _text(request: Request) -> tuple[Where, str]:
    body = await json_body(request)
    text, name = _utf8(expect(body, "text", str)), expect(body, "name", str, None)
    return await session_of(request).call(where, name), text


async def get(request: Request) -> JSONResponse:
    place = await session_of(request).call(where, request.query_params.get("name"))
    return JSONResponse(await asyncio.to_thread(_get, place))


async def compile_(request: Request) -> JSONResponse:
    place, text = await _text(request)
    return JSONResponse(await asyncio.to_thread(_checked, place, text))


async def put_draft(request: Request) -> JSONResponse:
    place, text = await _text(request)
    return JSONResponse(await asyncio.to_thread(_put_draft, place, text))


async def drop_draft(request: Request) -> JSONResponse:
    place = await session_of(request).call(where, request.query_params.get("name"))
    place.draft.unlink(missing_ok=True)
    return JSONResponse({"draft": None, "name": place.name})


async def save(request: Request) -> JSONResponse:
    place, text = await _text(request)
    try:
        scenario = await asyncio.to_thread(_save, place, text)
    except ScenarioError as exc:
        return JSONResponse(error_json(exc), status_code=400)
    await session_of(request).call(_saved, place, scenario)
    return JSONResponse({"saved": str(place.target), "name": place.name, "players": scenario.players})


async def live_start(request: Request) -> JSONResponse:
    body = await json_body(request)
    text, name = expect(body, "text", str, None), expect(body, "name", str, None)
    text = None if text is None else _utf8(text)
    session = session_of(request)
    place = await session.call(where, name)
    try:
        if text is None:
            scenario = await asyncio.to_thread(_compile_saved, place)
        else:
            scenario = await asyncio.to_thread(compile_text, place, text)
    except ScenarioError as exc:
        return JSONResponse(error_json(exc), status_code=400)
    return JSONResponse(await session.call(_go_live, place.name, scenario))


async def live_get(request: Request) -> JSONResponse:
    return JSONResponse(await session_of(request).call(_live_report))


async def live_stop(request: Request) -> JSONResponse:
    return JSONResponse(await session_of(request).call(_stop))


routes = [
    Route("/scenario", get, methods=["GET"]),
    Route("/scenario/compile", compile_, methods=["POST"]),
    Route("/scenario/draft", put_draft, methods=["PUT"]),
    Route("/scenario/draft", drop_draft, methods=["DELETE"]),
    Route("/scenario/save", save, methods=["POST"]),
    Route("/scenario/live", live_start, methods=["POST"]),
    Route("/scenario/live", live_get, methods=["GET"]),
    Route("/scenario/live", live_stop, methods=["DELETE"]),
]
