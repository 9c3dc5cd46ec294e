"""A Config's options checked against their annotations, and a new registry entry checked: what
both registries (the swarms' and the multi-agent planners') do with the options a user passes
before building a Config, and with an entry a user registers."""
from __future__ import annotations

import dataclasses
import numbers
import types
import typing

import numpy as np

KINDS = {int: ("an integer",
               lambda v: isinstance(v, numbers.Integral) and not isinstance(v, bool), int),
         float: ("a number",
                 lambda v: isinstance(v, numbers.Real) and not isinstance(v, bool), float),
         bool: ("True or False", lambda v: isinstance(v, (bool, np.bool_)), bool),
         str: ("a string", lambda v: isinstance(v, str), str)}
"""A Config field's type -> (what the message asks for, whether a value is of it, the Python
type the Config holds: NumPy scalars become Python ones, so equal options give equal Configs and
a config record stays JSON)."""


def typed_option(owner: str, option: str, annotation, value):
    """``value`` of ``option`` as its Config field's type: ``int``, ``float``, ``bool``, ``str``
    or a union of them, ``| None`` included (the first of the union's types that takes the
    value). A field of another type (a tuple of agents) is left to its Config's own check, and
    its value returned as given.

    Args:
      owner: the swarm or planner the option belongs to, for the message.
      option: the option's name; annotation: its Config field's annotation (resolved).
      value: what the user passed.

    Raises:
      TypeError: a value of another type (a bool is no number here), naming the owner and the
        option.
    """
    union = typing.get_origin(annotation) in (typing.Union, types.UnionType)
    kinds = typing.get_args(annotation) if union else (annotation,)
    optional = type(None) in kinds
    kinds = [kind for kind in kinds if kind is not type(None)]
    if (value is None and optional) or not all(kind in KINDS for kind in kinds):
        return value
    for kind in kinds:
        _, accepts, convert = KINDS[kind]
        if accepts(value):
            return convert(value)
    wanted = " or ".join(KINDS[kind][0] for kind in kinds)
    raise TypeError(f"{option} of {owner} must be {wanted}{' or None' * optional}, got "
                    f"{value!r} ({type(value).__name__})")


def check_new_entry(registry: dict, name: str, entry, entry_type: type, kind: str) -> None:
    """Host-side: raise unless ``entry`` may join ``registry`` as ``name``: an ``entry_type``
    whose ``config`` is a dataclass, under a name not taken (``kind`` says what the registry
    holds, for the message).

    Raises:
      TypeError: ``entry`` is not an ``entry_type``, or its config is not a dataclass.
      ValueError: ``name`` is taken.
    """
    if not isinstance(entry, entry_type):
        raise TypeError(f"entry of {name!r} must be an {entry_type.__name__}, got "
                        f"{type(entry).__name__}")
    if not dataclasses.is_dataclass(entry.config):
        raise TypeError(f"config of {name!r} must be a dataclass, got {entry.config!r}")
    if name in registry:
        raise ValueError(f"{kind} {name!r} is registered already")
