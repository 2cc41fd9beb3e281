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
               mimic: str = "ordinary", accept_improper_inertia: bool = False) -> Chain:
    """Load a robot description as a Chain (a tree when the file is one); base, tip and lock select and
    freeze joints of a URDF tree; `floating` lets the base float (vampc.robot.chain); `mimic` says how
    a URDF's mimic joints are read and `accept_improper_inertia` whether an inertia that is not
    positive semi-definite is refused (vampc.robot.urdf.load_urdf)."""
    from vampc.robot.dh import load_dh
    from vampc.robot.mjcf import is_mjcf, load_mjcf
    from vampc.robot.urdf import load_urdf
    from vampc.sniff import looks_like, suffix_mismatch
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix in URDF_SUFFIXES + YAML_SUFFIXES + JSON_SUFFIXES:
        mismatch = suffix_mismatch(path, "urdf" if suffix in URDF_SUFFIXES else "dh")
        if mismatch:
            raise located(path, "", mismatch)
    if suffix == ".xml" and is_mjcf(path):
        return load_mjcf(path, base=base, tip=tip, lock=lock, floating=floating,
                         accept_improper_inertia=accept_improper_inertia, mimic=mimic)
    if suffix in URDF_SUFFIXES:
        return load_urdf(path, base=base, tip=tip, lock=lock, floating=floating, mimic=mimic,
                         accept_improper_inertia=accept_improper_inertia)
    if suffix in YAML_SUFFIXES + JSON_SUFFIXES:
        if base is not None or tip is not None or lock or mimic != "ordinary" or accept_improper_inertia:
            raise located(path, "", "base, tip, lock, mimic and accept_improper_inertia apply to URDF and "
                                    "MJCF files only (a DH table is read whole)")
        return load_dh(path, floating=floating)
    raise located(path, "", f"unknown robot file extension {path.suffix!r}{looks_like(path)} "
                            "(expected .urdf, .xml, .yaml, .yml or .json)")
