"""Reading retrokit's YAML files: guarded, bounded, and strict about duplicate keys.

Every retrokit YAML file (``game.yaml``, scenarios, benchmark files) is read
here, so the same limits hold for each:

- the file is read by :func:`retrokit.paths.read_regular_file`: a FIFO, a
  device or a symlink loop is an error, and so is a file over
  :data:`MAX_YAML_BYTES`;
- the document is composed into nodes, and its values are counted with
  aliases followed before anything expands them: a YAML "alias bomb" of a few
  hundred bytes stands for billions of values, and any walk over the loaded
  data (a schema check, a copy) would never end. Aliases that add more than
  :data:`MAX_VALUES` values are :class:`TooManyValuesError`;
- collections nested so deep that the parser recurses past Python's limit
  are a :class:`yaml.YAMLError` too, never a raw ``RecursionError``;
- :func:`load_yaml` refuses a mapping that names a key twice (PyYAML keeps the
  last of two equal keys, so a field written twice silently took the later
  definition).
"""

from __future__ import annotations

import copy
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import yaml

from retrokit.data.textmemo import TextMemo
from retrokit.paths import read_regular_file

_Base: type = getattr(yaml, "CSafeLoader", yaml.SafeLoader)

#: The most values aliases may add to a YAML file once expanded (the file's size bounds the values written out).
MAX_VALUES = 100_000
#: The largest YAML file read: the shipped ones are a few kilobytes, and YAML takes tens of times a file's size.
MAX_YAML_BYTES = 4 * 2**20


class DuplicateKeyError(yaml.constructor.ConstructorError):
    """A YAML mapping names the same key twice."""


class TooManyValuesError(yaml.MarkedYAMLError):
    """A YAML document holds more than :data:`MAX_VALUES` values once its aliases are expanded."""


class StrictLoader(_Base):  # type: ignore[misc, valid-type]
    """PyYAML's safe loader (the C one where available), refusing duplicate mapping keys."""

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        seen: dict[Any, yaml.Node] = {}
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=True)
            try:
                first = seen.get(key)
            except TypeError:  # an unhashable key: the base class reports it
                continue
            if first is not None:
                raise DuplicateKeyError(
                    "while reading a mapping", node.start_mark,
                    f"found the key {key!r} twice (first on line {first.start_mark.line + 1})", key_node.start_mark,
                )
            seen[key] = key_node
        return super().construct_mapping(node, deep=deep)


StrictLoader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, StrictLoader.construct_mapping)


def read_yaml_text(path: Path | str, what: str) -> str:
    """Read a YAML file's text through the guarded reader (a leading byte-order mark is dropped).

    Args:
        path: The file.
        what: What it should be, for errors (``"a game.yaml data file"``).

    Raises:
        FileSystemError: The file is missing, not a regular file, or larger than :data:`MAX_YAML_BYTES`.
        UnicodeDecodeError: It is not UTF-8.
    """
    return read_regular_file(path, what, MAX_YAML_BYTES).decode("utf-8-sig")


def _distinct_nodes(root: yaml.Node) -> int:
    """How many nodes the document holds as written: each alias's target counted once."""
    seen = {id(root)}
    stack = [root]
    while stack:
        node = stack.pop()
        children = (
            node.value if isinstance(node, yaml.SequenceNode)
            else [part for pair in node.value for part in pair] if isinstance(node, yaml.MappingNode)
            else ()
        )
        for child in children:
            if id(child) not in seen:
                seen.add(id(child))
                stack.append(child)
    return len(seen)


def iter_nodes(root: yaml.Node) -> Iterator[yaml.Node]:
    """Yield every node under ``root`` (itself included), aliases followed, as many times as they are used.

    A file's own size bounds its values; aliases may add at most :data:`MAX_VALUES` to them.

    Raises:
        TooManyValuesError: The aliases expand to more; raised before they are all walked.
    """
    limit = _distinct_nodes(root) + MAX_VALUES
    stack = [root]
    count = 0
    while stack:
        node = stack.pop()
        count += 1
        if count > limit:
            raise TooManyValuesError(
                problem=f"expected aliases (*name) to add at most {MAX_VALUES} YAML values once expanded; found "
                "more. Write out what the aliases repeat, or drop them",
                problem_mark=root.start_mark,
            )
        yield node
        if isinstance(node, yaml.SequenceNode):
            stack.extend(node.value)
        elif isinstance(node, yaml.MappingNode):
            stack.extend(part for pair in node.value for part in pair)


def compose_yaml(text: str, loader: type = _Base) -> yaml.Node | None:
    """Compose YAML ``text`` into its root node, with its values counted (see :func:`iter_nodes`).

    Raises:
        yaml.YAMLError: The text is not valid YAML, is nested too deep, or holds
            too many values (:class:`TooManyValuesError`).
    """
    try:
        root = yaml.compose(text, Loader=loader)
    except RecursionError:  # collections nested thousands deep
        raise yaml.YAMLError("expected YAML collections nested at most a few hundred deep; found deeper ones") from None
    if root is not None:
        for _ in iter_nodes(root):
            pass
    return root


def load_yaml(text: str) -> Any:
    """Parse YAML with the safe loader, refusing duplicate keys and alias bombs.

    Raises:
        yaml.YAMLError: The text is not valid YAML, a mapping names a key twice
            (:class:`DuplicateKeyError`, with the line of the second one), or it
            holds too many values (:class:`TooManyValuesError`).
    """
    # Every make() reads its game.yaml again (an edit must show): a text parsed before is known by its digest, and
    # each caller gets its own copy to change.
    return copy.deepcopy(_PARSED.get(text, None, lambda: _parse(text)))


_PARSED: TextMemo[Any] = TextMemo()
""":func:`load_yaml`'s documents by their text."""


def _parse(text: str) -> Any:
    root = compose_yaml(text, StrictLoader)
    if root is None:
        return None
    loader = StrictLoader("")  # a SafeLoader subclass: no arbitrary objects
    try:
        return loader.construct_document(root)
    except RecursionError:
        raise yaml.YAMLError("expected YAML collections nested at most a few hundred deep; found deeper ones") from None
    finally:
        loader.dispose()
