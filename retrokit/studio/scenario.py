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
every few frames (the samples overlap: the page keeps each frame once), and
``GET /api/scenario/live`` returns the last :data:`HISTORY` frames.

Routes (under ``/api``): ``GET /scenario?name=``, ``POST /scenario/compile``
``{"text", "name"?}``, ``PUT /scenario/draft`` ``{"text", "name"?}``, ``DELETE
/scenario/draft?name=``, ``POST /scenario/save`` ``{"text", "name"?}``, ``POST
/scenario/live`` ``{"name"?, "text"?}``, ``GET /scenario/live``, ``DELETE /scenario/live``.
"""

from __future__ import annotations

import collections
import weakref
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from starlette.requests import Request
from starlette.responses import JSONResponse
from starlette.routing import Route

from retrokit import paths
from retrokit.data.names import check_state_name
from retrokit.dsl.scenario import Run, Scenario, scenario_from_text
from retrokit.dsl.source import read_source
from retrokit.errors import DataFileError, InvalidArgumentError, ScenarioError, ScenarioRuntimeError, shown
from retrokit.studio.app import session_of
from retrokit.studio.fields import field_reader
from retrokit.studio.search import PUSH_EVERY
from retrokit.studio.security import expect, json_body

HISTORY = 600
"""Frames of reward kept for the plot: 10 seconds at 60 fps."""
_OVERLAP = 4 * PUSH_EVERY  # samples per push: a push the page missed is covered by the next


def _name(value: object, game: Any) -> str:
    """The scenario's name: given, or the game's default (``scenario``)."""
    if value is None or value == "":
        return game.default_scenario or "scenario"
    return check_state_name(value, what="scenario name")


def _target(search: Any, name: str) -> Path:
    """Where scenario ``name`` is saved: beside the game's own game.yaml (never inside an installed package)."""
    return search.default_game_file().parent / f"{name}.yaml"


def draft_path(game: str, name: str) -> Path:
    """The draft of a game's scenario in the data folder."""
    return paths.data_dir() / "studio" / "drafts" / game / f"{name}.yaml"


def _read_text(path: Path) -> str:
    return read_source(path).text


def compile_text(search: Any, name: str, text: object) -> Scenario:
    """Compile ``text`` as scenario ``name`` of the game, its errors located in the file it is saved to.

    Raises:
        ScenarioError: It does not compile (with ``line`` and ``column`` where the language gives them).
    """
    if not isinstance(text, str):
        raise InvalidArgumentError(f"Expected the scenario's text as a string; got {shown(text)}.")
    game = search.game
    try:
        source = str(_target(search, name))
    except DataFileError:  # a game the studio cannot write to still compiles, under its own file's name
        source = str(game.scenarios.get(name, f"{name}.yaml"))
    return scenario_from_text(text, list(game.fields), source=source, name=name, game_dir=game.folders[0])


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
    countdown: int = 0
    remove: Any = None

    def restart(self, session: Any) -> None:
        """A new episode from the game's moment now."""
        self.search, self.start_state = session.search, session.search.start_state
        self.run = self.scenario.start()
        self.run.reset(field_reader(session).read())
        self.episode_frame, self.total, self.done, self.error = 0, 0.0, False, None

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


_live: weakref.WeakKeyDictionary[Any, _Live] = weakref.WeakKeyDictionary()


def _on_frame(session: Any) -> None:
    """Frame hook: step the live scenario on this frame's fields, and push the reward every few frames."""
    live = _live.get(session)
    if live is None or live.error is not None:
        return
    if live.search is not session.search or live.start_state is not session.search.start_state:
        live.restart(session)  # a state was loaded (or another game): a new episode
    if not live.done:
        live.episode_frame += 1
        try:
            rewards, done = live.run.step(field_reader(session).read(), live.episode_frame, live.episode_frame)
        except ScenarioRuntimeError as exc:  # the scenario's fault, told to the page; the game goes on
            live.error = error_json(exc)
            session.publish(live.report(_OVERLAP))
            return
        reward = float(sum(rewards))
        live.total += reward
        live.done = bool(done)
        live.samples.append([session.frame, reward, live.total, live.done])
    live.countdown -= 1
    if live.countdown <= 0:
        live.countdown = PUSH_EVERY
        session.publish(live.report(_OVERLAP))


def _go_live(session: Any, name: object, text: object) -> dict[str, Any]:
    search = session.search
    name = _name(name, search.game)
    if text is None:
        path = search.game.scenario_path(name)
        if path.suffix.lower() != ".yaml":
            from retrokit.dsl.scenario import load_scenario

            scenario = load_scenario(path, list(search.game.fields), game_dir=path.parent, name=name)
        else:
            scenario = compile_text(search, name, _read_text(path))
    else:
        scenario = compile_text(search, name, text)
    old = _live.get(session)
    live = _Live(name, scenario, remove=old.remove if old is not None else None)
    live.restart(session)
    _live[session] = live
    if live.remove is None:
        live.remove = session.on_frame(_on_frame)
    return live.report()


def _stop(session: Any) -> dict[str, Any]:
    live = _live.pop(session, None)
    if live is not None and live.remove is not None:
        live.remove()
    return {"live": False}


def _live_report(session: Any) -> dict[str, Any]:
    live = _live.get(session)
    return {"live": False} if live is None else {"live": True, **live.report()}


# --- the text, drafts and saving -------------------------------------------------------------------


def _get(session: Any, name: object) -> dict[str, Any]:
    search = session.search
    game = search.game
    name = _name(name, game)
    path = game.scenarios.get(name)
    text = _read_text(path) if path is not None else ""
    draft = draft_path(game.name, name)
    kept = _read_text(draft) if draft.is_file() else None
    try:
        target, writable = str(_target(search, name)), True
    except DataFileError as exc:  # a shipped game: shown, not saved
        target, writable = str(exc), False
    return {
        "name": name,
        "names": list(game.scenarios),
        "path": str(path) if path is not None else None,
        "text": text,
        "draft": kept if kept != text else None,
        "save_to": target if writable else None,
        "writable": writable,
        "why_not": None if writable else target,
    }


def _compile(session: Any, name: object, text: object) -> dict[str, Any]:
    name = _name(name, session.search.game)
    try:
        scenario = compile_text(session.search, name, text)
    except ScenarioError as exc:
        return {"ok": False, **error_json(exc)}
    return {"ok": True, "name": name, "players": scenario.players, "fields": list(scenario.fields)}


def _put_draft(session: Any, name: object, text: object) -> dict[str, Any]:
    name = _name(name, session.search.game)
    if not isinstance(text, str):
        raise InvalidArgumentError(f"Expected the scenario's text as a string; got {shown(text)}.")
    path = draft_path(session.search.game.name, name)
    paths.ensure_folder(path.parent, "the studio's scenario drafts")
    paths.atomic_write(path, text.encode("utf-8"), overwrite=True)  # the studio's own file, replaced at each edit
    return {"draft": str(path), **_compile(session, name, text)}


def _drop_draft(session: Any, name: object) -> dict[str, Any]:
    name = _name(name, session.search.game)
    path = draft_path(session.search.game.name, name)
    path.unlink(missing_ok=True)
    return {"draft": None, "name": name}


def _save(session: Any, name: object, text: object) -> dict[str, Any]:
    search = session.search
    name = _name(name, search.game)
    scenario = compile_text(search, name, text)  # raises where it does not compile: nothing written
    target = _target(search, name)
    paths.atomic_write(target, text.encode("utf-8"), overwrite=True)  # the user asked to save over it
    draft_path(search.game.name, name).unlink(missing_ok=True)
    search.reload_game()  # its scenarios are listed afresh (a new name is one now)
    live = _live.get(session)
    if live is not None and live.name == name:
        _go_live(session, name, None)
    return {"saved": str(target), "name": name, "players": scenario.players}


async def get(request: Request) -> JSONResponse:
    return JSONResponse(await session_of(request).call(_get, request.query_params.get("name")))


async def compile_(request: Request) -> JSONResponse:
    body = await json_body(request)
    text, name = expect(body, "text", str), expect(body, "name", str, None)
    return JSONResponse(await session_of(request).call(_compile, name, text))


async def put_draft(request: Request) -> JSONResponse:
    body = await json_body(request)
    text, name = expect(body, "text", str), expect(body, "name", str, None)
    return JSONResponse(await session_of(request).call(_put_draft, name, text))


async def drop_draft(request: Request) -> JSONResponse:
    return JSONResponse(await session_of(request).call(_drop_draft, request.query_params.get("name")))


async def save(request: Request) -> JSONResponse:
    body = await json_body(request)
    text, name = expect(body, "text", str), expect(body, "name", str, None)
    try:
        return JSONResponse(await session_of(request).call(_save, name, text))
    except ScenarioError as exc:
        return JSONResponse(error_json(exc), status_code=400)


async def live_start(request: Request) -> JSONResponse:
    body = await json_body(request)
    text, name = expect(body, "text", str, None), expect(body, "name", str, None)
    try:
        return JSONResponse(await session_of(request).call(_go_live, name, text))
    except ScenarioError as exc:
        return JSONResponse(error_json(exc), status_code=400)


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
