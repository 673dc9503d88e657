"""The host's answer to GET_AUDIO_VIDEO_ENABLE (47), frame by frame, as any core sees it.

A probe core, compiled here from a few lines of C, asks 47 on every frame and
writes the answer into its RAM, so the tests read exactly what the host told
it: bit 0 video, bit 1 audio. It runs alone and through the native runner, as
single envs and vector envs run cores.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from retrokit.host import primitives

PROBE = r"""
#include <stdbool.h>
#include <stddef.h>
typedef bool (*env_t)(unsigned, void *);
struct sys_info { const char *name, *version, *extensions; bool need_fullpath, block_extract; };
struct av_info { unsigned base_w, base_h, max_w, max_h; float aspect; double fps, rate; };
static env_t env;
static unsigned char ram[64];
static unsigned frame;
void retro_set_environment(env_t e) { env = e; }
void retro_set_video_refresh(void *f) {}
void retro_set_audio_sample(void *f) {}
void retro_set_audio_sample_batch(void *f) {}
void retro_set_input_poll(void *f) {}
void retro_set_input_state(void *f) {}
void retro_init(void) {}
void retro_deinit(void) {}
unsigned retro_api_version(void) { return 1; }
void retro_get_system_info(struct sys_info *i) { i->name = "probe"; i->version = "1"; i->extensions = "bin"; }
void retro_get_system_av_info(struct av_info *i) { i->base_w = i->max_w = i->base_h = i->max_h = 4; i->fps = 60; }
void retro_set_controller_port_device(unsigned port, unsigned device) {}
void retro_reset(void) { frame = 0; }
void retro_run(void) {
    int av = 0xEE;
    if (!env(47 | 0x10000, &av)) av = 0xFF;  /* GET_AUDIO_VIDEO_ENABLE */
    ram[frame++ % sizeof ram] = (unsigned char)av;
}
size_t retro_serialize_size(void) { return 0; }
bool retro_serialize(void *data, size_t size) { return false; }
bool retro_unserialize(const void *data, size_t size) { return false; }
bool retro_load_game(const void *game) { return true; }
void retro_unload_game(void) {}
void *retro_get_memory_data(unsigned id) { return id == 2 ? ram : NULL; }
size_t retro_get_memory_size(unsigned id) { return id == 2 ? sizeof ram : 0; }
"""

VIDEO, AUDIO = 1, 2
MODES = {"all": primitives.VIDEO_ALL, "last": primitives.VIDEO_LAST, "none": primitives.VIDEO_NONE}


@pytest.fixture(scope="module")
def probe_core(tmp_path_factory: pytest.TempPathFactory) -> Path:
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        pytest.skip("no C compiler (cc) to build the probe core")
    folder = tmp_path_factory.mktemp("probe")
    (folder / "probe.c").write_text(PROBE)
    library = folder / "probe_libretro.so"
    subprocess.run([cc, "-shared", "-fPIC", "-O1", str(folder / "probe.c"), "-o", str(library)], check=True)
    return library


def open_probe(core: Path, tmp_path: Path):
    emu = primitives.NativeEmulator(str(core), str(tmp_path), str(tmp_path))
    emu.load_game(str(tmp_path / "game.bin"), b"\0")
    return emu


def answers(emu, frames: int) -> list[int]:
    """The answers to 47 of the last ``frames`` frames run since the reset."""
    ram = np.frombuffer(emu.memory(primitives.MEMORY_SYSTEM_RAM), dtype=np.uint8)
    return [int(v) for v in ram[:frames]]


@pytest.mark.parametrize(
    "mode, capture, expected",
    [
        ("all", False, [VIDEO | AUDIO] * 4),  # the default: as before skipping existed
        ("all", True, [VIDEO | AUDIO] * 4),
        ("last", False, [0, 0, 0, VIDEO]),
        ("last", True, [AUDIO, AUDIO, AUDIO, VIDEO | AUDIO]),
        ("none", False, [0, 0, 0, 0]),
        ("none", True, [AUDIO] * 4),
    ],
    ids=["all", "all-capturing", "last", "last-capturing", "none", "none-capturing"],
)
def test_each_frame_of_a_run_is_answered_by_the_mode(probe_core, tmp_path, mode, capture, expected) -> None:
    emu = open_probe(probe_core, tmp_path)
    emu.set_video_frames(MODES[mode])
    emu.capture_audio(capture)
    emu.run(np.zeros(2, np.uint16), 4)
    assert answers(emu, 4) == expected
    assert emu.av_asked == 4
    emu.close()


def test_a_new_emulator_reports_everything_wanted_and_runs_of_one_frame_draw_it(probe_core, tmp_path) -> None:
    emu = open_probe(probe_core, tmp_path)
    emu.run(np.zeros(2, np.uint16), 1)
    emu.set_video_frames(primitives.VIDEO_LAST)
    emu.run(np.zeros(2, np.uint16), 1)
    emu.run(np.zeros(2, np.uint16), 2)
    assert answers(emu, 4) == [VIDEO | AUDIO, VIDEO, 0, VIDEO]
    emu.close()


def test_the_runner_answers_as_a_single_run_does(probe_core, tmp_path) -> None:
    emus = [open_probe(probe_core, tmp_path) for _ in range(3)]
    for emu, mode in zip(emus, ("all", "last", "none")):
        emu.set_video_frames(MODES[mode])
    runner = primitives.NativeRunner(1)
    runner.run(emus, np.zeros((3, 2), np.uint16), 3)
    assert [answers(emu, 3) for emu in emus] == [[3, 3, 3], [0, 0, VIDEO], [0, 0, 0]]
    for emu in emus:
        emu.close()


@pytest.mark.parametrize("mode", [-1, 3, 2**40], ids=["negative", "unknown", "huge"])
def test_unknown_modes_are_refused(probe_core, tmp_path, mode: int) -> None:
    from retrokit.errors import InvalidArgumentError

    emu = open_probe(probe_core, tmp_path)
    with pytest.raises((InvalidArgumentError, OverflowError)):
        emu.set_video_frames(mode)
    emu.close()
