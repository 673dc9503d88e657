"""Writing an animated GIF one frame at a time, with the timing the format can really hold.

Pillow's ``save_all`` keeps every frame in memory until it writes (1.26 GB for
4,000 frames); :class:`GifWriter` encodes each frame as it comes, with a
palette of its own, so memory stays flat however long the movie is.

GIF delays are whole hundredths of a second, and browsers play a delay under
2/100 s as 10/100 s. So frames are kept at :data:`MAX_GIF_FPS` at most (every
other frame of a 60 fps console), and each frame's delay is the difference of
rounded presentation times: 3, 3, 4, 3, 3, 4, ... hundredths at 30 fps, which
plays at exactly 30 fps on average instead of the 100 ms that a stored
"17 ms" (truncated to 10 ms) gives.
"""

from __future__ import annotations

import math
from typing import Any, BinaryIO

import numpy as np

MAX_GIF_FPS = 30.0
"""The highest frame rate exported to GIF: the highest below 50 (2/100 s) that divides 60 fps evenly."""


def gif_step(fps: float) -> int:
    """How many frames of a ``fps`` stream make one GIF frame, so the GIF runs at :data:`MAX_GIF_FPS` at most."""
    return max(1, math.ceil(fps / MAX_GIF_FPS - 1e-9))


def _paletted(frame: np.ndarray) -> Any:
    """``frame`` (H, W, 3) as a paletted Pillow image: exactly its colours when it has at most 256, as a console's has.

    Pillow's adaptive palette (median cut, ~5 ms a frame) is kept for frames of more colours; a frame of few
    colours gets a table of exactly its own (~1 ms), each pixel its colour's index, found by a binary search of
    the packed RGB values (Pillow's own palette mapping merges colours that differ in the low bits).
    """
    from PIL import Image

    image = Image.fromarray(frame)
    colors = image.getcolors(256)
    if colors is None:
        return image.convert("P", palette=Image.Palette.ADAPTIVE)
    table = np.sort(np.array([(r << 16) | (g << 8) | b for _, (r, g, b) in colors], dtype=np.uint32))
    rgb = frame.astype(np.uint32)
    indices = np.searchsorted(table, (rgb[..., 0] << 16) | (rgb[..., 1] << 8) | rgb[..., 2]).astype(np.uint8)
    out = Image.fromarray(indices, "P")
    out.putpalette(np.stack([table >> 16, (table >> 8) & 0xFF, table & 0xFF], axis=1).astype(np.uint8).tobytes())
    return out


class GifWriter:
    """Writes frames to an animated GIF as they come.

    Args:
        stream: A binary file to write to.
        fps: The frame rate of the frames given (already thinned by :func:`gif_step`).
        loop: How many times to play (0: forever).
    """

    def __init__(self, stream: BinaryIO, fps: float, *, loop: int = 0) -> None:
        self.stream, self.fps, self.loop = stream, float(fps), loop
        self.count = 0

    def delay_ms(self, index: int) -> int:
        """The delay of frame ``index``, in milliseconds, a whole number of hundredths of a second."""
        centiseconds = round((index + 1) * 100 / self.fps) - round(index * 100 / self.fps)
        return 10 * max(centiseconds, 2)

    def add(self, frame: np.ndarray) -> None:
        """Encode one RGB frame (H, W, 3) and write it."""
        from PIL import GifImagePlugin

        image = _paletted(frame)
        if self.count == 0:
            header, _ = GifImagePlugin.getheader(image, info={"loop": self.loop, "duration": self.delay_ms(0)})
            self.stream.write(b"".join(header))
        chunks = GifImagePlugin.getdata(image, duration=self.delay_ms(self.count), include_color_table=True)
        self.stream.write(b"".join(chunks))
        self.count += 1

    def close(self) -> None:
        """Write the GIF's trailer (the file stays open: it is the caller's)."""
        self.stream.write(b";")
