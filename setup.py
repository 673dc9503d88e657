"""Build the private native host, ``retrokit.native._host``, and bundle ``games/`` and ``docs/`` into the package.

Everything else about the package is declared in ``pyproject.toml``; this file
exists because a C extension needs a setuptools ``Extension``, and because the
bundled integrations and the guides live at the top of the repository (where
integrators look for them) but must ship inside the installed package.
"""

from __future__ import annotations

import shutil
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_py import build_py

HERE = Path(__file__).resolve().parent


class BuildWithGames(build_py):
    """Copies ``games/`` (data, scenarios, states, the test cartridge) to ``retrokit/_games`` in the build,
    and the guides ``docs/*.md`` to ``retrokit/_docs`` (``retrokit docs TOPIC`` prints them)."""

    def run(self) -> None:
        super().run()
        if self.editable_mode:  # an editable install finds games/ and docs/ in the checkout itself
            return
        target = Path(self.build_lib) / "retrokit" / "_games"
        if target.exists():
            shutil.rmtree(target)
        shutil.copytree(HERE / "games", target, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
        docs = Path(self.build_lib) / "retrokit" / "_docs"
        if docs.exists():
            shutil.rmtree(docs)
        docs.mkdir(parents=True)
        for guide in sorted((HERE / "docs").glob("*.md")):  # the images stay out: a terminal cannot show them
            shutil.copy2(guide, docs / guide.name)


host = Extension(
    "retrokit.native._host",
    sources=[
        "retrokit/native/host.c",
        "retrokit/native/host_emulator.c",
        "retrokit/native/host_memory.c",
        "retrokit/native/host_functions.c",
        "retrokit/native/host_state.c",
        "retrokit/native/host_runner.c",
        "retrokit/native/core.c",
        "retrokit/native/environment.c",
        "retrokit/native/isolate.c",
        "retrokit/native/video.c",
        "retrokit/native/preprocess.c",
        "retrokit/native/runner.c",
    ],
    include_dirs=["retrokit/native"],
    extra_compile_args=["-O3", "-std=c11", "-Wall", "-Wextra", "-Wno-unused-parameter"],
    libraries=["dl", "pthread"],
)

setup(ext_modules=[host], cmdclass={"build_py": BuildWithGames})
