"""The observation an agent trains on, made natively: crop, grayscale, max-pool, resize, frame stack.

RL agents train on small gray stacks of frames, which Gymnasium's wrappers make
in Python, per env and per step. ``retrokit.make(..., grayscale=True,
resize=(84, 84), frame_stack=4)`` makes the same observation in C instead,
inside the native step (``retrokit/native/preprocess.c``): on the thread that
ran the frames, with the GIL released, for one env and for every env of a
vector env alike.

The steps, in this order, each optional:

1. ``crop=(top, bottom, left, right)``: pixels cut off each edge of the screen;
2. ``grayscale``: Gymnasium's ``GrayscaleObservation`` luma, truncated to uint8;
3. ``max_pool``: the pixel-wise max of a step's last two frames (as Atari's
   ``MaxAndSkip``); with the patched core only those two are drawn. With
   ``scenario_every_frame=True`` (the Sonic preset) too: a step that the
   scenario ends early maxes the frame that ended it with the one before;
4. ``resize=(height, width)`` with ``resize_method`` ``"area"`` (OpenCV's
   INTER_AREA, what ``ResizeObservation`` uses), ``"bilinear"`` or ``"nearest"``;
5. ``frame_stack=N``: the last N frames, oldest first, along the channel axis,
   which is the last one, or the first with ``channels_first=True``.

The observation keeps a channel axis: ``(H, W, C * N)``, or ``(C * N, H, W)``
channels first, where C is 1 gray and 3 RGB. At reset, the stack is filled
with the first frame, as ``FrameStackObservation`` pads.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from gymnasium import spaces

from retrokit.errors import InvalidArgumentError

#: The options that ask for a preprocessed observation (checked in ``envs/options.py``'s table).
OBSERVATION_OPTIONS = ("grayscale", "resize", "resize_method", "crop", "frame_stack", "channels_first", "max_pool")
#: Their values when not given: the plain RGB screen.
DEFAULTS: dict[str, Any] = {
    "grayscale": False, "resize": None, "resize_method": "area", "crop": None, "frame_stack": 1,
    "channels_first": False, "max_pool": False,
}  # fmt: skip
#: The largest observation: a step writes all of it, and a vector env holds a batch of them.
MAX_OBSERVATION_BYTES = 32 << 20
#: The native method codes (``RK_RESIZE_*`` in ``native/preprocess.h``).
_METHODS = {None: 0, "area": 1, "bilinear": 2, "nearest": 3}


@dataclass(frozen=True)
class Preprocessing:
    """A checked preprocessing of a ``(height, width)`` screen.

    Attributes:
        screen: The screen's ``(height, width)``.
        crop: Pixels off the top, bottom, left and right.
        resize: The observation's ``(height, width)``, or ``None`` for the cropped size.
        method: ``"area"``, ``"bilinear"`` or ``"nearest"``.
        grayscale: One luma channel instead of RGB.
        max_pool: The max of a step's last two frames.
        frame_stack: Frames stacked.
        channels_first: The channel axis first.
    """

    screen: tuple[int, int]
    crop: tuple[int, int, int, int]
    resize: tuple[int, int] | None
    method: str
    grayscale: bool
    max_pool: bool
    frame_stack: int
    channels_first: bool

    @property
    def channels(self) -> int:
        """Channels of one frame: 1 gray, 3 RGB."""
        return 1 if self.grayscale else 3

    @property
    def frame_size(self) -> tuple[int, int]:
        """``(height, width)`` of one frame of the observation."""
        if self.resize is not None:
            return self.resize
        top, bottom, left, right = self.crop
        return self.screen[0] - top - bottom, self.screen[1] - left - right

    @property
    def shape(self) -> tuple[int, int, int]:
        """The observation's shape."""
        height, width = self.frame_size
        depth = self.channels * self.frame_stack
        return (depth, height, width) if self.channels_first else (height, width, depth)

    def space(self) -> spaces.Box:
        """The exact observation space: uint8, 0 to 255, of :attr:`shape`."""
        return spaces.Box(0, 255, self.shape, np.uint8)

    def native(self) -> tuple[int, ...]:
        """The spec the native host takes (``Emulator.set_preprocess``, ``rk_prep_spec``'s order)."""
        top, bottom, left, right = self.crop
        height, width = self.frame_size
        method = _METHODS[self.method if self.resize is not None else None]
        return (
            *self.screen, top, bottom, left, right, height, width, method, int(self.grayscale), int(self.max_pool),
            self.frame_stack, int(self.channels_first),
        )  # fmt: skip


def preprocessing(
    options: Mapping[str, Any],
    screen: tuple[int, int],
    *,
    obs_type: str,
    scenario_crop: object,
) -> Preprocessing | None:
    """The preprocessing that checked options (``envs/options.py``) ask of a screen, or ``None`` for plain RGB.

    Args:
        options: The observation options (:data:`OBSERVATION_OPTIONS`), checked one by one already.
        screen: The screen's ``(height, width)``.
        obs_type: The env's ``obs_type``; preprocessing needs ``"rgb"``.
        scenario_crop: The scenario's own ``crop``, if it has one.

    Raises:
        InvalidArgumentError: The options do not fit together or leave nothing of the screen.
    """
    given = {**DEFAULTS, **{k: v for k, v in options.items() if k in DEFAULTS}}
    if given == DEFAULTS:
        return None
    asked = ", ".join(k for k in OBSERVATION_OPTIONS if given[k] != DEFAULTS[k])
    if obs_type != "rgb":
        raise InvalidArgumentError(
            f"Expected obs_type='rgb' with {asked}, got obs_type={obs_type!r}; they preprocess the screen, not RAM."
        )
    if scenario_crop is not None:
        raise InvalidArgumentError(
            f"Expected either the scenario's crop or make()'s {asked}, got both; remove 'crop' from the scenario "
            "and pass crop=(top, bottom, left, right) to make() instead."
        )
    height, width = screen
    crop = given["crop"] or (0, 0, 0, 0)
    top, bottom, left, right = crop
    if top + bottom >= height or left + right >= width:
        raise InvalidArgumentError(
            f"Expected crop=(top, bottom, left, right) to leave part of the {height}x{width} (height x width) "
            f"screen, got {crop}; keep top + bottom below {height} and left + right below {width}."
        )
    made = Preprocessing(
        screen=(height, width), crop=crop, resize=given["resize"], method=given["resize_method"],
        grayscale=given["grayscale"], max_pool=given["max_pool"], frame_stack=given["frame_stack"],
        channels_first=given["channels_first"],
    )  # fmt: skip
    size = int(np.prod(made.shape))
    if size > MAX_OBSERVATION_BYTES:
        raise InvalidArgumentError(
            f"Expected an observation of at most {MAX_OBSERVATION_BYTES >> 20} MiB, got {made.shape} "
            f"({size / 2**20:.0f} MiB) from {asked}; resize it smaller or stack fewer frames."
        )
    return made
