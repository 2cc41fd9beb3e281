"""Plain-numpy dynamics: the serial RNEA oracle (Table I.1) and the logarithmic combining forms (IV.1)."""
from vampc.dynamics.logforms import (
                                     Back,
                                     Fwd,
                                     State,
                                     back_combine,
                                     back_leaf,
                                     back_leaf_unified,
                                     fwd_combine,
                                     fwd_leaf,
                                     fwd_leaf_unified,
                                     log_rnea,
                                     prefix_backward,
                                     reduce_range,
                                     split_first,
                                     split_last,
                                     split_middle,
                                     suffix_forward,
)
from vampc.dynamics.reference import (
                                     joint_forces,
                                     kinetic_energy,
                                     link_loads,
                                     mass_matrix,
                                     potential_energy,
                                     rnea,
                                     rnea_variables,
)

__all__ = [
    "Back", "Fwd", "State", "back_combine", "back_leaf", "back_leaf_unified", "fwd_combine", "fwd_leaf",
    "fwd_leaf_unified", "log_rnea", "prefix_backward", "reduce_range", "split_first", "split_last",
    "split_middle", "suffix_forward",
    "joint_forces", "kinetic_energy", "link_loads", "mass_matrix", "potential_energy", "rnea",
    "rnea_variables",
]
