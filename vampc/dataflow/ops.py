"""The op repertoire as the dataflow stage imported it before the op table moved: the names of
vampc.machine.ops, where each op is defined once (kept so code written against the old module runs)."""
from vampc.machine.ops import (
                               MICRO_STEPS,
                               OPERAND_SHAPES,
                               SERIAL_WORK,
                               VAMPS_PER_OP,
                               Op,
                               Timing,
                               result_shape,
)

__all__ = ["MICRO_STEPS", "OPERAND_SHAPES", "SERIAL_WORK", "VAMPS_PER_OP", "Op", "Timing",
           "result_shape"]
