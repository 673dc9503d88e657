"""What a state name may be: the one check every place that names a state goes through.

A state's name becomes a file name (``<folder>/<name>.state``), so a name that
holds a path separator, ``..`` or a control character would write outside the
game's folder, into a subfolder, or under a name no terminal shows. Every tool
that takes a state name from a user (``retrokit integrate``, ``ramsearch
savestate``, ``play``'s F5, the studio) calls :func:`check_state_name` before
it builds a path.
"""

from __future__ import annotations

import unicodedata

from retrokit.errors import InvalidArgumentError, shown

MAX_NAME_BYTES = 200
"""The longest name, in UTF-8 bytes: file systems allow 255 per name, and ``.state`` and temporary suffixes need room."""


def check_state_name(name: object, *, what: str = "state name") -> str:
    """Return ``name`` if it is a valid state name; raise otherwise.

    A state name is one plain file name: not empty, not ``.`` or ``..`` and not
    starting with a dot, with no ``/`` or ``\\``, no control character, no
    space at either end, and at most :data:`MAX_NAME_BYTES` bytes.

    Args:
        name: The name to check.
        what: What to call it in the message.

    Raises:
        InvalidArgumentError: The name is not a valid state name.
    """
    if not isinstance(name, str):
        raise InvalidArgumentError(f"Expected the {what} to be a string, got {type(name).__name__}.")
    problem = _problem(name)
    if problem:
        raise InvalidArgumentError(
            f"Expected the {what} to be a plain name such as 'Level1' or 'Zone1.Act2'; got {shown(name)}, "
            f"which {problem}. Pick a name of letters, digits, dots, dashes and underscores."
        )
    return name


def _problem(name: str) -> str:
    if not name:
        return "is empty"
    if name in (".", ".."):
        return "names a folder, not a file"
    if name.startswith("."):
        return "starts with a dot (a hidden file)"
    if "/" in name or "\\" in name:
        return "holds a path separator (a state is kept in its game's folder, not elsewhere)"
    if any(unicodedata.category(c) in ("Cc", "Cf", "Cs", "Zl", "Zp") for c in name):
        return "holds a control character or an undecodable byte"
    if name != name.strip():
        return "starts or ends with a space"
    if len(name.encode("utf-8", "surrogatepass")) > MAX_NAME_BYTES:
        return f"is longer than {MAX_NAME_BYTES} bytes"
    if name.lower().endswith(".state"):
        return "ends in .state (give the name without it)"
    return ""
