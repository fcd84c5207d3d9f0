"""A scene's YAML text with some values changed, by dotted key (docs/sweeps.md).

The values are written into the base scene's own text, in place: every other character stays as it was, so
the package's loader (yaml-cpp, YAML 1.2) reads the rest exactly as it reads the base file, comments and all,
and a refused value's `FILE:LINE` points at the line it replaced. A round trip through PyYAML would not:
it reads YAML 1.1 (`1e3` is a string there, `on` a boolean) and drops the comments.

A key such as `bodies.rope.stiffness` is a path of mapping keys; in a list of mappings a part names the
element by its `name` (`bodies.rope`, `colliders.ball`), and in any list an integer part is an index
(`colliders.ball.position.2`). Every part but the last must be in the base scene; the last may be absent
(a key left at its default), and is then added to its mapping.
"""
import json
import math

import yaml


class KeyPathError(ValueError):
    """A dotted key that does not lead into the scene; the message says where it stops and what is there."""


def kind(value):
    """The YAML kind of a Python value, as a sweep file states it: number, boolean, string, list, mapping, null."""
    if isinstance(value, bool):
        return "boolean"
    if isinstance(value, (int, float)):
        return "number"
    if isinstance(value, str):
        return "string"
    if isinstance(value, list):
        return "list"
    if isinstance(value, dict):
        return "mapping"
    return "null"


def node_kind(node):
    """The kind of a node of the base scene as the package's loader reads it (YAML 1.2: `1e3` is a number)."""
    if isinstance(node, yaml.SequenceNode):
        return "list"
    if isinstance(node, yaml.MappingNode):
        return "mapping"
    if node.style is not None:  # quoted or a block scalar: a string whatever it says
        return "string"
    if node.value in ("true", "false", "True", "False", "TRUE", "FALSE"):
        return "boolean"
    if node.value in ("", "~", "null", "Null", "NULL"):
        return "null"
    try:
        float(node.value)
        return "number"
    except ValueError:
        return "string"


def to_yaml(value):
    """`value` as YAML flow text that yaml-cpp reads back to the same value (a float to the same bits: repr)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        if not math.isfinite(value):
            raise ValueError(f"{value!r} is not a finite number")
        return repr(value)
    if isinstance(value, int):
        return str(value)
    if isinstance(value, str):
        return json.dumps(value)  # a double-quoted YAML scalar
    if isinstance(value, list):
        return "[" + ", ".join(to_yaml(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{json.dumps(str(k))}: {to_yaml(v)}" for k, v in value.items()) + "}"
    return "null"


class Scene:
    """A base scene's text and its YAML node tree, to find keys in and to write values into."""

    def __init__(self, text, source):
        self.text = text
        self.source = source
        self.root = yaml.compose(text)
        if not isinstance(self.root, yaml.MappingNode):
            raise KeyPathError(f"{source}: a scene file is a mapping of keys")

    def find(self, key):
        """(parent node, part, node or None) that `key` leads to; KeyPathError saying where it stops."""
        parts = key.split(".")
        node, walked = self.root, []
        for depth, part in enumerate(parts):
            last = depth == len(parts) - 1
            child = self._child(node, part, ".".join(walked) or "the scene")
            if child is None and not last:
                raise KeyPathError(f"no {part!r} in {'.'.join(walked) or 'the scene'}: every part of a key "
                                   "but the last must be in the base scene")
            if last:
                return node, part, child
            node = child
            walked.append(part)

    @staticmethod
    def _child(node, part, where):
        if isinstance(node, yaml.MappingNode):
            for key_node, value_node in node.value:
                if key_node.value == part:
                    return value_node
            return None
        if isinstance(node, yaml.SequenceNode):
            names = [name for name in (_name_of(item) for item in node.value) if name is not None]
            for item in node.value:
                if _name_of(item) == part:
                    return item
            if part.isdigit() and int(part) < len(node.value):
                return node.value[int(part)]
            known = (f"names: {', '.join(names)}" if names else f"{len(node.value)} element(s), by index")
            raise KeyPathError(f"no element {part!r} in {where} ({known})")
        raise KeyPathError(f"{where} is a {node_kind(node)}, it has no {part!r}")

    def with_values(self, values):
        """The scene's text with `values` ({dotted key: value}) written in; KeyPathError for a key that does
        not lead into the scene or one inside another's value."""
        edits = []
        for key, value in values.items():
            parent, part, node = self.find(key)
            if node is not None:
                edits.append((node.start_mark.index, node.end_mark.index, to_yaml(value), key))
            elif isinstance(parent, yaml.MappingNode):
                edits.append(_insertion(self.text, parent, part, to_yaml(value), key))
            else:
                raise KeyPathError(f"{key}: no element {part!r} in that list")
        edits.sort()
        for (start_a, end_a, _, key_a), (start_b, _, _, key_b) in zip(edits, edits[1:]):
            if start_b < end_a:
                raise KeyPathError(f"{key_b}: inside the value of {key_a}; set one of them")
        text = self.text
        for start, end, new, _ in reversed(edits):
            text = text[:start] + new + text[end:]
        return text


def _name_of(node):
    if isinstance(node, yaml.MappingNode):
        for key_node, value_node in node.value:
            if key_node.value == "name" and isinstance(value_node, yaml.ScalarNode):
                return value_node.value
    return None


def _insertion(text, mapping, key, value_text, dotted):
    """An edit that adds `key: value` to a mapping: first in a flow mapping `{...}`; in a block mapping on a
    line of its own before the first key, at that key's indentation (the lines below move down by one)."""
    if mapping.flow_style:
        at = mapping.start_mark.index + 1  # just after the "{"
        rest = text[at:mapping.end_mark.index - 1].strip()
        return (at, at, f" {key}: {value_text}" + ("," if rest else " "), dotted)
    first_key = mapping.value[0][0].start_mark
    return (first_key.index, first_key.index, f"{key}: {value_text}\n" + " " * first_key.column, dotted)
