"""Play: the game's buttons and default keys, pause, frame advance, speed and reset, over HTTP and the socket.

The socket's commands (``{"type": "buttons", "buttons": [...]}``, ``pause``,
``resume``, ``step``, ``speed``, ``reset``) and the HTTP routes under
``/api`` run the same functions, so a script can do what the page does.
"""

from __future__ import annotations

import io
from typing import Any

from starlette.requests import Request
from starlette.responses import JSONResponse, Response
from starlette.routing import Route

from retrokit.data.names import check_state_name
from retrokit.errors import InvalidArgumentError, UnknownNameError, did_you_mean, shown
from retrokit.host.systems import System
from retrokit.ramsearch.ram import RamLayout
from retrokit.studio.security import check_inside, expect, game_roots, json_body, session_of
from retrokit.studio.session import MAX_SPEED, MIN_SPEED, Session

MAX_STEP = 3600
"""The most frames one frame-advance runs (a minute of play)."""

RAM_SHOWN = 256
"""The bytes the RAM view and click-to-find show at first (all of an Atari 2600's 128)."""

# KeyboardEvent.code of each button where the system has it: the D-pad on the arrows; Enter is the system's
# start button (START, the PC Engine's RUN, the 2600's RESET switch: `start:` in systems.yaml).
_KEYS = {"UP": "ArrowUp", "DOWN": "ArrowDown", "LEFT": "ArrowLeft", "RIGHT": "ArrowRight"}
_SELECT_KEYS = ("ShiftRight", "Backspace")  # SELECT, then MODE (Genesis) when both exist
_FACE_ORDER = ("A", "B", "C", "X", "Y", "Z", "L", "R", "L2", "R2", "L3", "R3")
_FACE_KEYS = ("KeyZ", "KeyX", "KeyC", "KeyA", "KeyS", "KeyD", "KeyQ", "KeyW", "KeyE", "KeyR", "KeyT", "KeyY")
# The standard Gamepad API layout's button indices.
_PAD = {"UP": 12, "DOWN": 13, "LEFT": 14, "RIGHT": 15, "START": 9, "SELECT": 8, "MODE": 8}
_PAD_FACE = (0, 1, 2, 3, 4, 5, 6, 7, 10, 11)


def key_map(system: System) -> dict[str, str]:
    """The default keyboard map of a system: ``{KeyboardEvent.code: button}`` (arrows: D-pad, Enter: its start button)."""
    names = system.button_names
    keys = {key: button for button, key in _KEYS.items() if button in names}
    keys["Enter"] = system.start
    others = [b for b in ("SELECT", "MODE") if b in names and b != system.start]
    keys.update(zip(_SELECT_KEYS, others, strict=False))
    face = [b for b in _FACE_ORDER if b in names]
    face += [b for b in names if b not in face and b not in keys.values() and b not in others]
    keys.update(zip(_FACE_KEYS, face, strict=False))
    return keys


def pad_map(system: System) -> dict[str, str]:
    """The default Gamepad API map: ``{standard button index: button}``."""
    names = system.button_names
    pad = {str(index): button for button, index in _PAD.items() if button in names}
    pad[str(_PAD["START"])] = system.start
    face = [b for b in _FACE_ORDER if b in names]
    pad.update((str(i), b) for i, b in zip(_PAD_FACE, face, strict=False))
    return pad


def ram_region(layout: RamLayout, system: System) -> dict[str, int]:
    """Where the RAM view and click-to-find start: the system RAM's region (at the descriptor's base; a Game Boy's
    core maps HRAM and VRAM too), its first :data:`RAM_SHOWN` bytes; and the hex digits the page writes an address
    with, the CLI's and game.yaml's (``0x0300`` on a NES, ``0xFF0000`` on a Genesis), not one width for all."""
    regions = sorted(layout.regions, key=lambda region: region[0] != system.ram_base)  # that region first
    start, size = regions[0] if regions else (system.ram_base, 0)
    return {"start": start, "length": min(RAM_SHOWN, size), "digits": layout.digits}


def info(session: Session) -> dict[str, Any]:
    """What the page needs to draw itself: the game, its buttons and keys, its states, the screen's size."""
    search = session.search
    game = search.game
    height, width = search.emulator.screen_shape()
    return {
        "game": game.name,
        "system": game.system.name,
        "buttons": list(game.system.button_names),
        "ports": search.emulator.ports,
        "keys": key_map(game.system),
        "ram": ram_region(search.layout, game.system),
        "gamepad": pad_map(game.system),
        "frame_rate": session.rate,
        "speeds": [MIN_SPEED, MAX_SPEED],
        "width": width,
        "height": height,
        "states": game.states,
        "default_state": game.default_state,
        "status": session.status(),
    }


# --- the commands ---------------------------------------------------------------------------------------


def _step(session: Session, frames: int) -> None:
    session.paused = True
    session.advance(frames)


def _pause(session: Session, paused: bool) -> None:
    session.set_paused(paused)


def _speed(session: Session, value: float) -> None:
    session.set_speed(value)
    session.publish(session.status())


def reset(session: Session, state: str | None) -> None:
    """Load ``state`` (the state the session began from, by default), through the one checked path."""
    search = session.search
    name = state if state is not None else search.state
    session.play_frames(None)
    if name is None:  # a game without states (a new one): power-on
        search.emulator.reset()
        search.restart_inputs()  # a movie recorded from here starts here
    else:
        path = search.game.state_path(name)  # StateNotFoundError, with a did-you-mean, for an unknown one
        check_inside(path, game_roots(search.game), what="state")
        search.load_state(name)
        search.state = name
    session.mark_loaded()
    session.send_screen()
    session.publish(session.status())


def _frames(message: dict[str, Any]) -> int:
    frames = expect(message, "frames", int, 1)
    if not 1 <= frames <= MAX_STEP:
        raise InvalidArgumentError(f"Expected 'frames' from 1 to {MAX_STEP}, got {frames}.")
    return frames


async def handle_message(session: Session, message: object) -> dict[str, Any] | None:
    """Run one command of the socket (or of the HTTP routes); return a reply to send, if any.

    Raises:
        InvalidArgumentError: The message is not a known command with arguments of the right types.
        UnknownNameError: A button or a state is unknown.
    """
    if not isinstance(message, dict):
        raise InvalidArgumentError(f'Expected a JSON object {{"type": ...}}; got {shown(message)}.')
    kind = expect(message, "type", str)
    if kind == "buttons":
        session.set_buttons(expect(message, "buttons", list))
    elif kind in ("pause", "resume"):
        await session.call(_pause, kind == "pause")
    elif kind == "step":
        await session.call(_step, _frames(message))
    elif kind == "speed":
        await session.call(_speed, expect(message, "value", (int, float)))
    elif kind == "reset":
        state = expect(message, "state", str, None)
        if state is not None:
            check_state_name(state)
        await session.call(reset, state)
    elif kind == "status":
        return session.status()
    else:
        raise UnknownNameError(
            f"Expected a command: one of {', '.join(COMMANDS)}; got {kind!r}." + did_you_mean(kind, COMMANDS)
        )
    return None


COMMANDS = ("buttons", "pause", "resume", "step", "speed", "reset", "status")


# --- routes ---------------------------------------------------------------------------------------------


async def info_route(request: Request) -> Response:
    """``GET /api/info``."""
    session = session_of(request)
    return JSONResponse(await session.call(info))


async def status_route(request: Request) -> Response:
    """``GET /api/status``."""
    return JSONResponse(session_of(request).status())


async def command_route(request: Request) -> Response:
    """``POST /api/play/{command}``: a socket command by HTTP; the body holds its arguments."""
    session = session_of(request)
    body = await json_body(request)
    await handle_message(session, {**body, "type": request.path_params["command"]})
    return JSONResponse(session.status())


def _png(session: Session) -> bytes:
    from PIL import Image

    buffer = io.BytesIO()
    Image.fromarray(session.screen()).save(buffer, format="PNG")
    return buffer.getvalue()


async def screen_route(request: Request) -> Response:
    """``GET /api/screen.png``: the screen now."""
    return Response(await session_of(request).call(_png), media_type="image/png")


routes = [
    Route("/info", info_route),
    Route("/status", status_route),
    Route("/screen.png", screen_route),
    Route("/play/{command}", command_route, methods=["POST"]),
]
