"""Every core the wheel ships loads in our host; every pixel format converts right."""

from __future__ import annotations

import ctypes

import native_c as native_c_module
import numpy as np
import pytest
from native_c import PIXEL_FORMATS

from retrokit.native import _host
from retrokit.paths import wheel_cores_dir

CORES = sorted(wheel_cores_dir().glob("*_libretro.so"))


@pytest.mark.parametrize("core", CORES, ids=lambda p: p.name.removesuffix("_libretro.so"))
def test_core_loads_declares_its_options_and_unloads(core, tmp_path) -> None:
    emu = _host.Emulator(str(core), str(tmp_path), str(tmp_path))
    info = emu.system_info()
    assert info["library_name"] and info["valid_extensions"]
    for key, (_, value, allowed) in emu.options().items():
        assert isinstance(value, str)  # every option always has a string value
        assert not allowed or value in allowed, key
    emu.close()


def test_two_copies_of_one_core_are_independent(tmp_path) -> None:
    core = next(p for p in CORES if p.name.startswith("gambatte"))
    probe = _host.Emulator(str(core), str(tmp_path), str(tmp_path))
    key, (_, _, allowed) = next(iter(probe.options().items()))
    probe.close()
    a = _host.Emulator(str(core), str(tmp_path), str(tmp_path), {key: allowed[-1]})
    b = _host.Emulator(str(core), str(tmp_path), str(tmp_path), {key: allowed[0]})
    assert a.options()[key][1] == allowed[-1] and b.options()[key][1] == allowed[0]
    a.close()
    b.close()


def test_an_empty_override_leaves_a_declared_option_unanswered(tmp_path) -> None:
    """A descriptor's null option: the core is told nothing, as by stable-retro's frontend (the PC Engine's turbo
    delay; that the core then keeps its own fallback shows in tests/test_pcecart.py)."""
    core = next(p for p in CORES if p.name.startswith("mednafen_pce_fast"))
    emu = _host.Emulator(str(core), str(tmp_path), str(tmp_path), {"pce_Turbo_Delay": ""})
    try:
        _, value, allowed = emu.options()["pce_Turbo_Delay"]
        assert value == "" and "Fast" in allowed
    finally:
        emu.close()


@pytest.mark.parametrize("options", [{"\udc80": "x"}, {"key": "\udc80"}], ids=["key", "value"])
def test_an_option_utf8_cannot_hold_raises_instead_of_crashing(tmp_path, options: dict[str, str]) -> None:
    with pytest.raises(UnicodeEncodeError):
        _host.Emulator(str(CORES[0]), str(tmp_path), str(tmp_path), options)


def reference(pixels: np.ndarray, fmt: int) -> np.ndarray:
    """The expected RGB of pixels, written with numpy, channels widened by shifting as stable-retro does."""
    p = pixels.astype(np.uint32)
    if fmt == PIXEL_FORMATS["XRGB8888"]:
        r, g, b = (p >> 16) & 0xFF, (p >> 8) & 0xFF, p & 0xFF
    elif fmt == PIXEL_FORMATS["RGB565"]:
        r, g, b = ((p >> 11) & 0x1F) << 3, ((p >> 5) & 0x3F) << 2, (p & 0x1F) << 3
    else:
        r, g, b = ((p >> 10) & 0x1F) << 3, ((p >> 5) & 0x1F) << 3, (p & 0x1F) << 3
    return np.stack([r, g, b], axis=-1).astype(np.uint8)


FORMATS = [
    (PIXEL_FORMATS["0RGB1555"], np.uint16),
    (PIXEL_FORMATS["XRGB8888"], np.uint32),
    (PIXEL_FORMATS["RGB565"], np.uint16),
]


@pytest.fixture(scope="module")
def native_c(tmp_path_factory):
    lib = native_c_module.build(tmp_path_factory.mktemp("native"))
    if lib is None:
        pytest.skip("no C compiler to build the native host's plain C on its own")
    return lib


@pytest.mark.parametrize("fmt,dtype", FORMATS, ids=["0rgb1555", "xrgb8888", "rgb565"])
@pytest.mark.parametrize("width", [320, 37], ids=["wide", "odd-width"])
def test_pixel_format_converts_with_row_padding(native_c, fmt: int, dtype: type, width: int) -> None:
    rng = np.random.default_rng(fmt)
    height, pad = 11, 5  # rows padded, as cores' frames are
    frame = rng.integers(0, np.iinfo(dtype).max, (height, width + pad), dtype=dtype, endpoint=True)
    out = np.zeros((height, width, 3), dtype=np.uint8)
    assert native_c.rk_frame_to_rgb(frame.ctypes.data, frame.strides[0], width, height, fmt, out.ctypes.data) == 0
    assert (out == reference(frame[:, :width], fmt)).all()


def test_unknown_pixel_format_is_refused(native_c) -> None:
    frame, out = np.zeros((4, 4), np.uint16), np.zeros((4, 4, 3), np.uint8)
    assert native_c.rk_frame_to_rgb(frame.ctypes.data, 8, 4, 4, 7, out.ctypes.data) == -1


@pytest.mark.parametrize("seed", [0, 1, 42, 2**31 + 5], ids=["zero", "default", "42", "large"])
def test_the_cores_rand_is_glibcs(native_c, seed: int) -> None:
    libc = ctypes.CDLL(None)
    libc.random.restype = ctypes.c_long
    libc.srandom(ctypes.c_uint(seed))
    expected = [libc.random() for _ in range(1000)]
    state = native_c_module.Rand()
    native_c.rk_rand_seed(ctypes.byref(state), seed)
    assert [native_c.rk_rand_next(ctypes.byref(state)) for _ in range(1000)] == expected
