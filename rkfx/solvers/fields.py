"""The unknowns of a model: named fields laid out one block after another.

A field with ``c`` components on ``n`` nodes occupies a block of ``c n`` unknowns, interleaved
per node (u of node I at ``2 I, 2 I + 1``), so a u-p model's vector is ``[u_0x, u_0y, u_1x,
..., p_0, p_1, ...]``. The time order of a field is the highest time derivative of it that the
equations carry: 2 for a displacement with inertia, 1 for a pressure or for a displacement
whose rate enters the storage equation of quasi-static consolidation, 0 for none.
"""
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from rkfx.errors import InputError


@dataclass(frozen=True)
class Field:
    """One field of a model.

    Attributes:
        name: e.g. ``"u"`` or ``"p"``.
        components: Values per node: 2 for u in 2-D (3 in 3-D), 1 for p.
        order: Highest time derivative in the equations (0, 1 or 2).
        nodes: Number of nodes carrying the field.
    """

    name: str
    components: int
    order: int
    nodes: int

    def __post_init__(self):
        if self.components < 1 or int(self.components) != self.components:
            raise InputError(f"field {self.name!r}: components = {self.components!r} must be a positive integer")
        if self.order not in (0, 1, 2):
            raise InputError(f"field {self.name!r}: time order {self.order!r} must be 0, 1 or 2")
        if self.nodes < 0 or int(self.nodes) != self.nodes:
            raise InputError(f"field {self.name!r}: nodes = {self.nodes!r} must be a non-negative integer")

    @property
    def size(self) -> int:
        return self.components * self.nodes


@dataclass(frozen=True)
class FieldLayout:
    """Fields in the order of their blocks in the state vector.

    Attributes:
        fields: The fields, first block first.
    """

    fields: tuple[Field, ...]

    def __post_init__(self):
        names = [f.name for f in self.fields]
        if len(set(names)) != len(names):
            raise InputError(f"field names {names} repeat; give every field its own name")

    @property
    def size(self) -> int:
        """Total number of unknowns."""
        return sum(f.size for f in self.fields)

    def field(self, name: str) -> Field:
        for f in self.fields:
            if f.name == name:
                return f
        raise InputError(f"no field {name!r}; this layout has {', '.join(f.name for f in self.fields)}")

    def block(self, name: str) -> slice:
        """The unknowns of one field in the state vector."""
        start = 0
        for f in self.fields:
            if f.name == name:
                return slice(start, start + f.size)
            start += f.size
        self.field(name)  # raises with the names
        raise AssertionError

    def values(self, x: np.ndarray, name: str) -> np.ndarray:
        """The nodal values of one field, shape ``(nodes, components)`` (a view of ``x``)."""
        f = self.field(name)
        return x[self.block(name)].reshape(f.nodes, f.components)

    @cached_property
    def orders(self) -> np.ndarray:
        """Time order of every unknown, shape ``(size,)``."""
        return np.concatenate([np.full(f.size, f.order, np.int8) for f in self.fields]) if self.fields \
            else np.zeros(0, np.int8)


def layout(*fields: Field | tuple, nodes: int | None = None) -> FieldLayout:
    """A layout from fields or ``(name, components, order)`` tuples on ``nodes`` nodes.

    Example: ``layout(("u", 2, 1), ("p", 1, 1), nodes=n)`` for quasi-static consolidation.
    """
    out = []
    for f in fields:
        if isinstance(f, Field):
            out.append(f)
        else:
            if nodes is None:
                raise InputError("layout(...) of (name, components, order) tuples needs nodes=")
            out.append(Field(*f, nodes=nodes))
    return FieldLayout(tuple(out))


def single(name: str, components: int, order: int, nodes: int) -> FieldLayout:
    """A layout of one field."""
    return FieldLayout((Field(name, components, order, nodes),))

