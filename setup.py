"""Build the private native host, ``retrokit.native._host``.

Everything else about the package is declared in ``pyproject.toml``; this file
exists only because a C extension needs a setuptools ``Extension``.
"""

from __future__ import annotations

from setuptools import Extension, setup

host = Extension(
    "retrokit.native._host",
    sources=[
        "retrokit/native/host.c",
        "retrokit/native/host_emulator.c",
        "retrokit/native/host_data.c",
        "retrokit/native/host_runner.c",
        "retrokit/native/host_functions.c",
        "retrokit/native/core.c",
        "retrokit/native/environment.c",
        "retrokit/native/isolate.c",
        "retrokit/native/video.c",
        "retrokit/native/fields.c",
        "retrokit/native/runner.c",
    ],
    include_dirs=["retrokit/native"],
    extra_compile_args=["-O3", "-std=c11", "-Wall", "-Wextra", "-Wno-unused-parameter"],
    libraries=["dl", "pthread"],
)

setup(ext_modules=[host])
