"""Our libretro declarations agree with the reference libretro.h, checked by the C compiler.

retrokit declares the part of the libretro API it uses (retrokit/native/
libretro_api.h). Those constants and struct layouts are an interface with
every core, so each one is compared with Debian's retroarch-dev header.
"""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

NATIVE = Path(__file__).resolve().parent.parent / "retrokit" / "native"
REFERENCE = next(
    (p for p in (Path("/usr/include/libretro-common/libretro.h"), Path("/usr/include/libretro.h")) if p.is_file()), None
)

STRUCTS = {
    "retro_variable": ["key", "value"],
    "retro_game_info": ["path", "data", "size", "meta"],
    "retro_system_info": ["library_name", "library_version", "valid_extensions", "need_fullpath", "block_extract"],
    "retro_game_geometry": ["base_width", "base_height", "max_width", "max_height", "aspect_ratio"],
    "retro_system_timing": ["fps", "sample_rate"],
    "retro_system_av_info": ["geometry", "timing"],
    "retro_log_callback": ["log"],
    "retro_message": ["msg", "frames"],
    "retro_memory_descriptor": ["flags", "ptr", "offset", "start", "select", "disconnect", "len", "addrspace"],
    "retro_memory_map": ["descriptors", "num_descriptors"],
    "retro_core_option_value": ["value", "label"],
    "retro_core_option_definition": ["key", "desc", "info", "values", "default_value"],
    "retro_core_options_intl": ["us", "local"],
    "retro_core_option_v2_definition": [
        "key", "desc", "desc_categorized", "info", "info_categorized", "category_key", "values", "default_value",
    ],
    "retro_core_options_v2": ["categories", "definitions"],
    "retro_core_options_v2_intl": ["us", "local"],
}  # fmt: skip


def our_constants() -> dict[str, str]:
    """Map each RK_ constant of our header to the reference name it mirrors."""
    text = (NATIVE / "libretro_api.h").read_text()
    names = re.findall(r"^#define (RK_[A-Z0-9_]+) ", text, re.MULTILINE)
    mapping = {}
    for name in names:
        if name.startswith("RK_ENV_"):
            mapping[name] = "RETRO_ENVIRONMENT_" + name[len("RK_ENV_") :]
        else:
            mapping[name] = name[len("RK_") :]
    return mapping


def check_source() -> str:
    lines = ['#include <stddef.h>', f'#include "{REFERENCE}"', '#include "libretro_api.h"']
    for ours, theirs in our_constants().items():
        lines.append(f'_Static_assert({ours} == {theirs}, "{ours} differs from {theirs}");')
    for struct, fields in STRUCTS.items():
        lines.append(f'_Static_assert(sizeof(struct rk_{struct}) == sizeof(struct {struct}), "size of {struct}");')
        for f in fields:
            lines.append(
                f"_Static_assert(offsetof(struct rk_{struct}, {f}) == offsetof(struct {struct}, {f}), "
                f'"offset of {struct}.{f}");'
            )
    return "\n".join(lines) + "\n"


@pytest.mark.skipif(REFERENCE is None, reason="the reference libretro.h is not installed (apt-get install retroarch-dev)")
@pytest.mark.skipif(shutil.which("cc") is None, reason="no C compiler")
def test_declarations_match_the_reference_header(tmp_path: Path) -> None:
    source = tmp_path / "abi.c"
    source.write_text(check_source())
    result = subprocess.run(
        ["cc", "-std=c11", "-fsyntax-only", f"-I{NATIVE}", str(source)], capture_output=True, text=True, check=False
    )
    assert result.returncode == 0, result.stderr


def test_every_constant_we_declare_is_checked() -> None:
    constants = our_constants()
    assert "RK_ENV_GET_VARIABLE" in constants and constants["RK_ENV_GET_VARIABLE"] == "RETRO_ENVIRONMENT_GET_VARIABLE"
    assert len(constants) > 40
