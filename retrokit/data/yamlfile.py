"""Reading YAML data files strictly: a mapping that names a key twice is an error, not a silent override.

PyYAML keeps the last of two equal keys, so a field written twice in a
``game.yaml`` silently took the later definition. :func:`load_yaml` refuses it,
naming the key and both lines.
"""

from __future__ import annotations

from typing import Any

import yaml

_Base: type = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


class DuplicateKeyError(yaml.constructor.ConstructorError):
    """A YAML mapping names the same key twice."""


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


def load_yaml(text: str) -> Any:
    """Parse YAML with the safe loader, refusing duplicate keys.

    Raises:
        yaml.YAMLError: The text is not valid YAML, or a mapping names a key twice
            (:class:`DuplicateKeyError`, with the line of the second one).
    """
    return yaml.load(text, Loader=StrictLoader)  # a SafeLoader subclass: no arbitrary objects
