"""Movies: ``.bk2`` recordings of episodes, read and written as stable-retro does.

A movie made by stable-retro plays in retrokit to identical frames, and one
made by retrokit plays in stable-retro. See ``docs/movies.md``.

- :class:`Movie`, :func:`read_bk2`, :func:`write_bk2`: the file format (:mod:`retrokit.movie.bk2`).
- :class:`MovieRecorder`: records an episode frame by frame.
- :func:`play`, :func:`export`: replay a movie, to screens, PNG frames, a GIF or an MP4.
"""

from __future__ import annotations

from retrokit.lazy import lazy_names
from retrokit.movie.bk2 import encode_bk2, read_bk2, write_bk2
from retrokit.movie.model import Movie, layout
from retrokit.movie.playback import export, play
from retrokit.movie.recorder import MovieRecorder

__all__ = ["Movie", "MovieRecorder", "encode_bk2", "export", "layout", "play", "read_bk2", "write_bk2"]

__getattr__ = lazy_names(__name__)  # its submodules, on first use: retrokit.movie.<module>
