"""States and movies: list, load, save the moment as a state, set the default; record and replay ``.bk2`` movies.

Each route is a thin layer over the :class:`~retrokit.ramsearch.RamSearch`
the session plays: states are loaded through the one checked path
(``RamSearch.load_state``) and saved with ``RamSearch.save_state``, the same
record ``retrokit integrate`` writes; a movie records the inputs played since
recording began (``RamSearch.restart_inputs`` and ``write_movie``) and is
replayed through ``RamSearch.play``, whose start state ``movie.playback.replay``
checks. A request names a movie by a file name that :func:`movie_path`
resolves through :func:`~retrokit.studio.security.resolve_path`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from starlette.requests import Request
from starlette.responses import JSONResponse, Response
from starlette.routing import Route

from retrokit import paths
from retrokit.data.names import check_state_name
from retrokit.errors import InvalidArgumentError, UnknownNameError, did_you_mean
from retrokit.studio.security import check_inside, expect, game_roots, json_body, resolve_path, session_of
from retrokit.studio.session import Session

MOVIES = "movies"
"""The folder of a game's movies, in each of its folders (``retrokit play`` and ``validate`` use it too)."""
SUFFIX = ".bk2"


def roots(session: Session) -> list[Path]:
    """The folders a request may reach: the game's folders, where its states go, and the data folder."""
    return game_roots(session.search.game)


def movie_path(session: Session, name: object, *, new: bool = False) -> Path:
    """The movie file a request names: ``NAME`` or ``NAME.bk2`` in a movies folder of the game.

    An existing movie is looked up in every folder of the game; a new one (``new``) goes to
    the ``movies`` folder where the game's made states go.

    Raises:
        AccessDeniedError: The name leads outside the game's folders and the data folder.
        UnknownNameError: No movie of that name (with a did-you-mean).
    """
    from retrokit.data.integrate import target_folder

    if not isinstance(name, str):
        raise InvalidArgumentError(f"Expected a movie name as a string, got {type(name).__name__}.")
    file = name if name.endswith(SUFFIX) else name + SUFFIX
    if new:
        check_state_name(file, what="movie name")
        return resolve_path(file, target_folder(session.search.game) / MOVIES, roots(session), what="movie")
    for folder in _movie_folders(session):
        path = resolve_path(file, folder, roots(session), what="movie")
        if path.exists():
            return path
    known = [m["name"] for m in list_movies(session)]
    raise UnknownNameError(
        f"Expected a movie of {session.search.game.name}: one of {', '.join(known) or '(none yet)'}; "
        f"got {name!r}." + did_you_mean(name.removesuffix(SUFFIX), known)
    )


def _movie_folders(session: Session) -> list[Path]:
    from retrokit.data.integrate import target_folder

    game = session.search.game
    folders = [f / MOVIES for f in (*game.folders, target_folder(game))]
    return list(dict.fromkeys(folders))


def list_movies(session: Session) -> list[dict[str, Any]]:
    """The game's movies: ``{"name", "path", "bytes"}`` for each ``movies/*.bk2`` of its folders."""
    found: dict[str, dict[str, Any]] = {}
    for folder in _movie_folders(session):
        if folder.is_dir():
            for path in sorted(folder.glob(f"*{SUFFIX}")):
                if path.is_file():
                    found.setdefault(path.stem, {"name": path.stem, "path": str(path), "bytes": path.stat().st_size})
    return list(found.values())


def list_states(session: Session) -> dict[str, Any]:
    """The game's states and its default."""
    game = session.search.game
    return {"states": game.states, "default": game.default_state, "current": session.search.state}


# --- on the emulator thread ---------------------------------------------------------------------------


def _save(session: Session, name: str, default: bool, force: bool) -> dict[str, Any]:
    outcome = session.search.save_state(name, default=default, force=force)
    session.refresh_game()
    return {"name": outcome.name, "status": outcome.status, "path": str(outcome.path), **list_states(session)}


def _set_default(session: Session, name: str) -> dict[str, Any]:
    check_inside(session.search.default_game_file(), roots(session), what="game.yaml")  # not a planted link
    written = session.search.set_default_state(name)
    session.refresh_game()
    return {"game_file": str(written), **list_states(session)}


def _record(session: Session) -> dict[str, Any]:
    session.search.restart_inputs()
    session.recording = True
    session.publish(session.status())
    return {"recording": True, "frame": session.frame}


def _stop(session: Session, path: Path, force: bool) -> dict[str, Any]:
    if not session.recording:
        raise InvalidArgumentError(
            "Expected a recording to stop; none is under way. Start one with POST /api/movies/record first."
        )
    paths.ensure_folder(path.parent, "written with movies")
    written = session.search.write_movie(path, overwrite=force)
    frames = len(session.search.movie().frames)
    session.recording = False
    session.publish(session.status())
    return {"path": str(written), "frames": frames, "movies": list_movies(session)}


def _replay(session: Session, path: Path) -> dict[str, Any]:
    search = session.search
    movie, frames = search.replaying(path)  # checks the game, then plays one frame each time it is advanced
    next(frames)  # the console at the movie's start, its state checked: a bad one fails this request

    def next_frame(session: Session) -> bool:
        if session.search is not search:  # the game was switched meanwhile
            return False
        return next(frames, None) is not None

    session.recording = False
    session.mark_loaded()
    session.play_frames(next_frame)
    session.paused = False
    session.send_screen()
    session.publish(session.status())
    return {"path": str(path), "frames": len(movie.frames)}


def _load(session: Session, name: str) -> dict[str, Any]:
    from retrokit.studio.play import reset

    reset(session, name)
    return list_states(session)


# --- routes ---------------------------------------------------------------------------------------------


async def states_route(request: Request) -> Response:
    """``GET /api/states``."""
    return JSONResponse(await session_of(request).call(list_states))


async def load_route(request: Request) -> Response:
    """``POST /api/states/load`` ``{"name"}``."""
    body = await json_body(request)
    name = check_state_name(expect(body, "name", str))
    return JSONResponse(await session_of(request).call(_load, name))


async def save_route(request: Request) -> Response:
    """``POST /api/states/save`` ``{"name", "default": false, "force": false}``."""
    body = await json_body(request)
    name = check_state_name(expect(body, "name", str))
    default, force = expect(body, "default", bool, False), expect(body, "force", bool, False)
    return JSONResponse(await session_of(request).call(_save, name, default, force))


async def default_route(request: Request) -> Response:
    """``POST /api/states/default`` ``{"name"}``."""
    body = await json_body(request)
    name = check_state_name(expect(body, "name", str))
    return JSONResponse(await session_of(request).call(_set_default, name))


async def movies_route(request: Request) -> Response:
    """``GET /api/movies``."""
    session = session_of(request)
    return JSONResponse({"movies": await session.call(list_movies), "recording": session.recording})


async def record_route(request: Request) -> Response:
    """``POST /api/movies/record``: record from this moment."""
    await json_body(request)
    return JSONResponse(await session_of(request).call(_record))


async def stop_route(request: Request) -> Response:
    """``POST /api/movies/stop`` ``{"name", "force": false}``: write what was recorded."""
    body = await json_body(request)
    session = session_of(request)
    path = movie_path(session, expect(body, "name", str), new=True)
    return JSONResponse(await session.call(_stop, path, expect(body, "force", bool, False)))


async def replay_route(request: Request) -> Response:
    """``POST /api/movies/play`` ``{"name"}``: replay a movie on the screen, from its start state."""
    body = await json_body(request)
    session = session_of(request)
    path = movie_path(session, expect(body, "name", str))
    return JSONResponse(await session.call(_replay, path))


routes = [
    Route("/states", states_route),
    Route("/states/load", load_route, methods=["POST"]),
    Route("/states/save", save_route, methods=["POST"]),
    Route("/states/default", default_route, methods=["POST"]),
    Route("/movies", movies_route),
    Route("/movies/record", record_route, methods=["POST"]),
    Route("/movies/stop", stop_route, methods=["POST"]),
    Route("/movies/play", replay_route, methods=["POST"]),
]
