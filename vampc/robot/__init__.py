"""The robot model (Chain, Joint: the paper's notation) and the loaders that produce it.

`load_robot` picks the loader from the file extension: .urdf/.xml → `load_urdf` (an .xml file whose root
is <mujoco> → `load_mjcf`), .yaml/.yml/.json → `load_dh` (a standard DH table, schema
`schemas/dh-table.schema.json`).
"""
from __future__ import annotations

from pathlib import Path

from vampc.errors import located
from vampc.robot.chain import Chain, Joint, JointType, Limits

URDF_SUFFIXES = (".urdf", ".xml")
YAML_SUFFIXES = (".yaml", ".yml")
JSON_SUFFIXES = (".json",)
# The loaders (and PyYAML, lxml) are imported when first used: reading a program file needs only the
# Chain, and a whole `vampc emulate` of a program is a fraction of a second.
_LAZY = {"chain_from_dh": "vampc.robot.dh", "load_dh": "vampc.robot.dh", "load_urdf": "vampc.robot.urdf",
         "load_mjcf": "vampc.robot.mjcf", "is_mjcf": "vampc.robot.mjcf"}


def __getattr__(name: str):
    if name in _LAZY:
        import importlib
        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'vampc.robot' has no attribute {name!r}")

__all__ = ["Chain", "Joint", "JointType", "Limits", "chain_from_dh", "load_dh", "load_robot", "load_urdf"]


def load_robot(path, base: str | None = None, tip: str | None = None,
               lock: dict[str, float] | None = None, floating: bool = False,
               mimic: str = "ordinary", accept_improper_inertia: bool = False,
               mimic_given: bool = False) -> Chain:
    """Load a robot description as a Chain (a tree when the file is one); base, tip and lock select and
    freeze joints of a URDF tree; `floating` lets the base float (vampc.robot.chain); `mimic` says how
    a URDF's mimic joints are read (`mimic_given`: the user named it, so a file without mimic joints
    warns that it has no effect) and `accept_improper_inertia` whether an inertia that is not
    positive semi-definite is refused (vampc.robot.urdf.load_urdf)."""
    from collections.abc import Mapping

    import numpy as np
    if lock is not None and not isinstance(lock, Mapping):
        # (a library caller's list: said, not an AttributeError: a new user's find)
        from vampc.errors import VampcUsageError
        raise VampcUsageError(f"lock: give a mapping of joint name to position (radians or metres), "
                              f"not a {type(lock).__name__}")
    with np.errstate(over="ignore", invalid="ignore"):      # (overflows are said below, by joint)
        chain = _load(Path(path), base, tip, lock, floating, mimic, accept_improper_inertia,
                      mimic_given)
    _check_finite(chain, path)
    _check_names(chain, path)
    if chain.locked:     # (the user's --lock only: a joint an MJCF equality held is left out)
        import dataclasses
        held = tuple(n for n in chain.locked if n not in (lock or {}))
        chain = dataclasses.replace(chain, locked=tuple(n for n in chain.locked if n in (lock or {})),
                                    left_out=chain.left_out + held)
    return chain


def _check_names(chain: Chain, path) -> None:
    """VampcError where the robot's or a joint's name holds a control character (textio.name_problem),
    or a joint's is blank, the joint named by its number (from 1)."""
    from vampc.textio import first_name_problem
    found = first_name_problem([("robot", chain.name)] + [(f"joint {i + 1}", j.name)
                                                          for i, j in enumerate(chain.joints)])
    if found:
        raise located(path, *found)
    blank = next((i for i, j in enumerate(chain.joints) if not j.name.strip()), None)
    if blank is not None:          # (a torque column 'tau_ ', and messages naming ' ')
        from vampc.textio import shown
        raise located(path, f"joint {blank + 1}", f"its name {shown(chain.joints[blank].name)} is "
                      "blank: a joint's name heads its torque column and names it in messages")


def _check_finite(chain: Chain, path) -> None:
    """VampcError naming the first place (joint, the base, the robot) whose number is not finite
    (Chain.first_non_finite): a file's numbers each finite can overflow when a loader combines them
    (a fixed link merged into its parent at an offset of 1e200 gave an infinite inertia, a floating
    base's merged links an infinite centre of mass, each reported as a bug in vampc)."""
    found = chain.first_non_finite()
    if found:
        place, what = found
        raise located(path, place, f"{what} is not a finite number once the file's numbers are "
                      "combined (numbers too large for a float)")


def _load(path: Path, base, tip, lock, floating: bool, mimic: str, accept_improper_inertia: bool,
          mimic_given: bool = False):
    from vampc.robot.dh import load_dh
    from vampc.robot.mjcf import is_mjcf, load_mjcf
    from vampc.robot.urdf import load_urdf
    from vampc.sniff import looks_like, suffix_mismatch
    suffix = path.suffix.lower()
    if path.is_dir():    # (click's own message and exit 2 for a folder, "cannot read" for d.urdf)
        raise located(path, "", "not a regular file (a robot or program file is read from one)")
    if suffix != ".xml" and is_mjcf(path):    # (it was told it is a URDF, or to name it .urdf)
        raise located(path, "", "this is an MJCF model (a <mujoco> root); name it .xml to load it as "
                                "one")
    if suffix in URDF_SUFFIXES + YAML_SUFFIXES + JSON_SUFFIXES:
        mismatch = suffix_mismatch(path, "urdf" if suffix in URDF_SUFFIXES else "dh")
        if mismatch:
            raise located(path, "", mismatch)
    if suffix == ".xml" and is_mjcf(path):
        return load_mjcf(path, base=base, tip=tip, lock=lock, floating=floating,
                         accept_improper_inertia=accept_improper_inertia, mimic=mimic,
                         mimic_given=mimic_given)
    if suffix in URDF_SUFFIXES:
        return load_urdf(path, base=base, tip=tip, lock=lock, floating=floating, mimic=mimic,
                         accept_improper_inertia=accept_improper_inertia, mimic_given=mimic_given)
    if suffix in YAML_SUFFIXES + JSON_SUFFIXES:
        if base is not None or tip is not None or lock or mimic != "ordinary" or accept_improper_inertia:
            raise located(path, "", "base, tip, lock, mimic and accept_improper_inertia apply to URDF and "
                                    "MJCF files only (a DH table is read whole)")
        return load_dh(path, floating=floating)
    from vampc.sniff import OTHER_COMPRESSION, OTHER_COMPRESSIONS, sniff
    if not path.is_file():        # (any name may be a program file's: not a question of extension)
        from vampc.textio import stdin_hint
        raise located(path, "", f"no such file{stdin_hint(path)}" if not path.exists() else
                      "not a regular file (a robot or program file is read from one)")
    kind = sniff(path)
    if kind in OTHER_COMPRESSIONS:
        raise located(path, "", f"{kind}-compressed; {OTHER_COMPRESSION}")
    if kind == "gzip-cut":                 # (whatever its name: a program file's content may be)
        from vampc.sniff import DESCRIPTIONS
        raise located(path, "", DESCRIPTIONS[kind])
    suffix = path.suffix.lower()            # (a new user gave their torque CSV as the robot)
    table = looks_like(path) or (
        ": a CSV table is a trajectory (for --trajectory), torques or limits, not a robot"
        if suffix == ".csv" else ": a NumPy array is a trajectory (for --trajectory) or torques, "
        "not a robot" if suffix in (".npy", ".npz") else "")     # (a robot saved as .csv: its content)
    if suffix == ".xacro":          # (a new user's arm.urdf.xacro: "it looks like XML (a URDF)")
        from vampc.robot.urdf import run_xacro
        table = f": a xacro file, which expands to a URDF: {run_xacro(path)}"
    raise located(path, "", f"unknown robot file extension {path.suffix!r}{table} "
                            "(expected .urdf, .xml, .yaml, .yml or .json)")
