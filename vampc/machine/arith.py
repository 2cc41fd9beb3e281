"""The arithmetic of a VAMP's units, behind one small interface (DESIGN §10).

Every engine does its arithmetic through a word format: the tick engine and the numpy stream engine
call `apply`, the stream engine's generated C renders `c_expr`, and later a Verilog generator renders
the same three functions again. A format decides where a result is rounded and what happens on
overflow, so every engine rounds and saturates at the same points, bit for bit.

    function   meaning             float64 (IEEE binary64, round to nearest even)
    mul        x · y               one rounded product (never fused with a following add)
    add        x + y               one rounded sum
    sub        x − y               one rounded difference

Only float64 exists today; a fixed-point format (issue "Hardware word formats") is another class with
the same four members.
"""
from __future__ import annotations

import enum


class Fn(enum.Enum):
    """An arithmetic function of a unit: what one micro-step assignment computes."""

    MUL = "mul"
    ADD = "add"
    SUB = "sub"

    @property
    def unit(self) -> str:
        """The kind of unit that computes it: "M" a multiplier, "A" the adder/subtractor."""
        return "M" if self is Fn.MUL else "A"


class Float64:
    """IEEE binary64 words: numpy's float64 in Python, `double` in C (compiled with
    -ffp-contract=off, so a product is rounded before it is added, as numpy rounds it)."""

    name = "float64"
    c_type = "double"
    _C = {Fn.MUL: "*", Fn.ADD: "+", Fn.SUB: "-"}

    def apply(self, fn: Fn, x, y):
        """fn(x, y) on numpy arrays (any broadcastable shapes)."""
        if fn is Fn.MUL:
            return x * y
        if fn is Fn.ADD:
            return x + y
        return x - y

    def c_expr(self, fn: Fn, x: str, y: str) -> str:
        """fn(x, y) as a C expression of two C expressions of type `c_type`."""
        return f"{x} {self._C[fn]} {y}"


FLOAT64 = Float64()
